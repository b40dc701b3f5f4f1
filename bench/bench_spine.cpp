// Spine costs against the real-time targets: one equilibrium + recruitment ≤ 100 ms; the whole
// displacement–force database in < 5 min; evaluating all 17 vertebra poses for one force from
// the fits in ≤ 10 µs (it runs inside the 1 kHz haptic loop).
//   SolveSpine/0           solve_spine, gravity only (recruitment + Newton)
//   SolveSpine/1           solve_spine, 400 N +z (forward) on T1's F.1 centre
//   Recruitment            recruitment_problem + recruit (Ipopt) for the 400 N case alone
//   DatabaseEvaluate/0|1   DisplacementDatabase::evaluate, one axis force | an oblique force
//                          (three axis fits superposed), shipped file
//   DatabaseGenerate/W     every solve and fit for one loaded vertebra (T7: 72 solves +
//                          baseline) on W threads; counter full_estimate_s = 17 × that
//   Seated/R               solve_seated in the parametric chair with the backrest at R deg
//                          (R = 0: a stool): one seated posture, i.e. one point of a sweep
//   SeatedHookSolve        one seated equilibrium under a 100 N hook on T1 as the haptic
//                          worker solves it (posture and contact forces of the seated sitter)
// Run: build/release/bench/bench_spine [--benchmark_filter=Database]
#include "spinesim/spine/database.hpp"
#include "spinesim/spine/equilibrium.hpp"
#include "spinesim/spine/model.hpp"
#include "spinesim/spine/recruitment.hpp"
#include "spinesim/spine/seating.hpp"

#include <benchmark/benchmark.h>

using namespace spinesim::spine;

namespace {

const SpineModel& model() {
  static const SpineModel m = load_spine_model(SPINESIM_DATA_DIR);
  return m;
}

const DisplacementDatabase& database() {
  static const DisplacementDatabase db =
      DisplacementDatabase::load(std::string(SPINESIM_DATA_DIR) + "/spine/displacement_db.json");
  return db;
}

std::vector<ExternalLoad> forward_on_t1() {
  ExternalLoad l;
  l.vertebra = 0;
  l.force_n = Eigen::Vector3d(0, 0, 400);
  return {l};
}

void SolveSpine(benchmark::State& state) {
  const auto loads = state.range(0) ? forward_on_t1() : std::vector<ExternalLoad>();
  SpineSolution s;
  for (auto _ : state) {
    s = solve_spine(model(), loads);
    benchmark::DoNotOptimize(s.displacement.data());
  }
  state.counters["newton_its"] = s.iterations;
  state.counters["recruit_ms"] = 1e3 * s.seconds_recruitment;
  state.counters["newton_ms"] = 1e3 * s.seconds_equilibrium;
}
BENCHMARK(SolveSpine)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond);

void Recruitment(benchmark::State& state) {
  const auto loads = forward_on_t1();
  Eigen::MatrixXd arm;
  Eigen::VectorXd moment;
  std::vector<int> joints;
  for (auto _ : state) {
    recruitment_problem(model(), loads, arm, moment, joints);
    const auto r = recruit(model(), arm, moment);
    benchmark::DoNotOptimize(r.force_n.data());
    if (!r.success) state.SkipWithError(("recruitment failed: " + r.status).c_str());
  }
  state.counters["muscles"] = double(arm.cols());
  state.counters["joint_axes"] = double(arm.rows());
}
BENCHMARK(Recruitment)->Unit(benchmark::kMillisecond);

void Seated(benchmark::State& state) {
  const Sitter sitter = load_sitter(model());
  Chair chair;
  if (state.range(0) == 0)
    chair.backrest_height_mm = 0;
  else
    chair.backrest_recline_deg = double(state.range(0));
  SeatedSolution s;
  for (auto _ : state) {
    s = solve_seated(model(), chair, sitter);
    benchmark::DoNotOptimize(s.spine.displacement.data());
  }
  state.counters["equilibria"] = s.solves;
  state.counters["lean_steps"] = s.lean_iterations;
  state.counters["ms_per_equilibrium"] = 1e3 * s.seconds / std::max(1, s.solves);
}
BENCHMARK(Seated)->Arg(0)->Arg(90)->Arg(100)->Arg(110)->Arg(120)->Unit(benchmark::kMillisecond);

void SeatedHookSolve(benchmark::State& state) {
  const Sitter sitter = load_sitter(model());
  const Chair chair;
  const SeatedSolution seated = solve_seated(model(), chair, sitter);
  const SeatedModel sm =
      seat_model(model(), chair, sitter, seated.pelvic_tilt_deg, seated.ischia_forward_mm);
  SolveOptions o;
  o.posture = sm.posture;
  o.recruitment_contact_forces = seated.spine.contact_force_n;
  auto loads = forward_on_t1();
  loads[0].force_n = Eigen::Vector3d(0, 0, -100);  // towards the backrest
  for (auto _ : state) {
    const SpineSolution s = solve_spine(sm.model, loads, o);
    benchmark::DoNotOptimize(s.displacement.data());
  }
}
BENCHMARK(SeatedHookSolve)->Unit(benchmark::kMillisecond);

void DatabaseEvaluate(benchmark::State& state) {
  const DisplacementDatabase& db = database();
  const Eigen::Vector3d force =
      state.range(0) ? Eigen::Vector3d(-212.1, 150.0, 212.1) : Eigen::Vector3d(0, 0, 300);
  VertebraResponse out;
  int v = 0;
  for (auto _ : state) {
    db.evaluate(v, force, out);
    benchmark::DoNotOptimize(out.data());
    benchmark::ClobberMemory();
    v = v == 16 ? 0 : v + 1;  // a different loaded vertebra each time: its fits are not in L1
  }
}
BENCHMARK(DatabaseEvaluate)->Arg(0)->Arg(1)->Unit(benchmark::kMicrosecond);

void DatabaseGenerate(benchmark::State& state) {
  GenerationOptions o;
  o.loaded_vertebrae = {vertebra_index("T7")};
  o.workers = int(state.range(0));
  ResponseSamples s;
  for (auto _ : state) {
    s = sample_responses(model(), o);
    const DisplacementDatabase db = DisplacementDatabase::fit(s, o.tolerance);
    benchmark::DoNotOptimize(db.force_max_n());
  }
  state.counters["solves"] = s.solves;
  state.counters["failed"] = double(s.failed.size());
  state.counters["full_estimate_s"] = kDbVertebrae * s.seconds;
}
BENCHMARK(DatabaseGenerate)->Arg(1)->Arg(2)->Iterations(1)->UseRealTime()->Unit(benchmark::kSecond);

}  // namespace

BENCHMARK_MAIN();

// MSS disc benchmarks: what one 1 kHz step costs, by stage and disc size, on the CGAL L4-L5 disc.
//
// Meshes: the parametric L4-L5 disc (data/disc_morphometry.csv) meshed by CGAL at a cell size
// (benchmark argument, µm); the tet count is a counter. Material: real-disc (E 3.22 MPa,
// nu 0.4557, rho 1038 kg/m^3), thesis springs (main + radial + torsion).
//   Gradient        — MssModel::gradient (all internal forces), the per-step force evaluation
//   TermGradient    — one term's gradient (0 main, 1 radial, 2 torsion, 3 per-tet volume),
//                     both regions, 2.5 mm L4-L5 disc: the force evaluation's parts
//   Hessian         — MssModel::hessian (exact), refilled in its fixed pattern
//   ImplicitFrozen  — one implicit Euler step, dt 1 ms, one Newton iteration on the rest
//                     factorisation (MatrixUpdate::frozen): the real-time haptic step
//   ImplicitFrozenMoving — the same while the plate keeps moving (a Newton iteration every
//                     step), with the per-tet volume term: the haptic step without contact
//   ImplicitNewton  — one implicit Euler step, dt 1 ms, the matrix refactorised (numeric only)
//   Static          — Newton equilibrium under 10 % axial compression
//   AllDiscs        — the 17 discs T1-T2 .. L5-S1 meshed at one cell size (µm; 0: the structured
//                     360-tet disc of mesh/structured_disc.hpp), one frozen
//                     implicit step each (DiscSet, 1 or 2 threads): real time at 1 kHz needs
//                     < 1 ms per iteration
// Run: build/release/bench/bench_mss [--benchmark_filter=Implicit]
#include "spinesim/mesh/disc_geometry.hpp"
#include "spinesim/mesh/material.hpp"
#include "spinesim/mesh/mesher.hpp"
#include "spinesim/mesh/structured_disc.hpp"
#include "spinesim/mss/disc_set.hpp"
#include "spinesim/mss/model.hpp"
#include "spinesim/mss/simulator.hpp"
#include "spinesim/mss/solver.hpp"

#include <benchmark/benchmark.h>

#include <cmath>
#include <map>
#include <memory>
#include <string>
#include <vector>

using namespace spinesim;
using namespace spinesim::mss;

namespace {

mesh::RegionMaterials real_disc() { return mesh::load_material("real-disc", SPINESIM_DATA_DIR); }

/// CGAL disc at a cell size, or (cell_mm == 0) the structured haptic-resolution disc
/// (mesh/structured_disc.hpp defaults: 12 sectors x 3 rings x 2 layers, 360 tets).
const mesh::TetMesh& disc_mesh(const std::string& level, double cell_mm) {
  static std::map<std::pair<std::string, long>, mesh::TetMesh> cache;
  const auto key = std::make_pair(level, std::lround(cell_mm * 1000));
  auto it = cache.find(key);
  if (it == cache.end()) {
    const mesh::DiscDimensions dims = mesh::disc_dimensions(level, SPINESIM_DATA_DIR);
    mesh::MeshOptions opt;
    opt.cell_size_mm = cell_mm;
    it = cache
             .emplace(key, cell_mm > 0 ? mesh::mesh_parametric_disc(dims, opt)
                                       : mesh::mesh_structured_disc(dims))
             .first;
  }
  return it->second;
}

const MssModel& disc_model(double cell_mm) {
  static std::map<long, std::unique_ptr<MssModel>> cache;
  auto& m = cache[std::lround(cell_mm * 1000)];
  if (!m) m = std::make_unique<MssModel>(disc_mesh("L4-L5", cell_mm), real_disc());
  return *m;
}

void set_counters(benchmark::State& state, const MssModel& model) {
  state.counters["tets"] = double(model.mesh().num_tets());
  state.counters["nodes"] = double(model.num_nodes());
  state.counters["angle_springs"] = double(model.num_angle_springs());
}

/// Boundary for 10 % axial compression of the plate (pose mode).
Boundary compression(const MssModel& model, double fraction) {
  Boundary bc;
  Eigen::Vector3d c = Eigen::Vector3d::Zero();
  int n = 0;
  for (Eigen::Index i = 0; i < model.num_nodes(); ++i)
    if (model.mesh().surface(i) == 2) c += model.mesh().V.row(i).transpose(), ++n;
  bc.plate_center_mm = c / n;
  Vector6d q = Vector6d::Zero();
  q(1) = -fraction * model.cylinder().length_mm;
  bc.superior = plate_pose(q, bc.plate_center_mm);
  return bc;
}

void Gradient(benchmark::State& state) {
  const MssModel& model = disc_model(state.range(0) / 1000.0);
  Eigen::VectorXd x = model.rest_positions_mm(), g;
  x *= 1.01;
  for (auto _ : state) {
    benchmark::DoNotOptimize(model.gradient(x, g));
    benchmark::ClobberMemory();
  }
  set_counters(state, model);
}

/// The energy alone (what a line-search trial needs), beside Gradient.
void Energy(benchmark::State& state) {
  const MssModel& model = disc_model(state.range(0) / 1000.0);
  Eigen::VectorXd x = model.rest_positions_mm();
  x *= 1.01;
  for (auto _ : state) benchmark::DoNotOptimize(model.energy(x));
  set_counters(state, model);
}

/// One term's gradient (argument: Term index; region 0 and 1 both), on the 2.5 mm L4-L5 disc
/// with the per-tet volume term on: where the force evaluation's time goes.
void TermGradient(benchmark::State& state) {
  static const MssModel model = [] {
    MssOptions o;
    o.volume_term = true;
    return MssModel(disc_mesh("L4-L5", 2.5), real_disc(), o);
  }();
  const auto term = static_cast<Term>(state.range(0));
  Eigen::VectorXd x = model.rest_positions_mm() * 1.01, g;
  for (auto _ : state) {
    for (int region = 0; region < 2; ++region) model.term_gradient(x, term, region, g);
    benchmark::ClobberMemory();
  }
  set_counters(state, model);
}

void Hessian(benchmark::State& state) {
  const MssModel& model = disc_model(state.range(0) / 1000.0);
  Eigen::VectorXd x = model.rest_positions_mm() * 1.01;
  Eigen::SparseMatrix<double> H;
  for (auto _ : state) {
    model.hessian(x, HessianMode::exact, H);
    benchmark::ClobberMemory();
  }
  set_counters(state, model);
}

void step_benchmark(benchmark::State& state, MatrixUpdate update) {
  const MssModel& model = disc_model(state.range(0) / 1000.0);
  DynamicsOptions opt;
  opt.dt_s = 1e-3;
  opt.matrix_update = update;
  Simulator sim(model, opt);
  State s = sim.rest_state();
  const Boundary bc = compression(model, 0.02);
  sim.step(s, bc);  // first step: analysis (+ the frozen factorisation)
  for (auto _ : state) {
    const StepReport r = sim.step(s, bc);
    if (!r.ok) state.SkipWithError(r.message.c_str());
  }
  set_counters(state, model);
}

void ImplicitFrozen(benchmark::State& state) { step_benchmark(state, MatrixUpdate::frozen); }

/// The frozen step while the superior plate keeps moving (2 % compression oscillating at 5 Hz),
/// so every step makes its Newton iteration (force evaluation + the two triangular solves): the
/// real-time haptic step without contact, on the model with the per-tet volume term as tuned.
void ImplicitFrozenMoving(benchmark::State& state) {
  MssOptions o;
  o.volume_term = true;
  const MssModel model(disc_mesh("L4-L5", state.range(0) / 1000.0), real_disc(), o);
  DynamicsOptions opt;
  opt.dt_s = 1e-3;
  opt.matrix_update = MatrixUpdate::frozen;
  Simulator sim(model, opt);
  State s = sim.rest_state();
  Boundary bc = compression(model, 0.0);
  const double amplitude = 0.02 * model.cylinder().length_mm;
  long k = 0;
  auto next = [&] {
    Vector6d q = Vector6d::Zero();
    q(1) = -amplitude * std::sin(2.0 * 3.14159265358979 * 5.0 * 1e-3 * double(k++));
    bc.superior = plate_pose(q, bc.plate_center_mm);
    return sim.step(s, bc);
  };
  next();  // first step: analysis + the frozen factorisation
  int iterations = 0;
  for (auto _ : state) {
    const StepReport r = next();
    if (!r.ok) state.SkipWithError(r.message.c_str());
    iterations += r.newton_iterations;
  }
  state.counters["newton_iterations_per_step"] = double(iterations) / double(state.iterations());
  set_counters(state, model);
}
void ImplicitNewton(benchmark::State& state) {
  step_benchmark(state, MatrixUpdate::every_iteration);
}

void Static(benchmark::State& state) {
  const MssModel& model = disc_model(state.range(0) / 1000.0);
  const Boundary bc = compression(model, 0.10);
  int iterations = 0;
  for (auto _ : state) {
    const StaticResult r = solve_static(model, bc);
    if (!r.converged) state.SkipWithError(r.message.c_str());
    iterations = r.iterations;
  }
  state.counters["newton_iterations"] = iterations;
  set_counters(state, model);
}

void AllDiscs(benchmark::State& state) {
  static std::map<std::pair<long, long>, std::unique_ptr<DiscSet>> cache;
  const double cell_mm = state.range(0) / 1000.0;
  const int threads = int(state.range(1));
  auto& set = cache[{state.range(0), state.range(1)}];
  std::vector<Boundary> bcs;
  if (!set) {
    DynamicsOptions opt;
    opt.dt_s = 1e-3;
    opt.matrix_update = MatrixUpdate::frozen;
    set = std::make_unique<DiscSet>(threads);
    for (const std::string& level : mesh::disc_levels())
      set->add(MssModel(disc_mesh(level, cell_mm), real_disc()), opt);
  }
  for (int i = 0; i < set->size(); ++i) bcs.push_back(compression(set->model(i), 0.02));
  set->step(bcs);  // first step: analysis + the frozen factorisations
  for (auto _ : state)
    for (const StepReport& r : set->step(bcs))
      if (!r.ok) state.SkipWithError(r.message.c_str());
  state.counters["discs"] = double(set->size());
  state.counters["tets"] = set->total_tets();
  state.counters["threads"] = threads;
}

// Cell sizes 4, 3, 2.5, 2, 1.5 mm (µm arguments).
void sizes(benchmark::internal::Benchmark* b) {
  for (int um : {4000, 3000, 2500, 2000, 1500}) b->Arg(um);
  b->Unit(benchmark::kMicrosecond);
}

}  // namespace

BENCHMARK(Gradient)->Apply(sizes);
BENCHMARK(Energy)->Apply(sizes);
BENCHMARK(TermGradient)->DenseRange(0, 3)->Unit(benchmark::kMicrosecond);
BENCHMARK(Hessian)->Apply(sizes);
BENCHMARK(ImplicitFrozen)->Apply(sizes);
BENCHMARK(ImplicitFrozenMoving)->Arg(2500)->Arg(3000)->Unit(benchmark::kMicrosecond);
BENCHMARK(ImplicitNewton)->Apply(sizes);
BENCHMARK(Static)->Apply(sizes)->Unit(benchmark::kMillisecond);
BENCHMARK(AllDiscs)
    ->ArgsProduct({{0, 2000, 4000}, {1, 2}})
    ->ArgNames({"cell_um", "threads"})
    ->Unit(benchmark::kMicrosecond);

BENCHMARK_MAIN();

#include "spinesim/studies/disc_palpation_setup.hpp"

#include "spinesim/calibration/tuned_set.hpp"
#include "spinesim/common/timer.hpp"
#include "spinesim/fem/contact_disc.hpp"
#include "spinesim/mesh/disc_cache.hpp"
#include "spinesim/mesh/disc_level.hpp"
#include "spinesim/mss/boundary.hpp"
#include "spinesim/studies/toolkit.hpp"

#include <time.h>

#include <algorithm>
#include <optional>
#include <stdexcept>

namespace spinesim::studies {

std::pair<Eigen::Vector3d, Eigen::Vector3d> disc_anterior_wall(const mesh::TetMesh& disc) {
  // In the disc's frame: the node furthest anterior (+z) within the middle third of the height.
  const Eigen::Matrix3d& A = disc.frame.axes;
  const Eigen::MatrixX3d local = (disc.V.rowwise() - disc.frame.origin_mm.transpose()) * A;
  const double h = local.col(1).maxCoeff() - local.col(1).minCoeff();
  const double mid = 0.5 * (local.col(1).maxCoeff() + local.col(1).minCoeff());
  Eigen::Index best = -1;
  for (Eigen::Index i = 0; i < disc.V.rows(); ++i)
    if (std::abs(local(i, 1) - mid) < h / 6 && (best < 0 || local(i, 2) > local(best, 2))) best = i;
  if (best < 0) throw std::invalid_argument("disc palpation: the disc mesh has no wall nodes");
  return {disc.V.row(best).transpose(), A.col(2)};
}

std::string palpation_params_path(const std::string& params, const std::string& data_dir) {
  return calibration::tuned_set_path(
      params, {{"fibre-reinforced", calibration::shipped_fibre_tuned_set_path(data_dir)},
               {"real-disc", calibration::shipped_tuned_set_path(data_dir)}});
}

namespace {

/// fem::ContactDisc behind the palpation interface: each step is the static equilibrium.
class FemPalpableDisc final : public haptics::PalpableDisc {
 public:
  FemPalpableDisc(const mesh::TetMesh& mesh, const mesh::RegionMaterials& materials,
                  const fem::ContactDiscOptions& options)
      : disc_(mesh, materials, options), radius_(options.probe_radius_mm) {}
  const char* name() const override { return "linear FEM"; }
  const mesh::TetMesh& mesh() const override { return disc_.mesh(); }
  const Eigen::VectorXd& rest_positions_mm() const override { return disc_.rest_positions_mm(); }
  const Eigen::VectorXd& positions_mm() const override { return disc_.positions_mm(); }
  double probe_radius_mm() const override { return radius_; }
  double probe_penalty_n_per_mm() const override { return disc_.penalty_n_per_mm(); }
  /// The equilibrium, then (a step without new contact nodes costing about a millisecond at
  /// 20,000 tets against a 10 ms worker period) the columns of one more wall node near the
  /// probe, so that a touch or a slide meets nodes already solved.
  bool step(const Eigen::Vector3d& center_mm) override {
    const fem::ContactSolveReport r = disc_.solve(center_mm);
    if (r.ok && r.new_nodes == 0) disc_.prefetch(center_mm, radius_ + kAhead, 1);
    return r.ok;
  }
  static constexpr double kAhead = 4;  ///< mm beyond the probe's radius
  Eigen::Vector3d probe_force_n() const override { return disc_.probe_force_n(); }
  // The normal springs' linearisation, as the mass-spring disc's probe gives: the exact one's
  // negative directions along the convex wall (about -F / r) would make the palpation's local
  // model untrusted at 29 N on a 4 mm probe and the probe then creep to its balance.
  Eigen::Matrix3d probe_stiffness() const override { return disc_.probe_stiffness_gauss_newton(); }
  double volume_change() const override { return disc_.volume_change(); }

 private:
  fem::ContactDisc disc_;
  double radius_;
};

double thread_cpu_us() {
  timespec ts{};
  ::clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return 1e6 * double(ts.tv_sec) + 1e-3 * double(ts.tv_nsec);
}

/// The step's percentiles with the probe pressed 2 mm into the anterior wall (after 10 steps
/// 3 mm out, 20 of pressing in, 0.25 mm a step, and 30 of holding): wall time, and the thread's CPU time, which
/// leaves out the time the host took the core away (a stall is not the solver's cost). At most
/// 300 pressed steps, and no more than half a second in all once 40 are in: a 21,000-tet disc
/// steps in about 5 ms, and 400 steps of it were 2 s of every run's start.
void measure_step(haptics::DiscPalpation& p, const mesh::TetMesh& m, DiscCandidate* c) {
  const auto [wall, n] = disc_anterior_wall(m);
  const double r = p.options().probe_radius_mm;
  std::vector<float> us, cpu;
  const Timer pressed;
  for (int k = 0; k < 360; ++k) {
    const double depth = k < 10 ? -3.0 : std::min(2.0, -3.0 + 5.0 * (k - 10) / 20.0);
    const double cpu0 = thread_cpu_us();
    const haptics::DiscContact& step = p.step(wall - (depth - r) * n);
    const double cpu1 = thread_cpu_us();
    if (k >= 60) {  // after 30 steps of holding: the contact's onset is not the step's cost
      us.push_back(float(step.step_us));
      cpu.push_back(float(cpu1 - cpu0));
      if (us.size() >= 40 && pressed.seconds() > 0.5) break;
    }
  }
  c->step_us = haptics::percentiles(us);
  c->step_cpu_us = haptics::percentiles(cpu);
  std::sort(cpu.begin(), cpu.end());
  c->judged_cpu_us = double(cpu[cpu.size() >= 4 ? cpu.size() - 4 : 0]);
}

mss::Boundary held_plates(const mesh::TetMesh& m) {
  mss::Boundary bc;
  bc.plate_center_mm = mss::default_plate_center(m);
  return bc;
}

}  // namespace

std::unique_ptr<haptics::PalpableDisc> make_fem_palpable_disc(
    const mesh::TetMesh& mesh, const mesh::RegionMaterials& materials, double radius_mm,
    double penalty_n_per_mm) {
  fem::ContactDiscOptions o;
  o.probe_radius_mm = radius_mm;
  o.penalty_n_per_mm = penalty_n_per_mm;
  return std::make_unique<FemPalpableDisc>(mesh, materials, o);
}

DiscSetup make_disc_setup(const DiscSceneRequest& request, const std::string& data_dir,
                          const std::function<void(const std::string&)>& stage) {
  if (!(request.budget_us > 0) || request.budget_us > 1e6)
    throw std::invalid_argument("--disc-budget-us must be > 0 and at most 1 s");
  if (request.cell_sizes_mm.empty())
    throw std::invalid_argument("disc palpation: no candidate resolution");
  if (request.disc_model != "mss" && request.disc_model != "fem")
    throw std::invalid_argument(
        "--disc-model must be mss (the tuned mass-spring disc) or fem (its "
        "linear FEM), got '" +
        request.disc_model + "'");
  const bool fem_disc = request.disc_model == "fem";
  DiscSetup s;
  s.tuned_file = palpation_params_path(request.params, data_dir);
  // The level and its tuned parameters, refused before any meshing.
  mesh::disc_dimensions(request.level, data_dir);
  std::optional<calibration::TunedSet> set;
  try {
    set = calibration::read_tuned_set(s.tuned_file);
  } catch (const std::invalid_argument&) {  // a single tuned.json: checked on the mesh below
  }
  if (set) calibration::tuned_level(*set, request.level);  // names the levels it has
  const bool fixed_size = request.fixed_cell_size_mm > 0;
  if (fixed_size && !(request.fixed_cell_size_mm >= 0.5 && request.fixed_cell_size_mm <= 10))
    throw std::invalid_argument("--disc-cell-size must be 0.5 to 10 mm (0: the budget check)");
  const std::vector<double> cells =
      fixed_size ? std::vector<double>{request.fixed_cell_size_mm} : request.cell_sizes_mm;
  const std::string period = request.palpation.multirate
                                 ? fixed(1e3 * request.palpation.dt_s, 0) + " ms worker period"
                                 : "1 ms tick";
  for (const double cell : cells) {
    if (stage) stage("meshing " + request.level + " at " + fixed(cell, 1) + " mm, timing its step");
    mesh::MeshOptions mo;
    mo.cell_size_mm = cell;
    const mesh::TetMesh m = mesh::cached_disc_level(request.level, mo, data_dir, request.cache_dir);
    const calibration::TunedDisc tuned = calibration::read_tuned_for_mesh(s.tuned_file, &m);
    auto model = std::make_unique<mss::MssModel>(
        calibration::build_tuned_model(tuned, m, tuned.materials()));
    DiscCandidate c;
    c.cell_size_mm = cell;
    c.tets = long(m.num_tets());
    const mss::MssModel& tuned_model = *model;
    const mesh::RegionMaterials materials = tuned.materials();
    const haptics::DiscPalpationOptions& po = request.palpation;
    auto make = [fem_disc, &tuned_model, materials,
                 po]() -> std::unique_ptr<haptics::PalpableDisc> {
      if (fem_disc)
        return make_fem_palpable_disc(tuned_model.mesh(), materials, po.probe_radius_mm,
                                      po.probe_penalty_n_per_mm);
      return haptics::make_mss_palpable_disc(tuned_model, held_plates(tuned_model.mesh()), po);
    };
    {
      haptics::DiscPalpation trial(make(), request.palpation);
      measure_step(trial, model->mesh(), &c);
    }
    c.fits = c.judged_cpu_us <= request.budget_us;
    s.tried.push_back(c);
    const bool last = cell == cells.back();
    if (!c.fits && !last) continue;
    // The asked size, or the coarsest when none fits: the run starts and says what it holds.
    if (!c.fits)
      s.note = std::string(fixed_size ? "the asked " : "no resolution fits; the coarsest, ") +
               fixed(cell, 1) + " mm disc's step (CPU " + fixed(c.judged_cpu_us, 0) +
               " us at the fourth-worst step, CPU p99 " + fixed(c.step_cpu_us.p99, 0) +
               " us, wall p99 " + fixed(c.step_us.p99, 0) + " us) does not fit the " +
               fixed(request.budget_us, 0) + " us budget of the " + period +
               ": the disc thread will overrun and the disc lag the hand (give a "
               "larger --disc-budget-us or a coarser --disc-cell-size)";
    s.chosen = c;
    s.plates = held_plates(model->mesh());
    s.palpation = std::make_unique<haptics::DiscPalpation>(make(), request.palpation);
    s.make_disc = make;
    s.model = std::move(model);
    break;
  }
  if (!fixed_size && s.chosen.fits && s.chosen.tets < request.min_tets) {
    const DiscCandidate& finest = s.tried.front();
    s.note = "could not hold " + std::to_string(request.min_tets) + " tets within " +
             fixed(request.budget_us, 0) + " us on this CPU (" + std::to_string(finest.tets) +
             " tets: fourth-worst step CPU " + fixed(finest.judged_cpu_us, 0) + " us); running " +
             std::to_string(s.chosen.tets) + " tets";
  }
  return s;
}

}  // namespace spinesim::studies

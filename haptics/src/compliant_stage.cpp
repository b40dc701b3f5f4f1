#include "spinesim/haptics/compliant_stage.hpp"

#include "blas_threads.hpp"

#include "spinesim/common/timer.hpp"
#include "spinesim/spine/kinematics.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <stdexcept>

namespace spinesim::haptics {

namespace {

/// The rigid motion of displacement row `d` (translation mm, rotation vector deg) about c.
spine::Pose pose_of(const Eigen::Vector3d& c, const Eigen::Matrix<double, 1, 6>& d) {
  return spine::pose_from_displacement(c, d.head<3>().transpose(), d.tail<3>().transpose());
}

}  // namespace

void relative_poses(const std::vector<Eigen::Vector3d>& centres_mm, const SpineDisplacement& from,
                    const SpineDisplacement& to, const std::array<int, kSpineVertebrae>& body_of,
                    ScenePoses& poses) {
  for (int i = 0; i < kSpineVertebrae; ++i) {
    if (body_of[std::size_t(i)] < 0) continue;
    const spine::Pose a = pose_of(centres_mm[std::size_t(i)], from.row(i));
    const spine::Pose b = pose_of(centres_mm[std::size_t(i)], to.row(i));
    spine::Pose& out = poses.pose[std::size_t(body_of[std::size_t(i)])];
    out.R = b.R * a.R.transpose();
    out.t = b.t - out.R * a.t;
  }
}

// --- the database ------------------------------------------------------------------------------

DatabaseResponse::DatabaseResponse(const spine::DisplacementDatabase& db)
    : db_(db), baseline_(db.baseline()) {}

void DatabaseResponse::predict(const HookLoad& load, SpineDisplacement& relative) {
  if (load.vertebra < 0 || !db_.has_vertebra(load.vertebra) || !load.force_n.allFinite()) {
    relative.setZero();
    return;
  }
  Eigen::Vector3d f = load.force_n;
  for (int a = 0; a < 3; ++a) {
    const int d = 2 * a + (f[a] < 0 ? 1 : 0);
    const double most = db_.solved_max_n(load.vertebra, d);
    f[a] = std::clamp(f[a], -most, most);
  }
  db_.evaluate(load.vertebra, f, relative);
}

// --- the multirate spine -----------------------------------------------------------------------

MultirateSpine::MultirateSpine(const spine::SpineModel& model, const MultirateOptions& options)
    : model_(model), options_(options) {
  if (int(model.vertebrae.size()) != kSpineVertebrae)
    throw std::invalid_argument("the multirate spine needs the 17-vertebra model");
  if (!(options.max_force_n > 0) || options.max_force_n > spine::kMaxForceN)
    throw std::invalid_argument("multirate spine: the largest hook force must be > 0 and at most " +
                                std::to_string(int(spine::kMaxForceN)) + " N");
  if (options.handover_ticks < 0 || options.handover_ticks > 1000)
    throw std::invalid_argument("multirate spine: the handover must be 0 to 1000 ticks");
  const spine::SpineSolution gravity = spine::solve_spine(model, {}, options.solve);
  baseline_ = gravity.displacement;
}

MultirateSpine::~MultirateSpine() { stop(); }

LocalSpineModel MultirateSpine::solve(const HookLoad& load, const LocalSpineModel* previous,
                                      bool full) const {
  spine::ExternalLoad l;
  l.vertebra = load.vertebra;
  l.force_n = load.force_n;
  l.has_point = true;
  l.point_mm = load.point_mm;
  const std::vector<spine::ExternalLoad> loads = {l};
  const spine::SpineSolution s = spine::solve_spine(model_, loads, options_.solve);
  LocalSpineModel out;
  out.vertebra = load.vertebra;
  out.point_mm = load.point_mm;
  out.force_n = load.force_n;
  out.relative = s.displacement - baseline_;
  if (previous && !full) {
    // Broyden: the smallest change of S that maps the last force step onto the last response
    // step.
    out.sensitivity = previous->sensitivity;
    const Eigen::Vector3d dF = load.force_n - previous->force_n;
    if (dF.squaredNorm() > 1e-6) {
      Eigen::Matrix<double, 6 * kSpineVertebrae, 1> dd;
      for (int i = 0; i < kSpineVertebrae; ++i)
        dd.segment<6>(6 * i) = (out.relative.row(i) - previous->relative.row(i)).transpose();
      out.sensitivity += (dd - out.sensitivity * dF) * dF.transpose() / dF.squaredNorm();
    }
    return out;
  }
  out.sensitivity = spine::displacement_sensitivity(
      model_, loads, s, 0, options_.solve, options_.sensitivity_step_n,
      full ? spine::SensitivityMethod::automatic : spine::SensitivityMethod::fixed_muscles);
  return out;
}

namespace {

bool made_for(const LocalSpineModel& m, const HookLoad& load) {
  return load.vertebra >= 0 && m.vertebra == load.vertebra && m.point_mm == load.point_mm;
}

/// The local model's linear prediction at `force`, into `out` (or blended into it with weight w).
void linear_prediction(const LocalSpineModel& m, const Eigen::Vector3d& force, double w,
                       SpineDisplacement& out) {
  const Eigen::Vector3d dF = force - m.force_n;
  for (int i = 0; i < kSpineVertebrae; ++i)
    for (int c = 0; c < 6; ++c)
      out(i, c) =
          (1 - w) * out(i, c) + w * (m.relative(i, c) + m.sensitivity.row(6 * i + c).dot(dF));
}

}  // namespace

void MultirateSpine::predict(const HookLoad& load, SpineDisplacement& relative) {
  const LocalSpineModel& m = model_out_.read();
  if (m.solve != current_.solve) {  // a new model: hand over from the one in use
    previous_ = current_;
    current_ = m;
    handover_left_ =
        made_for(previous_, load) && made_for(current_, load) ? options_.handover_ticks : 0;
  }
  if (!made_for(current_, load)) {
    relative.setZero();
    return;
  }
  relative.setZero();
  double w = 1;
  if (handover_left_ > 0) {
    linear_prediction(previous_, load.force_n, 1, relative);
    w = 1.0 - double(handover_left_) / double(options_.handover_ticks + 1);
  }
  linear_prediction(current_, load.force_n, w, relative);
}

void MultirateSpine::publish(const HookLoad& load) {
  if (handover_left_ > 0) --handover_left_;
  request_.write(load);
}

void MultirateSpine::start() {
  if (worker_.joinable()) return;
  // The worker's solves reach OpenBLAS through Ipopt's linear solver (blas_threads.hpp).
  detail::use_one_blas_thread();
  stop_.store(false);
  worker_ = std::thread([this] { run(); });
}

void MultirateSpine::stop() {
  stop_.store(true);
  if (worker_.joinable()) worker_.join();
  if (stats_.solves > 0) stats_.mean_update_s = stats_.busy_s / double(stats_.solves);
}

void MultirateSpine::run() {
  HookLoad last;
  LocalSpineModel model;
  std::int64_t sequence = 0, since_full = 0;
  Timer clock;
  while (!stop_.load()) {
    const HookLoad load = request_.read();
    if (load.vertebra < 0 || (load.vertebra == last.vertebra && load.point_mm == last.point_mm &&
                              load.force_n == last.force_n)) {
      std::this_thread::sleep_for(std::chrono::milliseconds(1));
      continue;
    }
    const bool same_hook = model.vertebra == load.vertebra && model.point_mm == load.point_mm;
    const bool recruited = options_.solve.recruit && !model_.muscles.empty();
    // A new hook: one solve and the cheap derivative first, so the spine gives at once.
    const bool full = same_hook && (!recruited || since_full >= options_.full_sensitivity_every);
    Timer t;
    try {
      model = solve(load, same_hook ? &model : nullptr, full);
      since_full = full ? 0 : since_full + 1;
      if (!same_hook) since_full = options_.full_sensitivity_every;  // full next time
      model.solve = ++sequence;
      model.solved_at_s = clock.seconds();
      model_out_.write(model);
      ++stats_.solves;
      last = load;
    } catch (const std::exception& e) {
      ++stats_.failures;
      stats_.last_error = e.what();
      last = load;  // not again at the same force
    }
    stats_.busy_s += t.seconds();
  }
}

// --- the stage ---------------------------------------------------------------------------------

CompliantStage::CompliantStage(SpineResponse& response,
                               const std::vector<Eigen::Vector3d>& centres_mm,
                               const std::array<int, kSpineVertebrae>& body_of,
                               const CouplingParameters& p)
    : response_(response), centres_(centres_mm), body_of_(body_of), p_(p) {
  if (int(centres_mm.size()) != kSpineVertebrae)
    throw std::invalid_argument("compliant stage: 17 vertebra centres expected");
  if (!(p.stiffness_n_per_mm > 0) || !(p.force_scale > 0))
    throw std::invalid_argument("compliant stage: coupling stiffness and force scale must be > 0");
  for (int b : body_of)
    if (b < 0 || b >= kMaxBodies)
      throw std::invalid_argument("compliant stage: every vertebra T1-L5 must be in the scene");
  if (!(p.damping_n_s_per_mm >= 0) || !(p.ramp_s >= 0))
    throw std::invalid_argument("compliant stage: coupling damping and ramp must be >= 0");
}

void CompliantStage::update(const DeviceState& device, const RenderOutput& last, double dt_s,
                            ScenePoses& poses) {
  const bool pressed = (device.buttons & p_.button_mask) != 0;
  const bool press = pressed && !(last_buttons_ & p_.button_mask);
  last_buttons_ = device.buttons;
  HookState& s = state_;
  if (press && last.contact && !s.attached) {
    for (int i = 0; i < kSpineVertebrae; ++i)
      if (body_of_[std::size_t(i)] >= 0 && body_of_[std::size_t(i)] == last.body) {
        s.attached = true;
        s.load.vertebra = i;
        s.load.point_mm = to_body(poses, last.body, last.proxy_mm);
        last_hook_mm_ = last.proxy_mm;
      }
  }
  if (!pressed) s.attached = false;
  const double step = p_.ramp_s > 0 ? dt_s / p_.ramp_s : 1.0;
  s.gain = std::clamp(s.gain + (s.attached ? step : -step), 0.0, 1.0);
  if (s.gain == 0 && !s.attached) {
    s.load.vertebra = -1;
    s.load.force_n.setZero();
    s.felt_force_n.setZero();
    s.clamped = false;
  } else {
    const double spring = s.gain * p_.force_scale * p_.stiffness_n_per_mm;  // on the spine, N/mm
    Eigen::Vector3d spine_force = equilibrium_force(device.position_mm, spring);
    const double most = response_.max_force_n();
    s.clamped = !(spine_force.norm() <= most);
    if (s.clamped) spine_force *= most / spine_force.norm();
    if (!spine_force.allFinite()) spine_force.setZero();
    s.load.force_n = spine_force;
    s.hook_mm = hook_at(spine_force);
    const Eigen::Vector3d hook_velocity =
        dt_s > 0 ? Eigen::Vector3d((s.hook_mm - last_hook_mm_) / dt_s) : Eigen::Vector3d::Zero();
    last_hook_mm_ = s.hook_mm;
    s.felt_force_n = -spine_force / p_.force_scale -
                     s.gain * p_.damping_n_s_per_mm * (device.velocity_mm_s - hook_velocity);
  }
  response_.predict(s.load, relative_);
  response_.publish(s.load);
  absolute_ = response_.baseline() + relative_;
  relative_poses(centres_, response_.baseline(), absolute_, body_of_, poses);
}

Eigen::Vector3d CompliantStage::hook_at(const Eigen::Vector3d& force) {
  HookLoad load = state_.load;
  load.force_n = force;
  response_.predict(load, relative_);
  const int v = load.vertebra;
  const auto& base = response_.baseline();
  const spine::Pose a = pose_of(centres_[std::size_t(v)], base.row(v));
  const spine::Pose b = pose_of(centres_[std::size_t(v)], base.row(v) + relative_.row(v));
  return b.apply(a.R.transpose() * (load.point_mm - a.t));
}

Eigen::Vector3d CompliantStage::equilibrium_force(const Eigen::Vector3d& probe_mm,
                                                  double spring_n_per_mm) {
  // g(F) = F − c (probe − hook(F)) = 0 from the last tick's force; the hook point in the
  // response's reference posture is load.point_mm, carried by the vertebra's relative motion.
  Eigen::Vector3d F = state_.load.force_n;
  if (!F.allFinite()) F.setZero();
  const double delta = 1.0;  // N, the Jacobian's difference step
  for (int it = 0; it < 3; ++it) {
    const Eigen::Vector3d h0 = hook_at(F);
    const Eigen::Vector3d g = F - spring_n_per_mm * (probe_mm - h0);
    if (g.norm() < 1e-3) break;
    Eigen::Matrix3d J = Eigen::Matrix3d::Identity();
    for (int a = 0; a < 3; ++a)
      J.col(a) += spring_n_per_mm * (hook_at(F + delta * Eigen::Vector3d::Unit(a)) - h0) / delta;
    F -= J.partialPivLu().solve(g);
  }
  return F;
}

Eigen::Vector3d CompliantStage::blend(const Eigen::Vector3d& contact_force_n) const {
  return (1 - state_.gain) * contact_force_n + state_.felt_force_n;
}

}  // namespace spinesim::haptics

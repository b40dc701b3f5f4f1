#include "spinesim/haptics/compliant_stage.hpp"

#include "spinesim/common/timer.hpp"
#include "spinesim/spine/kinematics.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <stdexcept>

namespace spinesim::haptics {

namespace {

constexpr double kDegToRad = M_PI / 180.0;

/// The rigid motion of displacement row `d` about centre c: x ↦ R x + c + Δt − R c.
spine::Pose pose_of(const Eigen::Vector3d& c, const Eigen::Matrix<double, 1, 6>& d) {
  spine::Pose p;
  p.R = spine::rotation_exp(d.tail<3>().transpose() * kDegToRad);
  p.t = c + d.head<3>().transpose() - p.R * c;
  return p;
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
  const spine::SpineSolution gravity = spine::solve_spine(model, {}, options.solve);
  baseline_ = gravity.displacement;
}

MultirateSpine::~MultirateSpine() { stop(); }

LocalSpineModel MultirateSpine::solve(const HookLoad& load) const {
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
  out.sensitivity = spine::displacement_sensitivity(model_, loads, s, 0, options_.solve,
                                                    options_.sensitivity_step_n);
  return out;
}

void MultirateSpine::predict(const HookLoad& load, SpineDisplacement& relative) {
  request_.write(load);
  const LocalSpineModel& m = model_out_.read();
  if (load.vertebra < 0 || m.vertebra != load.vertebra || m.point_mm != load.point_mm) {
    relative.setZero();
    return;
  }
  const Eigen::Vector3d dF = load.force_n - m.force_n;
  for (int i = 0; i < kSpineVertebrae; ++i)
    for (int c = 0; c < 6; ++c)
      relative(i, c) = m.relative(i, c) + m.sensitivity.row(6 * i + c).dot(dF);
}

void MultirateSpine::start() {
  if (worker_.joinable()) return;
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
  std::int64_t sequence = 0;
  Timer clock;
  while (!stop_.load()) {
    const HookLoad load = request_.read();
    if (load.vertebra < 0 || (load.vertebra == last.vertebra && load.point_mm == last.point_mm &&
                              load.force_n == last.force_n)) {
      std::this_thread::sleep_for(std::chrono::milliseconds(1));
      continue;
    }
    Timer t;
    try {
      LocalSpineModel m = solve(load);
      m.solve = ++sequence;
      m.solved_at_s = clock.seconds();
      model_out_.write(m);
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
    const int body = body_of_[std::size_t(s.load.vertebra)];
    s.hook_mm = poses.pose[std::size_t(body)].apply(s.load.point_mm);
    const Eigen::Vector3d hook_velocity =
        dt_s > 0 ? Eigen::Vector3d((s.hook_mm - last_hook_mm_) / dt_s) : Eigen::Vector3d::Zero();
    last_hook_mm_ = s.hook_mm;
    Eigen::Vector3d spring = s.gain * p_.stiffness_n_per_mm * (device.position_mm - s.hook_mm);
    Eigen::Vector3d spine_force = p_.force_scale * spring;
    const double most = response_.max_force_n();
    s.clamped = !(spine_force.norm() <= most);
    if (s.clamped) spine_force *= most / spine_force.norm();
    if (!spine_force.allFinite()) spine_force.setZero();
    s.load.force_n = spine_force;
    s.felt_force_n = -spine_force / p_.force_scale -
                     s.gain * p_.damping_n_s_per_mm * (device.velocity_mm_s - hook_velocity);
  }
  response_.predict(s.load, relative_);
  absolute_ = response_.baseline() + relative_;
  relative_poses(centres_, response_.baseline(), absolute_, body_of_, poses);
}

Eigen::Vector3d CompliantStage::blend(const Eigen::Vector3d& contact_force_n) const {
  return (1 - state_.gain) * contact_force_n + state_.felt_force_n;
}

}  // namespace spinesim::haptics

#include "spinesim/haptics/compliant_stage.hpp"

#include "blas_threads.hpp"

#include "spinesim/common/constants.hpp"
#include "spinesim/common/rotation.hpp"
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
  l.moment_nmm = load.moment_nmm;
  l.has_point = true;
  l.point_mm = load.point_mm;
  const std::vector<spine::ExternalLoad> loads = {l};
  const spine::SpineSolution s = spine::solve_spine(model_, loads, options_.solve);
  LocalSpineModel out;
  out.vertebra = load.vertebra;
  out.point_mm = load.point_mm;
  out.force_n = load.force_n;
  out.moment_nmm = load.moment_nmm;
  out.relative = s.displacement - baseline_;
  const auto flat = [](const SpineDisplacement& d) {
    Eigen::Matrix<double, 6 * kSpineVertebrae, 1> v;
    for (int i = 0; i < kSpineVertebrae; ++i) v.segment<6>(6 * i) = d.row(i).transpose();
    return v;
  };
  if (previous && !full) {
    // Broyden: the smallest change of S that maps the last load step onto the last response
    // step. The moment is measured in N × 50 mm (a vertebra's size), so that a newton and a
    // newton-metre-ish couple weigh alike in "smallest".
    const double arm_mm = 50;
    Eigen::Matrix<double, 6 * kSpineVertebrae, 6> S = previous->sensitivity;
    S.rightCols<3>() *= arm_mm;
    Eigen::Matrix<double, 6, 1> du;
    du << load.force_n - previous->force_n, (load.moment_nmm - previous->moment_nmm) / arm_mm;
    if (du.squaredNorm() > 1e-6)
      S += (flat(out.relative - previous->relative) - S * du) * du.transpose() / du.squaredNorm();
    S.rightCols<3>() /= arm_mm;
    out.sensitivity = S;
    return out;
  }
  out.sensitivity.leftCols<3>() = spine::displacement_sensitivity(
      model_, loads, s, 0, options_.solve, options_.sensitivity_step_n,
      full ? spine::SensitivityMethod::automatic : spine::SensitivityMethod::fixed_muscles);
  if (load.twist && full) {
    // ∂d/∂M by forward differences of whole solves (recruitment changes with the couple).
    for (int k = 0; k < 3; ++k) {
      std::vector<spine::ExternalLoad> moved = loads;
      moved[0].moment_nmm[k] += options_.sensitivity_step_nmm;
      const spine::SpineSolution sk = spine::solve_spine(model_, moved, options_.solve);
      out.sensitivity.col(3 + k) =
          flat(sk.displacement - s.displacement) / options_.sensitivity_step_nmm;
    }
  }
  return out;
}

namespace {

bool made_for(const LocalSpineModel& m, const HookLoad& load) {
  return load.vertebra >= 0 && m.vertebra == load.vertebra && m.point_mm == load.point_mm;
}

/// The local model's linear prediction at `load`, into `out` (or blended into it with weight w).
void linear_prediction(const LocalSpineModel& m, const HookLoad& load, double w,
                       SpineDisplacement& out) {
  Eigen::Matrix<double, 6, 1> dW;
  dW << load.force_n - m.force_n, load.moment_nmm - m.moment_nmm;
  for (int i = 0; i < kSpineVertebrae; ++i)
    for (int c = 0; c < 6; ++c)
      out(i, c) =
          (1 - w) * out(i, c) + w * (m.relative(i, c) + m.sensitivity.row(6 * i + c).dot(dW));
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
    linear_prediction(previous_, load, 1, relative);
    w = 1.0 - double(handover_left_) / double(options_.handover_ticks + 1);
  }
  linear_prediction(current_, load, w, relative);
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
                              load.force_n == last.force_n && load.moment_nmm == last.moment_nmm)) {
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
  if (!(p.damping_n_s_per_mm >= 0) || !(p.ramp_s >= 0) ||
      !(p.rotational_stiffness_nmm_per_rad >= 0) || !(p.rotational_damping_nmm_s_per_rad >= 0))
    throw std::invalid_argument(
        "compliant stage: coupling damping, ramp and rotational stiffness must be >= 0");
  twists_ = p.rotational_stiffness_nmm_per_rad > 0 && response.max_moment_nmm() > 0;
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
        s.load.twist = twists_;
        last_hook_mm_ = last.proxy_mm;
        grip_at_press_ = device.orientation;
        Vector6d held;
        held << s.load.force_n, s.load.moment_nmm;
        hook_at(held, &vertebra_at_press_);
        last_vertebra_ = vertebra_at_press_;
      }
  }
  if (!pressed) s.attached = false;
  const double step = p_.ramp_s > 0 ? dt_s / p_.ramp_s : 1.0;
  s.gain = std::clamp(s.gain + (s.attached ? step : -step), 0.0, 1.0);
  if (s.gain == 0 && !s.attached) {
    s.load.vertebra = -1;
    s.load.force_n.setZero();
    s.load.moment_nmm.setZero();
    s.felt_force_n.setZero();
    s.felt_torque_nmm.setZero();
    s.twist_deg.setZero();
    s.clamped = false;
  } else {
    const double spring = s.gain * p_.force_scale * p_.stiffness_n_per_mm;  // on the spine, N/mm
    const double torsion =
        twists_ ? s.gain * p_.force_scale * p_.rotational_stiffness_nmm_per_rad : 0;  // N·mm/rad
    const Eigen::Matrix3d turn = device.orientation * grip_at_press_.transpose();
    Vector6d W = equilibrium_load(device.position_mm, turn, spring, torsion);
    const double most = response_.max_force_n(), most_moment = response_.max_moment_nmm();
    const bool force_clamped = !(W.head<3>().norm() <= most);
    if (force_clamped) W.head<3>() *= most / W.head<3>().norm();
    const bool moment_clamped = twists_ && !(W.tail<3>().norm() <= most_moment);
    if (moment_clamped) W.tail<3>() *= most_moment / W.tail<3>().norm();
    if (!twists_) W.tail<3>().setZero();
    if (!W.allFinite()) W.setZero();
    s.clamped = force_clamped || moment_clamped;
    s.load.force_n = W.head<3>();
    s.load.moment_nmm = W.tail<3>();
    Eigen::Matrix3d vertebra;
    s.hook_mm = hook_at(W, &vertebra);
    const Eigen::Vector3d hook_velocity =
        dt_s > 0 ? Eigen::Vector3d((s.hook_mm - last_hook_mm_) / dt_s) : Eigen::Vector3d::Zero();
    const Eigen::Vector3d vertebra_spin =
        dt_s > 0 ? Eigen::Vector3d(rotation_log_total(vertebra * last_vertebra_.transpose()) / dt_s)
                 : Eigen::Vector3d::Zero();
    last_hook_mm_ = s.hook_mm;
    last_vertebra_ = vertebra;
    s.felt_force_n = -s.load.force_n / p_.force_scale -
                     s.gain * p_.damping_n_s_per_mm * (device.velocity_mm_s - hook_velocity);
    s.twist_deg =
        twists_ ? Eigen::Vector3d(twist(turn, vertebra) / kRadPerDeg) : Eigen::Vector3d::Zero();
    s.felt_torque_nmm = twists_
                            ? Eigen::Vector3d(-s.load.moment_nmm / p_.force_scale -
                                              s.gain * p_.rotational_damping_nmm_s_per_rad *
                                                  (device.angular_velocity_rad_s - vertebra_spin))
                            : Eigen::Vector3d::Zero();
  }
  response_.predict(s.load, relative_);
  response_.publish(s.load);
  absolute_ = response_.baseline() + relative_;
  relative_poses(centres_, response_.baseline(), absolute_, body_of_, poses);
  if (ribs_) {
    for (std::size_t i = 0; i < thoracic_bodies_.size(); ++i)
      thoracic_[i] = poses.pose[std::size_t(thoracic_bodies_[i])];
    ribs_->pose(thoracic_.data(), rib_poses_.data());
    for (std::size_t b = 0; b < rib_bodies_.size(); ++b)
      poses.pose[std::size_t(rib_bodies_[b])] = rib_poses_[b];
  }
}

void CompliantStage::attach_rib_cage(const spine::RibCage& cage,
                                     const std::vector<spine::Vertebra>& vertebrae,
                                     const std::vector<int>& bodies) {
  if (bodies.size() != cage.body_centres_mm.size())
    throw std::invalid_argument("compliant stage: one scene body per rib and the sternum");
  for (int b : bodies)
    if (b < 0 || b >= kMaxBodies)
      throw std::invalid_argument("compliant stage: a rib body outside the scene");
  thoracic_bodies_.clear();
  for (int v : cage.vertebrae) {
    if (v < 0 || v >= kSpineVertebrae)
      throw std::invalid_argument("compliant stage: the rib cage hangs on T1-T12");
    thoracic_bodies_.push_back(body_of_[std::size_t(v)]);
  }
  ribs_ = std::make_unique<spine::RibCagePoser>(cage, vertebrae);
  rib_bodies_ = bodies;
  thoracic_.assign(thoracic_bodies_.size(), spine::Pose());
  rib_poses_.assign(bodies.size(), spine::Pose());
}

Eigen::Vector3d CompliantStage::hook_at(const Vector6d& W, Eigen::Matrix3d* rotation) {
  HookLoad load = state_.load;
  load.force_n = W.head<3>();
  load.moment_nmm = W.tail<3>();
  response_.predict(load, relative_);
  const int v = load.vertebra;
  const auto& base = response_.baseline();
  const spine::Pose a = pose_of(centres_[std::size_t(v)], base.row(v));
  const spine::Pose b = pose_of(centres_[std::size_t(v)], base.row(v) + relative_.row(v));
  if (rotation) *rotation = b.R * a.R.transpose();
  return b.apply(a.R.transpose() * (load.point_mm - a.t));
}

Eigen::Vector3d CompliantStage::twist(const Eigen::Matrix3d& turn,
                                      const Eigen::Matrix3d& vertebra) const {
  return rotation_log_total(turn * (vertebra * vertebra_at_press_.transpose()).transpose());
}

CompliantStage::Vector6d CompliantStage::equilibrium_load(const Eigen::Vector3d& probe_mm,
                                                          const Eigen::Matrix3d& turn,
                                                          double spring_n_per_mm,
                                                          double torsion_nmm_per_rad) {
  // g(F, M) = (F − c (probe − hook(F, M)), M − c_r φ(F, M)) = 0 from the last tick's load; the
  // hook point in the response's reference posture is load.point_mm, carried by the vertebra's
  // relative motion, and φ is the stylus's turn against the vertebra's. Without a torsional
  // spring only the force is solved for (M stays 0).
  Vector6d W;
  W << state_.load.force_n, state_.load.moment_nmm;
  if (!W.allFinite() || !(torsion_nmm_per_rad > 0)) W.tail<3>().setZero();
  if (!W.allFinite()) W.setZero();
  const bool six = torsion_nmm_per_rad > 0;
  const auto residual = [&](const Vector6d& w) {
    Eigen::Matrix3d R;
    Vector6d g;
    g.head<3>() = w.head<3>() - spring_n_per_mm * (probe_mm - hook_at(w, &R));
    g.tail<3>() = six ? Eigen::Vector3d(w.tail<3>() - torsion_nmm_per_rad * twist(turn, R))
                      : Eigen::Vector3d(w.tail<3>());
    return g;
  };
  const double arm_mm = 50;  // a moment residual in N·mm weighs as a force one in N at 50 mm
  for (int it = 0; it < 3; ++it) {
    const Vector6d g0 = residual(W);
    if (std::hypot(g0.head<3>().norm(), g0.tail<3>().norm() / arm_mm) < 1e-3) break;
    Eigen::Matrix<double, 6, 6> J = Eigen::Matrix<double, 6, 6>::Identity();
    for (int a = 0; a < (six ? 6 : 3); ++a) {
      const double delta = a < 3 ? 1.0 : arm_mm;  // N, N·mm: the Jacobian's difference steps
      J.col(a) = (residual(W + delta * Vector6d::Unit(a)) - g0) / delta;
    }
    if (six)
      W -= J.partialPivLu().solve(g0);
    else
      W.head<3>() -= J.topLeftCorner<3, 3>().partialPivLu().solve(g0.head<3>());
  }
  return W;
}

Eigen::Vector3d CompliantStage::blend(const Eigen::Vector3d& contact_force_n) const {
  return (1 - state_.gain) * contact_force_n + state_.felt_force_n;
}

}  // namespace spinesim::haptics

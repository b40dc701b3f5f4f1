#include "spinesim/haptics/disc_palpation.hpp"
#include "spinesim/mss/simulator.hpp"

#include "spinesim/haptics/servo.hpp"
#include "spinesim/mss/quantities.hpp"

#include "blas_threads.hpp"
#include "monotonic_clock.hpp"

#include <pthread.h>
#include <sched.h>
#include <time.h>

#include <Eigen/Dense>
#include <Eigen/Eigenvalues>

#include <algorithm>
#include <array>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <map>
#include <stdexcept>

namespace spinesim::haptics {

using detail::monotonic_s;
using detail::to_timespec;

namespace {

void require(bool ok, const char* what) {
  if (!ok) throw std::invalid_argument(std::string("disc palpation: ") + what);
}

mss::DynamicsOptions dynamics(const DiscPalpationOptions& o) {
  require(std::isfinite(o.coupling_stiffness_n_per_mm) && o.coupling_stiffness_n_per_mm > 0,
          "the coupling stiffness must be > 0 N/mm");
  require(std::isfinite(o.coupling_damping_n_s_per_mm) && o.coupling_damping_n_s_per_mm >= 0,
          "the coupling damping must be >= 0 N·s/mm");
  require(std::isfinite(o.probe_radius_mm) && o.probe_radius_mm > 0,
          "the probe radius must be > 0 mm");
  require(std::isfinite(o.probe_penalty_n_per_mm) && o.probe_penalty_n_per_mm >= 0,
          "the probe penalty must be >= 0 N/mm (0: the default)");
  require(std::isfinite(o.dt_s) && o.dt_s > 0 && o.dt_s <= 0.01, "the step must be in (0, 10] ms");
  require(o.newton_iterations >= 1 && o.newton_iterations <= 20,
          "the Newton iterations must be 1 to 20");
  require(std::isfinite(o.force_scale) && o.force_scale >= 1 && o.force_scale <= 1e4,
          "the force scale must be 1 to 10,000 (disc N per felt N)");
  mss::DynamicsOptions d;
  d.integrator = mss::Integrator::implicit_euler;
  d.dt_s = o.dt_s;
  d.newton_iterations = o.newton_iterations;
  d.matrix_update = mss::MatrixUpdate::frozen;
  return d;
}

}  // namespace

LocalContact evaluate_local_model(const DiscContact& c, double kcd, const Eigen::Vector3d& device) {
  LocalContact out{device, Eigen::Vector3d::Zero(), false};
  if (!c.model) return out;
  const Eigen::Vector3d p = c.model_inverse * (kcd * device + c.model_offset);
  const Eigen::Vector3d f = kcd * (p - device);  // the disc's force on the probe, balanced
  if (!p.allFinite() || !(f.dot(c.model_normal) > 0)) return out;
  return {p, f, true};
}

double surface_gap_mm(const mesh::TetMesh& m) {
  // Boundary faces (the faces of exactly one tet) of the outer wall.
  std::map<std::array<int, 3>, int> count;
  static constexpr int kFaces[4][3] = {{1, 2, 3}, {0, 2, 3}, {0, 1, 3}, {0, 1, 2}};
  for (Eigen::Index t = 0; t < m.num_tets(); ++t)
    for (const auto& f : kFaces) {
      std::array<int, 3> key = {m.T(t, f[0]), m.T(t, f[1]), m.T(t, f[2])};
      std::sort(key.begin(), key.end());
      ++count[key];
    }
  double gap = 0;
  for (const auto& [key, n] : count) {
    if (n != 1) continue;
    const int l = m.surface(key[0]);
    if ((l == 1 || l == 2) && m.surface(key[1]) == l && m.surface(key[2]) == l)
      continue;  // an endplate face: the vertebra covers it
    const Eigen::Vector3d a = m.V.row(key[0]), b = m.V.row(key[1]), c = m.V.row(key[2]);
    // Circumradius |ab| |bc| |ca| / (4 area).
    const double area2 = (b - a).cross(c - a).norm();
    if (area2 <= 0) continue;
    gap = std::max(gap, (b - a).norm() * (c - b).norm() * (a - c).norm() / (2 * area2));
  }
  return gap;
}

MssPalpableDisc::MssPalpableDisc(const mss::MssModel& model, const mss::Boundary& plates,
                                 double radius_mm, double penalty_n_per_mm,
                                 const mss::DynamicsOptions& dynamics)
    : model_(model), sim_(model, dynamics), bc_(plates) {
  mss::validate(bc_, model.num_nodes());
  state_ = sim_.rest_state();
  mss::Probe probe;
  probe.radius_mm = radius_mm;
  probe.stiffness_n_per_mm =
      penalty_n_per_mm > 0 ? penalty_n_per_mm : mss::default_probe_stiffness(model);
  probe.center_mm = Eigen::Vector3d::Constant(1e9);  // far away until the first step
  bc_.probes = {probe};
  // The factorisation (~0.2 s at 20,000 tets) is done here, not in the disc thread's first
  // loaded step while the hand is on the disc.
  if (!sim_.prepare(bc_))
    throw std::invalid_argument(
        "disc palpation: the disc's implicit matrix is not positive definite");
}

bool MssPalpableDisc::step(const Eigen::Vector3d& center_mm) {
  bc_.probes[0].center_mm = center_mm;
  const bool ok = sim_.step(state_, bc_).ok;
  force_ = mss::probe_forces(model_, bc_, state_.x_mm)[0];
  return ok;
}

double MssPalpableDisc::volume_change() const { return mss::volume_change(model_, state_.x_mm); }

std::unique_ptr<PalpableDisc> make_mss_palpable_disc(const mss::MssModel& model,
                                                     const mss::Boundary& plates,
                                                     const DiscPalpationOptions& options) {
  return std::make_unique<MssPalpableDisc>(model, plates, options.probe_radius_mm,
                                           options.probe_penalty_n_per_mm, dynamics(options));
}

DiscPalpation::DiscPalpation(const mss::MssModel& model, const mss::Boundary& plates,
                             const DiscPalpationOptions& options)
    : DiscPalpation(make_mss_palpable_disc(model, plates, options), options) {}

DiscPalpation::DiscPalpation(std::unique_ptr<PalpableDisc> disc,
                             const DiscPalpationOptions& options)
    : options_(options), disc_(std::move(disc)) {
  // CHOLMOD's supernodal solves call OpenBLAS, whose threads busy-wait beside the servo thread
  // (blas_threads.hpp); measured: the 5,099-tet step pressed took 1.5 ms with them.
  detail::use_one_blas_thread();
  dynamics(options);  // validates the options
  require(disc_ != nullptr, "no disc");
  require(disc_->probe_radius_mm() == options.probe_radius_mm,
          "the disc was made for another probe radius");
  const double gap = surface_gap_mm(disc_->mesh());
  if (!(options.probe_radius_mm > gap)) {
    char why[256];
    std::snprintf(why, sizeof why,
                  "disc palpation: a probe of radius %.1f mm would slip between the disc's surface "
                  "nodes (up to %.1f mm from the nearest): give a larger radius or a finer disc",
                  options.probe_radius_mm, gap);
    throw std::invalid_argument(why);
  }
  const mesh::TetMesh& m = disc_->mesh();
  for (Eigen::Index i = 0; i < m.num_vertices(); ++i)
    if (m.surface(i) != 0) surface_nodes_.push_back(i);
  last_.probe_mm = Eigen::Vector3d::Constant(1e9);
  out_.write(last_);
  positions_.reset(disc_->positions_mm());
}

DiscPalpation::~DiscPalpation() { stop(); }

Eigen::Vector3d DiscPalpation::place_probe(const Eigen::Vector3d& device) const {
  // The nodes that can touch the probe on its way from the device towards the surface.
  const double r = options_.probe_radius_mm, kc = disc_coupling_n_per_mm();
  const double k_p = disc_->probe_penalty_n_per_mm();
  const Eigen::VectorXd& x = disc_->positions_mm();
  auto energy = [&](const Eigen::Vector3d& p, Eigen::Vector3d* g, Eigen::Matrix3d* H) {
    double e = 0.5 * kc * (p - device).squaredNorm();
    if (g) *g = kc * (p - device);
    if (H) *H = kc * Eigen::Matrix3d::Identity();
    for (const Eigen::Index i : surface_nodes_) {
      const Eigen::Vector3d d = p - x.segment<3>(3 * i);
      const double dist2 = d.squaredNorm();
      if (dist2 >= r * r) continue;
      const double dist = std::sqrt(dist2), pen = r - dist;
      e += 0.5 * k_p * pen * pen;
      if (dist < 1e-12) continue;  // no direction to push along
      const Eigen::Vector3d n = d / dist;
      if (g) *g -= k_p * pen * n;
      if (H) *H += k_p * n * n.transpose();  // Gauss-Newton: the convex part
    }
    return e;
  };
  // From where the probe was (the node penalty is symmetric about each node: started from a
  // device already past the wall's nodes, the minimum on the inner side would be found), in
  // steps of at most r/4, so that it cannot jump over the wall's nodes.
  Eigen::Vector3d p = last_.probe_mm.allFinite() && (last_.probe_mm - device).norm() < 1e6
                          ? last_.probe_mm
                          : device;
  Eigen::Vector3d g;
  Eigen::Matrix3d H;
  double e = energy(p, &g, &H);
  const double max_step = 0.25 * r;
  for (int it = 0; it < 200; ++it) {
    Eigen::Vector3d step = -H.ldlt().solve(g);
    if (step.norm() > max_step) step *= max_step / step.norm();
    double alpha = 1;
    Eigen::Vector3d q = p + step;
    double eq = energy(q, nullptr, nullptr);
    while (eq > e + 1e-4 * alpha * g.dot(step) && alpha > 1e-6) {
      alpha *= 0.5;
      q = p + alpha * step;
      eq = energy(q, nullptr, nullptr);
    }
    p = q;
    e = energy(p, &g, &H);
    if (alpha * step.norm() < 1e-7) break;
  }
  // Free of the disc the minimiser is the device itself (up to round-off): say so exactly.
  if ((p - device).norm() < 1e-9) return device;
  return p;
}

double DiscPalpation::indentation_mm(const Eigen::Vector3d& p) const {
  const double r2 = options_.probe_radius_mm * options_.probe_radius_mm;
  const Eigen::VectorXd& x = disc_->positions_mm();
  const Eigen::VectorXd& X = disc_->rest_positions_mm();
  double worst = 0;
  for (const Eigen::Index i : surface_nodes_)
    if ((p - x.segment<3>(3 * i)).squaredNorm() < 1.21 * r2)  // touched, or just left
      worst = std::max(worst, (x.segment<3>(3 * i) - X.segment<3>(3 * i)).norm());
  return worst;
}

void DiscPalpation::update_local_model(const Eigen::Vector3d& device) {
  const double kcd = disc_coupling_n_per_mm();
  last_.model = false;
  if (!armed_) return;  // started inside: no disc force until the hand has been outside
  Eigen::Matrix3d K;
  Eigen::Vector3d p0, f0, n;
  if (last_.contact && last_.force_n.norm() > 0) {
    // The step's contact stiffness, its negative (sliding) directions dropped: the local model
    // is then a spring network no stiffer than s k_c in series, so the servo's loop is passive.
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(disc_->probe_stiffness());
    K = eig.eigenvectors() * eig.eigenvalues().cwiseMax(0.0).asDiagonal() *
        eig.eigenvectors().transpose();
    p0 = last_.probe_mm;
    f0 = last_.force_n;
    // The probe is massless: the disc's force on it should balance the coupling's. A step whose
    // contact set grew beyond what the last linearisation knew (new wall nodes met at the full
    // penalty) leaves the disc pushing far harder than the hand (measured: 325 N against 45 N
    // at 10 ms steps); such a step's force is not passed on (the coupling's is, which the hand's
    // own spring bounds) and its model does not place the next probe.
    const Eigen::Vector3d coupling = kcd * (p0 - device);
    const bool balanced = f0.norm() <= 1.5 * coupling.norm() + 1.0;
    model_trusted_ = kcd + eig.eigenvalues().minCoeff() > 0.5 * kcd;
    if (!balanced) f0 = coupling;
    n = f0.normalized();
    normal_stiffness_ = n.dot(K * n);
  } else {
    // The onset plane: tangent to the probe sphere resting on the nearest surface node.
    const Eigen::VectorXd& x = disc_->positions_mm();
    Eigen::Index best = -1;
    double best2 = 0;
    for (const Eigen::Index i : surface_nodes_) {
      const double d2 = (device - x.segment<3>(3 * i)).squaredNorm();
      if (best < 0 || d2 < best2) best = i, best2 = d2;
    }
    if (best < 0 || !(best2 > 0)) return;
    n = (device - x.segment<3>(3 * best)) / std::sqrt(best2);
    p0 = x.segment<3>(3 * best) + options_.probe_radius_mm * n;
    f0.setZero();
    const double kn = normal_stiffness_ > 0 ? normal_stiffness_ : disc_->probe_penalty_n_per_mm();
    K = kn * n * n.transpose();
  }
  last_.model_inverse = (kcd * Eigen::Matrix3d::Identity() + K).inverse();
  last_.model_offset = f0 + K * p0;
  last_.model_normal = n;
  last_.model = last_.model_inverse.allFinite() && last_.model_offset.allFinite();
}

bool DiscPalpation::touches_disc(const Eigen::Vector3d& point) const {
  const double r = options_.probe_radius_mm;
  const Eigen::VectorXd& x = disc_->positions_mm();
  for (const Eigen::Index i : surface_nodes_)
    if ((point - x.segment<3>(3 * i)).squaredNorm() < r * r) return true;
  const mesh::TetMesh& m = disc_->mesh();
  for (Eigen::Index t = 0; t < m.num_tets(); ++t) {
    const Eigen::Vector3d a = x.segment<3>(3 * m.T(t, 0));
    Eigen::Matrix3d E;
    for (int k = 1; k < 4; ++k) E.col(k - 1) = x.segment<3>(3 * m.T(t, k)) - a;
    const Eigen::Vector3d l = E.partialPivLu().solve(point - a);
    if (l.minCoeff() >= 0 && l.sum() <= 1) return true;
  }
  return false;
}

const DiscContact& DiscPalpation::step(const Eigen::Vector3d& device_mm) {
  const auto t0 = std::chrono::steady_clock::now();
  // Until the device has been outside the disc once, the probe is not put in: started inside,
  // the probe would be held on the inner side of the wall and pull the hand deeper.
  if (!armed_ && !touches_disc(device_mm)) {
    armed_ = true;
    last_.probe_mm = device_mm;  // the probe starts from here, outside
  }
  // In contact, the probe goes where the coupling balances the disc's response as the last step
  // linearised it (its local model); placed against the disc's old nodes instead, the probe
  // would sink into them by a step's motion and the stiff penalty would push the disc ahead of
  // the hand (measured: 3x the balanced force a step after, relaxing over ~50 ms, at 10 ms steps).
  // Only at a physiological force scale (s > 1: the coupling s k_c is stiff, tens of N/mm), and
  // while the coupling outweighs the contact's negative (sliding) stiffness by 2x
  // and the probe moves less than r/4; else the nodes place it (on a soft coupling a frictionless sphere slides
  // between the nodes, which the one-node model does not see).
  Eigen::Vector3d p = device_mm;
  if (armed_) {
    const LocalContact predicted =
        options_.force_scale > 1 && last_.contact && last_.model && model_trusted_
            ? evaluate_local_model(last_, disc_coupling_n_per_mm(), device_mm)
            : LocalContact{device_mm, Eigen::Vector3d::Zero(), false};
    p = predicted.contact &&
                (predicted.probe_mm - last_.probe_mm).norm() <= 0.25 * options_.probe_radius_mm
            ? predicted.probe_mm
            : place_probe(device_mm);
  }
  last_.device_mm = device_mm;
  const bool ok = disc_->step(p);
  ++last_.step;
  last_.probe_mm = p;
  last_.contact = p != device_mm;
  last_.force_n = last_.contact ? disc_->probe_force_n() : Eigen::Vector3d::Zero().eval();
  last_.volume_change = disc_->volume_change();
  last_.failed = !ok;
  last_.indentation_mm = last_.contact ? indentation_mm(p) : 0.0;
  update_local_model(device_mm);
  last_.step_us =
      std::chrono::duration<double, std::micro>(std::chrono::steady_clock::now() - t0).count();
  return last_;
}

void DiscPalpation::start() {
  if (thread_.joinable()) return;
  stats_ = Stats();
  stats_.step_us.reserve(std::size_t(3600.0 / options_.dt_s));  // an hour of steps
  stop_.store(false);
  thread_ = std::thread([this] { run(); });
}

void DiscPalpation::stop() {
  stop_.store(true);
  if (thread_.joinable()) thread_.join();
}

void DiscPalpation::run() {
  stats_.realtime_priority = options_.realtime_priority &&
                             set_realtime_priority(options_.priority, &stats_.realtime_reason);
  if (!options_.realtime_priority) stats_.realtime_reason = "not asked for";
  double deadline = monotonic_s() + options_.dt_s;
  while (!stop_.load()) {
    const timespec ts = to_timespec(deadline);
    while (::clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &ts, nullptr) == EINTR) {}
    const DiscContact& c = step(device_.read());
    out_.write(c);
    ++stats_.steps;
    // Same-size copy assignment: no allocation on the disc thread.
    if (stats_.steps % positions_every() == 0) positions_.write(disc_->positions_mm());
    stats_.failed_steps += c.failed;
    if (stats_.step_us.size() < stats_.step_us.capacity())
      stats_.step_us.push_back(float(c.step_us));
    stats_.max_force_n = std::max(stats_.max_force_n, c.force_n.norm());
    stats_.max_indentation_mm = std::max(stats_.max_indentation_mm, c.indentation_mm);
    stats_.min_volume_change = std::min(stats_.min_volume_change, c.volume_change);
    stats_.max_volume_change = std::max(stats_.max_volume_change, c.volume_change);
    // The disc's clock keeps the wall clock's: each step advances the disc by dt, so a step
    // that ends past the next one's start is followed at once by the next, on the same grid
    // (one slow step among fast ones costs no step). More than a whole period behind, the
    // missed grid points are dropped and the grid restarts now: the steps never pile up.
    deadline += options_.dt_s;
    const double now = monotonic_s();
    if (now > deadline) {
      ++stats_.overruns;
      if (now > deadline + options_.dt_s) {
        stats_.dropped_periods += std::int64_t((now - deadline) / options_.dt_s);
        deadline = now;
      }
    }
  }
}

std::vector<Eigen::Vector3d> palpate_offline(const mss::MssModel& model,
                                             const mss::Boundary& plates,
                                             const DiscPalpationOptions& options,
                                             const std::vector<Eigen::Vector3d>& device_mm,
                                             double tick_s) {
  return palpate_offline([&] { return make_mss_palpable_disc(model, plates, options); }, options,
                         device_mm, tick_s);
}

std::vector<Eigen::Vector3d> palpate_offline(
    const std::function<std::unique_ptr<PalpableDisc>()>& make_disc,
    const DiscPalpationOptions& options, const std::vector<Eigen::Vector3d>& device_mm,
    double tick_s) {
  const double every = options.dt_s / tick_s;
  const long n_every = std::lround(every);
  if (!(tick_s > 0) || n_every < 1 || std::abs(every - double(n_every)) > 1e-9 * every ||
      (!options.multirate && n_every != 1))
    throw std::invalid_argument(
        "disc palpation: the step must be a whole number of ticks (one tick when direct)");
  DiscPalpationOptions o = options;
  o.realtime_priority = false;
  DiscPalpation disc(make_disc(), o);
  const double kcd = disc.disc_coupling_n_per_mm();
  std::vector<Eigen::Vector3d> force(device_mm.size(), Eigen::Vector3d::Zero());
  DiscContact seen;  // what the servo sees: the last finished step
  for (std::size_t k = 0; k < device_mm.size(); ++k) {
    const Eigen::Vector3d& x = device_mm[k];
    if (!options.multirate) {
      const DiscContact& c = disc.step(x);
      if (c.contact) force[k] = kcd * (c.probe_mm - x);
      continue;
    }
    const LocalContact local = evaluate_local_model(seen, kcd, x);
    if (local.contact) force[k] = local.force_n;
    if (long(k) % n_every == 0) seen = disc.step(x);
  }
  return force;
}

ForceError force_error(const std::vector<Eigen::Vector3d>& run,
                       const std::vector<Eigen::Vector3d>& reference) {
  ForceError e;
  const std::size_t n = std::min(run.size(), reference.size());
  double sum2 = 0;
  for (std::size_t k = 0; k < n; ++k) {
    const double d = (run[k] - reference[k]).norm();
    sum2 += d * d;
    e.max_n = std::max(e.max_n, d);
    e.peak_n = std::max(e.peak_n, reference[k].norm());
  }
  e.rms_n = n ? std::sqrt(sum2 / double(n)) : 0;
  return e;
}

DiscCouplingRenderer::DiscCouplingRenderer(ForceRenderer& rigid, DiscPalpation& disc)
    : rigid_(rigid), palpation_(disc) {}

void DiscCouplingRenderer::reset(const Eigen::Vector3d& device_mm) {
  rigid_.reset(device_mm);
  palpation_.set_device(device_mm);
}

RenderOutput DiscCouplingRenderer::render(const ProbeState& probe, const Scene& scene,
                                          const ScenePoses& poses, double dt_s) {
  RenderOutput out = rigid_.render(probe, scene, poses, dt_s);
  palpation_.set_device(probe.position_mm);
  disc_ = palpation_.latest();
  out.disc = true;
  out.disc_contact = disc_.contact;
  out.disc_volume_change = disc_.volume_change;
  out.disc_force_n = disc_.force_n;
  out.disc_probe_mm = disc_.contact ? disc_.probe_mm : probe.position_mm;
  const DiscPalpationOptions& o = palpation_.options();
  if (o.multirate) {
    // The worker's local model at this tick's device position; none when it is stale.
    if (disc_.step != model_step_) model_step_ = disc_.step, ticks_on_model_ = 0;
    const bool stale = ++ticks_on_model_ * dt_s > DiscPalpation::kStaleSteps * o.dt_s;
    stale_ticks_ += stale;
    LocalContact local{probe.position_mm, Eigen::Vector3d::Zero(), false};
    if (!stale)
      local = evaluate_local_model(disc_, palpation_.disc_coupling_n_per_mm(), probe.position_mm);
    disc_.contact = local.contact;
    disc_.probe_mm = local.probe_mm;
    disc_.force_n = local.force_n;
    out.disc_contact = local.contact;
    out.disc_force_n = local.force_n;
    out.disc_probe_mm = local.probe_mm;
  }
  out.disc_indentation_mm = disc_.contact ? disc_.indentation_mm : 0.0;
  if (!disc_.contact) return out;
  const Eigen::Vector3d f = o.coupling_stiffness_n_per_mm * (disc_.probe_mm - probe.position_mm) -
                            o.coupling_damping_n_s_per_mm * probe.velocity_mm_s;
  out.force_n += f;
  if (!out.contact) {
    out.contact = true;
    out.proxy_mm = disc_.probe_mm;
    out.penetration_mm = (disc_.probe_mm - probe.position_mm).norm();
  }
  return out;
}

}  // namespace spinesim::haptics

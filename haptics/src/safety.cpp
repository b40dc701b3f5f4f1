#include "spinesim/haptics/safety.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace spinesim::haptics {

SafetyOptions SafetyOptions::for_device(const DeviceCapabilities& c) {
  SafetyOptions o;
  o.peak_force_n = c.peak_force_n;
  o.continuous_force_n = c.continuous_force_n;
  if (c.renders_torque()) {
    o.peak_torque_nmm = c.peak_torque_nmm;
    o.continuous_torque_nmm = c.continuous_torque_nmm;
  }
  return o;
}

SafetyChain::SafetyChain(const SafetyOptions& o) : o_(o) {
  if (!(o.peak_force_n > 0) || !(o.continuous_force_n > 0) ||
      o.continuous_force_n > o.peak_force_n || !(o.continuous_window_s > 0) ||
      !(o.start_ramp_s >= 0) || !(o.contact_ramp_s >= 0) || !(o.fade_s > 0))
    throw std::invalid_argument(
        "safety chain: need peak >= continuous force > 0 and positive time constants");
  if (!(o.peak_torque_nmm >= 0) || !(o.continuous_torque_nmm >= 0) ||
      o.continuous_torque_nmm > o.peak_torque_nmm ||
      (o.peak_torque_nmm > 0) != (o.continuous_torque_nmm > 0))
    throw std::invalid_argument(
        "safety chain: need peak >= continuous torque > 0, or both 0 (no torque)");
}

void SafetyChain::reset() {
  since_start_s_ = 0;
  since_contact_s_ = 1e9;
  fade_ = 1;
  mean_square_ = torque_mean_square_ = 0;
  was_contact_ = contact_ramp_ = false;
}

namespace {

/// Links 2 and 3 for one vector: the peak clamp keeping the direction, then the continuous limit
/// — a running mean square of the clamped demand; while its root exceeds the continuous rating,
/// the output is scaled by rating / root, so a sustained demand is held at the rating. Both
/// ratings > 0.
void clamp_and_limit(Eigen::Vector3d& v, double peak, double continuous, double alpha,
                     double& mean_square, bool& clamped, bool& limited) {
  const double norm = v.norm();
  if (norm > peak) {
    v *= peak / norm;
    clamped = true;
  }
  mean_square += alpha * (v.squaredNorm() - mean_square);
  const double rms = std::sqrt(mean_square);
  if (rms > continuous) {
    v *= continuous / rms;
    limited = true;
  }
}

}  // namespace

Wrench SafetyChain::apply(const Wrench& demand, const SafetyTick& tick, SafetyReport* report) {
  SafetyReport r;
  const double dt = std::isfinite(tick.period_s) ? std::clamp(tick.period_s, 0.0, 1.0) : 1.0;
  Eigen::Vector3d f = demand.force_n, tau = demand.torque_nmm;
  // 1. Finite: a non-finite force or torque means the computation broke; neither is trusted.
  if (!f.allFinite() || !tau.allFinite()) {
    f.setZero();
    tau.setZero();
    r.non_finite = true;
  }
  // 2.–3. Peak and continuous ratings, force and torque each against its own.
  const double alpha = std::min(1.0, dt / o_.continuous_window_s);
  clamp_and_limit(f, o_.peak_force_n, o_.continuous_force_n, alpha, mean_square_, r.clamped,
                  r.limited);
  if (o_.peak_torque_nmm > 0)
    clamp_and_limit(tau, o_.peak_torque_nmm, o_.continuous_torque_nmm, alpha, torque_mean_square_,
                    r.torque_clamped, r.torque_limited);
  else
    tau.setZero();  // a device without torque motors: nothing to command
  // 4. Ramps: after (re)start, and when contact begins with the probe already in.
  since_start_s_ += dt;
  if (tick.contact && !was_contact_ && tick.penetration_mm > o_.penetrating_mm) {
    contact_ramp_ = true;
    since_contact_s_ = 0;
  }
  if (!tick.contact) contact_ramp_ = false;
  was_contact_ = tick.contact;
  since_contact_s_ += dt;
  double gain = o_.start_ramp_s > 0 ? std::min(1.0, since_start_s_ / o_.start_ramp_s) : 1.0;
  if (contact_ramp_ && o_.contact_ramp_s > 0)
    gain *= std::min(1.0, since_contact_s_ / o_.contact_ramp_s);
  r.ramping = gain < 1;
  // 5. Watchdog: a late tick or stale scene data fades the force out; it comes back as a ramp.
  const bool late = !(tick.period_s <= o_.late_tick_s);
  const bool stale = !(tick.scene_age_s <= o_.stale_s);
  if (late || stale) {
    fade_ = fade_ - dt / o_.fade_s;
    if (fade_ < 1e-9) fade_ = 0;
    r.fading = true;
  } else {
    fade_ = std::min(1.0, fade_ + dt / o_.fade_s);
  }
  gain *= fade_;
  f *= gain;
  tau *= gain;
  r.gain = gain;
  if (report) *report = r;
  return Wrench{f, tau};
}

}  // namespace spinesim::haptics

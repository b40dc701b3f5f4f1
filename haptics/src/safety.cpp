#include "spinesim/haptics/safety.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace spinesim::haptics {

SafetyOptions SafetyOptions::for_device(const DeviceCapabilities& c) {
  SafetyOptions o;
  o.peak_force_n = c.peak_force_n;
  o.continuous_force_n = c.continuous_force_n;
  return o;
}

SafetyChain::SafetyChain(const SafetyOptions& o) : o_(o) {
  if (!(o.peak_force_n > 0) || !(o.continuous_force_n > 0) ||
      o.continuous_force_n > o.peak_force_n || !(o.continuous_window_s > 0) ||
      !(o.start_ramp_s >= 0) || !(o.contact_ramp_s >= 0) || !(o.fade_s > 0))
    throw std::invalid_argument(
        "safety chain: need peak >= continuous force > 0 and positive time constants");
}

void SafetyChain::reset() {
  since_start_s_ = 0;
  since_contact_s_ = 1e9;
  fade_ = 1;
  mean_square_ = 0;
  was_contact_ = contact_ramp_ = false;
}

Eigen::Vector3d SafetyChain::apply(const Eigen::Vector3d& force_in, const SafetyTick& tick,
                                   SafetyReport* report) {
  SafetyReport r;
  const double dt = std::isfinite(tick.period_s) ? std::clamp(tick.period_s, 0.0, 1.0) : 1.0;
  Eigen::Vector3d f = force_in;
  // 1. Finite.
  if (!f.allFinite()) {
    f.setZero();
    r.non_finite = true;
  }
  // 2. Peak: scale the vector, keeping its direction.
  const double norm = f.norm();
  if (norm > o_.peak_force_n) {
    f *= o_.peak_force_n / norm;
    r.clamped = true;
  }
  // 3. Continuous: a running mean square of the demanded (clamped) force; while its root
  //    exceeds the continuous rating, the output is scaled by rating / root, so a sustained
  //    demand is held at the rating.
  const double alpha = std::min(1.0, dt / o_.continuous_window_s);
  mean_square_ += alpha * (f.squaredNorm() - mean_square_);
  const double rms = std::sqrt(mean_square_);
  if (rms > o_.continuous_force_n) {
    f *= o_.continuous_force_n / rms;
    r.limited = true;
  }
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
  r.gain = gain;
  if (report) *report = r;
  return f;
}

}  // namespace spinesim::haptics

// The safety chain: applied once per tick to the summed force, just before it goes to the
// device, in this order — finite → clamp to the peak force keeping the direction → continuous-
// force limit → ramps (on start; when contact begins while already penetrating) → watchdog
// (fades the force to zero while deadlines are missed or the scene data are stale). A person's
// hand is on the device: every link is tested on its own and on fuzzed trajectories.
// Also here: the passivity observer (Hannaford & Ryu 2002).
#pragma once

#include "spinesim/haptics/device.hpp"

#include <Eigen/Core>

#include <algorithm>
#include <cmath>

namespace spinesim::haptics {

struct SafetyOptions {
  double peak_force_n = 3.3;
  double continuous_force_n = 0.88;
  double continuous_window_s = 2.0;  ///< time constant of the force's running RMS
  double start_ramp_s = 0.5;         ///< 0 → full force after the loop starts
  double contact_ramp_s = 0.2;       ///< 0 → full force when contact begins penetrating
  double penetrating_mm = 0.5;       ///< "already penetrating" at contact onset beyond this
  double late_tick_s = 0.002;        ///< a period longer than this is a missed deadline
  double stale_s = 0.05;             ///< scene data older than this are stale
  double fade_s = 0.05;              ///< the watchdog fades to zero over this time
  static SafetyOptions for_device(const DeviceCapabilities& c);
};

/// What the chain did this tick.
struct SafetyReport {
  bool non_finite = false, clamped = false, limited = false, ramping = false, fading = false;
  double gain = 1;  ///< product of the ramps and the watchdog's fade
};

/// Per-tick inputs of the chain.
struct SafetyTick {
  double period_s = 0.001;  ///< measured time since the last tick
  double scene_age_s = 0;   ///< age of the scene data the force was computed from
  bool contact = false;
  double penetration_mm = 0;
};

class SafetyChain {
 public:
  explicit SafetyChain(const SafetyOptions& o);
  /// Restarts the start ramp and clears the running RMS and the watchdog.
  void reset();
  /// The force to command. No allocation.
  Eigen::Vector3d apply(const Eigen::Vector3d& force_n, const SafetyTick& tick,
                        SafetyReport* report = nullptr);
  const SafetyOptions& options() const { return o_; }
  /// Running RMS of the demanded force (after the clamp), N.
  double rms_force_n() const { return std::sqrt(mean_square_); }

 private:
  SafetyOptions o_;
  double since_start_s_ = 0, since_contact_s_ = 1e9, fade_ = 1, mean_square_ = 0;
  bool was_contact_ = false, contact_ramp_ = false;
};

/// Time-domain passivity observer of the display (the device with its known physical damping b
/// and the virtual environment; Hannaford & Ryu 2002): the energy the display has absorbed from
/// the hand, E(n) = Σ_k (b |Δx_k|² / T_k − F_k · Δx_k), where F_k is the force held over tick k
/// and Δx_k how far the device moved meanwhile (the exact work of a held force, where F_k · v_k T
/// would miss the lag that makes a sampled wall active). N·mm = mJ. A passive display keeps
/// E ≥ 0; E < 0 is energy the loop injected.
class PassivityObserver {
 public:
  explicit PassivityObserver(double physical_damping_n_s_per_mm = 0)
      : b_(physical_damping_n_s_per_mm) {}
  void add(const Eigen::Vector3d& held_force_on_hand_n, const Eigen::Vector3d& displacement_mm,
           double period_s) {
    if (!(period_s > 0)) return;
    energy_ +=
        b_ * displacement_mm.squaredNorm() / period_s - held_force_on_hand_n.dot(displacement_mm);
    minimum_ = std::min(minimum_, energy_);
  }
  double energy_mj() const { return energy_; }
  double minimum_mj() const { return minimum_; }

 private:
  double b_, energy_ = 0, minimum_ = 0;
};

}  // namespace spinesim::haptics

// The safety chain: applied once per tick to the summed force (and, on a 6-DOF device, the
// torque), just before it goes to the device, in this order — finite (a non-finite force or
// torque zeroes both) → clamp to the peak force, and the peak torque, keeping the direction →
// continuous-force and continuous-torque limits → ramps (on start; when contact begins while
// already penetrating) → watchdog (fades force and torque to zero while deadlines are missed or
// the scene data are stale). A device without torque motors gets no torque at all. A person's
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
  double peak_torque_nmm = 0;        ///< 0: the device renders no torque (always zero)
  double continuous_torque_nmm = 0;
  static SafetyOptions for_device(const DeviceCapabilities& c);
};

/// A force (N) and a torque (N·mm), scene axes.
struct Wrench {
  Eigen::Vector3d force_n = Eigen::Vector3d::Zero();
  Eigen::Vector3d torque_nmm = Eigen::Vector3d::Zero();
};

/// What the chain did this tick.
struct SafetyReport {
  bool non_finite = false, clamped = false, limited = false, ramping = false, fading = false;
  bool torque_clamped = false, torque_limited = false;
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
                        SafetyReport* report = nullptr) {
    return apply(Wrench{force_n, Eigen::Vector3d::Zero()}, tick, report).force_n;
  }
  /// The force and torque to command. No allocation.
  Wrench apply(const Wrench& demand, const SafetyTick& tick, SafetyReport* report = nullptr);
  const SafetyOptions& options() const { return o_; }
  /// Running RMS of the demanded force (after the clamp), N.
  double rms_force_n() const { return std::sqrt(mean_square_); }
  /// Running RMS of the demanded torque (after the clamp), N·mm.
  double rms_torque_nmm() const { return std::sqrt(torque_mean_square_); }

 private:
  SafetyOptions o_;
  double since_start_s_ = 0, since_contact_s_ = 1e9, fade_ = 1, mean_square_ = 0;
  double torque_mean_square_ = 0;
  bool was_contact_ = false, contact_ramp_ = false;
};

/// Time-domain passivity observer of the display (the device with its known physical damping b
/// and the virtual environment; Hannaford & Ryu 2002): the energy the display has absorbed from
/// the hand, E(n) = Σ_k (b |Δx_k|² / T_k − F_k · Δx_k), where F_k is the force held over tick k
/// and Δx_k how far the device moved meanwhile (the exact work of a held force, where F_k · v_k T
/// would miss the lag that makes a sampled wall active). N·mm = mJ. A passive display keeps
/// E ≥ 0; E < 0 is energy the loop injected.
/// On a 6-DOF device the rotations add their own term, b_r |Δφ_k|² / T_k − τ_k · Δφ_k (Δφ_k
/// the stylus's rotation vector over the tick, rad; τ_k the held torque, N·mm): one energy.
class PassivityObserver {
 public:
  explicit PassivityObserver(double physical_damping_n_s_per_mm = 0,
                             double rotational_damping_nmm_s_per_rad = 0)
      : b_(physical_damping_n_s_per_mm), b_r_(rotational_damping_nmm_s_per_rad) {}
  void add(const Eigen::Vector3d& held_force_on_hand_n, const Eigen::Vector3d& displacement_mm,
           double period_s) {
    if (!(period_s > 0)) return;
    energy_ +=
        b_ * displacement_mm.squaredNorm() / period_s - held_force_on_hand_n.dot(displacement_mm);
    minimum_ = std::min(minimum_, energy_);
  }
  void add_rotation(const Eigen::Vector3d& held_torque_on_hand_nmm,
                    const Eigen::Vector3d& rotation_rad, double period_s) {
    if (!(period_s > 0)) return;
    energy_ +=
        b_r_ * rotation_rad.squaredNorm() / period_s - held_torque_on_hand_nmm.dot(rotation_rad);
    minimum_ = std::min(minimum_, energy_);
  }
  double energy_mj() const { return energy_; }
  double minimum_mj() const { return minimum_; }

 private:
  double b_, b_r_, energy_ = 0, minimum_ = 0;
};

}  // namespace spinesim::haptics

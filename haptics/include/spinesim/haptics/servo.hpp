// The servo loop: its own thread, woken at absolute deadlines (clock_nanosleep, TIMER_ABSTIME)
// every period, real-time priority when the system allows it (and the reason when it does not).
// Each tick: read the device → render the scene at the latest poses → safety chain → command
// the force → statistics, status and recording. A tick allocates nothing; slower threads get
// the status through a triple buffer and the recording through a lock-free ring.
#pragma once

#include "spinesim/haptics/compliant_stage.hpp"
#include "spinesim/haptics/device.hpp"
#include "spinesim/haptics/renderer.hpp"
#include "spinesim/haptics/safety.hpp"
#include "spinesim/haptics/scene.hpp"
#include "spinesim/haptics/triple_buffer.hpp"

#include <Eigen/Core>

#include <atomic>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

namespace spinesim::haptics {

struct ServoOptions {
  double period_s = 0.001;
  double duration_s = 10;         ///< stop after this long (or when the device has finished)
  bool realtime_priority = true;  ///< ask for SCHED_FIFO
  int priority = 80;
  /// Sleep until this long before each deadline, then spin to it: the kernel's wake-up latency
  /// on a virtual machine is tens to hundreds of µs (docs/benchmarks.md), spinning is not. 0:
  /// sleep to the deadline (no CPU burnt).
  double spin_us = 400;
};

/// What the servo thread publishes every tick (for a status line or a viewer).
struct ServoStatus {
  std::int64_t ticks = 0;
  double time_s = 0;
  Eigen::Vector3d probe_mm = Eigen::Vector3d::Zero(), proxy_mm = Eigen::Vector3d::Zero();
  Eigen::Vector3d force_n = Eigen::Vector3d::Zero();
  /// 6-DOF devices: the stylus's rotation vector (deg) and the commanded torque (N·mm).
  Eigen::Vector3d rotation_deg = Eigen::Vector3d::Zero(), torque_nmm = Eigen::Vector3d::Zero();
  bool contact = false;
  int body = -1;
  unsigned buttons = 0;
  double passivity_mj = 0;
  HookState hook;  ///< the compliant stage's hook (attached = false without one)
  /// Disc palpation (disc = false without it): contact, volume change, the disc's force.
  bool disc = false, disc_contact = false;
  double disc_volume_change = 0;
  double disc_indentation_mm = 0;  ///< the disc wall's indentation under the probe
  Eigen::Vector3d disc_force_n = Eigen::Vector3d::Zero();   ///< disc N (the felt force x scale)
  Eigen::Vector3d disc_probe_mm = Eigen::Vector3d::Zero();  ///< the disc thread's probe
  /// The bodies' poses this tick's render used (the compliant stage's vertebrae moved).
  ScenePoses poses;
  /// The loop's own timing (0 for ticks not run by run()): the last period and the last tick's
  /// compute time, and the largest |period − T| and compute time over the last 1,000–2,000 ticks.
  float period_us = 0, compute_us = 0, recent_jitter_us = 0, recent_compute_us = 0;
};

/// One recorded tick (the `--record` file's row).
struct TickRecord {
  double t_s = 0;
  std::int64_t tick = 0;  ///< 1, 2, … (a gap: rows the writer lost)
  Eigen::Vector3d probe_mm, force_n, proxy_mm;
  unsigned buttons = 0;
  bool contact = false;
  /// 6-DOF devices (six_dof = false otherwise): the stylus's rotation vector (deg), the torque.
  bool six_dof = false;
  Eigen::Vector3f rotation_deg = Eigen::Vector3f::Zero(), torque_nmm = Eigen::Vector3f::Zero();
  // The compliant stage (when there is one): the hook and every vertebra's rigid motion from the
  // reference posture (x ↦ R x + t; single precision is 0.1 µm over the spine).
  bool compliant = false;
  HookState hook;
  // Disc palpation (disc = false without it).
  bool disc = false, disc_contact = false;
  float disc_volume_change = 0, disc_indentation_mm = 0;
  Eigen::Vector3f disc_force_n = Eigen::Vector3f::Zero(), disc_probe_mm = Eigen::Vector3f::Zero();
  std::array<Eigen::Matrix3f, kSpineVertebrae> R;
  std::array<Eigen::Vector3f, kSpineVertebrae> t;
};

struct Percentiles {
  double p50 = 0, p99 = 0, p999 = 0, max = 0;
};
/// Percentiles of `values` (sorted copy; nearest rank). All zero when empty.
Percentiles percentiles(std::vector<float> values);

struct ServoStats {
  std::int64_t ticks = 0;
  double seconds = 0, rate_hz = 0;
  Percentiles period_us, compute_us;
  std::int64_t missed_deadlines = 0;  ///< ticks that woke a period late or ended past the next
  double max_force_n = 0;             ///< largest commanded force
  double max_torque_nmm = 0;          ///< largest commanded torque (6-DOF devices)
  std::int64_t torque_clamped_ticks = 0, torque_limited_ticks = 0;
  std::int64_t clamped_ticks = 0, limited_ticks = 0, non_finite_ticks = 0, fading_ticks = 0;
  std::int64_t contact_ticks = 0, truncated_ticks = 0;
  int max_render_work = 0;  ///< the largest RenderOutput::work of a tick
  /// The compliant stage: ticks hooked, the largest force on the spine, ticks it was clamped.
  std::int64_t hooked_ticks = 0, spine_clamped_ticks = 0;
  double max_spine_force_n = 0, max_spine_moment_nmm = 0;
  double passivity_min_mj = 0, passivity_final_mj = 0;
  bool realtime_priority = false;
  std::string realtime_reason;
  std::string stop_reason;  ///< "duration", "device finished", "stopped", or the error
  bool error = false;
};

class ServoLoop {
 public:
  /// The device must be open. `poses` is written by a slower thread (or once, for a static
  /// scene); the loop only reads it.
  ServoLoop(Device& device, ForceRenderer& renderer, const Scene& scene,
            TripleBuffer<ScenePoses>& poses, const SafetyOptions& safety,
            const ServoOptions& options);

  /// One tick at time `now_s` (seconds since the start), `period_s` after the last one. Used by
  /// the thread and directly by tests (then nothing is timed). No allocation.
  void tick(double now_s, double period_s);

  /// Runs the thread to the end (duration, device finished, request_stop() or an error), then
  /// zeroes the force. `every_10ms(status, now_s)` is called from the calling thread about every
  /// 10 ms with the latest status and the loop's clock (s since the start, the clock scene
  /// poses are stamped with): the slow side publishes poses and draws status there. It may be
  /// empty. Returns the statistics.
  ServoStats run(const std::function<void(const ServoStatus&, double)>& every_10ms = {});
  /// Seconds on the loop's clock (valid during run()).
  double now_s() const;

  /// Asks the loop to end (any thread; async-signal-safe).
  void request_stop() { stop_.store(true); }
  /// Adds the compliant stage (set before run()): each tick it moves the vertebrae for the
  /// hook's force before the render, and its spring's force is blended into the hand's.
  void set_compliant_stage(CompliantStage* stage);
  /// Records every tick into a ring drained by `sink` on a writer thread (set before run()).
  void record_to(std::function<void(const TickRecord*, std::size_t)> sink, std::size_t capacity);

  const ServoStats& stats() const { return stats_; }
  TripleBuffer<ServoStatus>& status() { return status_; }
  const PassivityObserver& passivity() const { return passivity_; }

 private:
  Device& device_;
  ForceRenderer& renderer_;
  const Scene& scene_;
  TripleBuffer<ScenePoses>& poses_;
  SafetyChain safety_;
  PassivityObserver passivity_;
  ServoOptions options_;
  ServoStats stats_;
  TripleBuffer<ServoStatus> status_;
  std::atomic<bool> stop_{false};
  std::vector<float> period_us_, compute_us_;  ///< sized before the thread starts
  std::size_t samples_ = 0;
  DeviceState state_;
  Eigen::Vector3d held_force_ = Eigen::Vector3d::Zero();  ///< commanded at the last tick
  Eigen::Vector3d held_from_mm_ = Eigen::Vector3d::Zero();
  Eigen::Vector3d held_torque_ = Eigen::Vector3d::Zero();
  Eigen::Matrix3d held_from_R_ = Eigen::Matrix3d::Identity();
  bool six_dof_ = false;  ///< the device senses the stylus's orientation
  /// Zero force and torque to the device (the end of a run, a failure).
  void write_zero() { device_.write_wrench(Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero()); }
  // Recording: a single-producer single-consumer ring.
  std::vector<TickRecord> ring_;
  std::atomic<std::size_t> ring_head_{0}, ring_tail_{0};
  std::atomic<std::int64_t> ring_dropped_{0};
  std::function<void(const TickRecord*, std::size_t)> sink_;
  bool device_failed_ = false;
  /// A device read or write failed: zero force, stop, report (no allocation: the reason is a literal).
  void fail_device();
  /// The tick's status for the slower threads (and the stage's hook statistics).
  void publish_status(double now_s, const Wrench& command, const RenderOutput& out,
                      const ScenePoses& poses);
  void record(double now_s, const Wrench& command, const RenderOutput& out,
              const ScenePoses& poses);
  CompliantStage* stage_ = nullptr;
  ScenePoses stage_poses_;  ///< the scene's poses with the stage's vertebrae, kept across ticks
  RenderOutput last_out_;
  /// The timing run() measures, published with the next tick's status.
  struct RecentTiming {
    float period_us = 0, compute_us = 0;
    float jitter_block = 0, compute_block = 0, jitter_last_block = 0, compute_last_block = 0;
    int in_block = 0;
    void add(float period, float compute, float T_us);
  } timing_;
  double t0_ = 0;  ///< the loop's clock origin (CLOCK_MONOTONIC, s)
};

/// Sets the calling thread to SCHED_FIFO at `priority`; false with the reason when it cannot.
bool set_realtime_priority(int priority, std::string* reason);

}  // namespace spinesim::haptics

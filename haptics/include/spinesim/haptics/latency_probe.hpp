// The machine's own floor, measured beside the servo: a bare periodic thread (what cyclictest
// does, Debian rt-tests) that sleeps to absolute deadlines one period apart at the servo's
// priority and records how late each wake-up is. Nothing else runs in it, so what it sees is the
// host — the kernel, the hypervisor, other programs — not our code: a servo miss that the
// probe also sees is the machine's, a miss it does not see is ours. Allocates only in start().
#pragma once

#include "spinesim/haptics/servo.hpp"

#include <atomic>
#include <cstdint>
#include <string>
#include <thread>
#include <vector>

namespace spinesim::haptics {

struct LatencyProbeStats {
  std::int64_t wakeups = 0;
  Percentiles latency_us;   ///< wake-up time − deadline
  std::int64_t late = 0;    ///< wake-ups more than one period late (the servo's "missed")
  double late_percent = 0;  ///< of the wake-ups
  bool realtime_priority = false;
  std::string realtime_reason;
};

class LatencyProbe {
 public:
  ~LatencyProbe() { stop(); }
  /// Starts the thread: period `period_s`, SCHED_FIFO `priority` when `realtime` (and allowed),
  /// room for `max_seconds` of samples (later wake-ups are counted but not kept).
  void start(double period_s, bool realtime, int priority, double max_seconds);
  /// Stops and joins the thread (idempotent) and returns the statistics.
  LatencyProbeStats stop();
  const LatencyProbeStats& stats() const { return stats_; }

 private:
  std::thread thread_;
  std::atomic<bool> stop_{false};
  std::vector<float> latency_us_;
  std::size_t samples_ = 0;
  LatencyProbeStats stats_;
};

}  // namespace spinesim::haptics

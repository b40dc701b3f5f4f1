#include "spinesim/haptics/latency_probe.hpp"

#include "monotonic_clock.hpp"

#include <time.h>

#include <cerrno>

namespace spinesim::haptics {

using detail::monotonic_s;
using detail::to_timespec;

void LatencyProbe::start(double period_s, bool realtime, int priority, double max_seconds) {
  stop();
  stop_.store(false);
  stats_ = LatencyProbeStats{};
  latency_us_.assign(std::size_t(std::max(1.0, max_seconds / period_s)) + 16, 0.0f);
  samples_ = 0;
  thread_ = std::thread([this, period_s, realtime, priority] {
    std::string reason;
    stats_.realtime_priority = realtime && set_realtime_priority(priority, &reason);
    stats_.realtime_reason = realtime ? reason : "not asked for";
    double deadline = monotonic_s();
    while (!stop_.load(std::memory_order_relaxed)) {
      deadline += period_s;
      const timespec ts = to_timespec(deadline);
      while (::clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &ts, nullptr) == EINTR) {}
      const double late = monotonic_s() - deadline;
      if (samples_ < latency_us_.size()) latency_us_[samples_++] = float(late * 1e6);
      ++stats_.wakeups;
      if (late > period_s) ++stats_.late;
      if (late > 10 * period_s) deadline = monotonic_s();  // far behind: no burst
    }
  });
}

LatencyProbeStats LatencyProbe::stop() {
  if (!thread_.joinable()) return stats_;
  stop_.store(true);
  thread_.join();
  stats_.latency_us = percentiles(
      std::vector<float>(latency_us_.begin(), latency_us_.begin() + std::ptrdiff_t(samples_)));
  stats_.late_percent = stats_.wakeups ? 100.0 * double(stats_.late) / double(stats_.wakeups) : 0;
  return stats_;
}

}  // namespace spinesim::haptics

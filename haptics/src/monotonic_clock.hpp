// The real-time threads' clock (the servo loop, the palpated disc): CLOCK_MONOTONIC in seconds,
// and a time as the timespec clock_nanosleep(TIMER_ABSTIME) takes.
#pragma once

#include <time.h>

#include <cmath>

namespace spinesim::haptics::detail {

inline double monotonic_s() {
  timespec ts{};
  ::clock_gettime(CLOCK_MONOTONIC, &ts);
  return double(ts.tv_sec) + 1e-9 * double(ts.tv_nsec);
}

inline timespec to_timespec(double s) {
  timespec ts{};
  ts.tv_sec = time_t(std::floor(s));
  ts.tv_nsec = long((s - std::floor(s)) * 1e9);
  if (ts.tv_nsec >= 1000000000L) {
    ts.tv_sec += 1;
    ts.tv_nsec -= 1000000000L;
  }
  return ts;
}

}  // namespace spinesim::haptics::detail

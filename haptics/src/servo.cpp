#include "spinesim/haptics/servo.hpp"

#include "monotonic_clock.hpp"

#include "spinesim/common/constants.hpp"
#include "spinesim/common/rotation.hpp"

#include <pthread.h>
#include <sched.h>
#include <time.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstring>
#include <stdexcept>
#include <thread>

namespace spinesim::haptics {

using detail::monotonic_s;
using detail::to_timespec;

Percentiles percentiles(std::vector<float> v) {
  Percentiles p;
  if (v.empty()) return p;
  std::sort(v.begin(), v.end());
  auto rank = [&](double q) {
    const std::size_t i = std::size_t(std::ceil(q * double(v.size()))) - 1;
    return double(v[std::min(i, v.size() - 1)]);
  };
  p.p50 = rank(0.5);
  p.p99 = rank(0.99);
  p.p999 = rank(0.999);
  p.max = double(v.back());
  return p;
}

bool set_realtime_priority(int priority, std::string* reason) {
  sched_param sp{};
  sp.sched_priority = priority;
  const int rc = ::pthread_setschedparam(::pthread_self(), SCHED_FIFO, &sp);
  if (rc == 0) {
    if (reason) *reason = "SCHED_FIFO priority " + std::to_string(priority);
    return true;
  }
  if (reason)
    *reason = std::string("SCHED_FIFO refused (") + std::strerror(rc) +
              "): the loop runs at normal priority; allow real-time scheduling (CAP_SYS_NICE, "
              "or an rtprio limit in /etc/security/limits.conf) for steadier periods";
  return false;
}

ServoLoop::ServoLoop(Device& device, ForceRenderer& renderer, const Scene& scene,
                     TripleBuffer<ScenePoses>& poses, const SafetyOptions& safety,
                     const ServoOptions& options)
    : device_(device),
      renderer_(renderer),
      scene_(scene),
      poses_(poses),
      safety_(safety),
      passivity_(device.capabilities().physical_damping_n_s_per_mm,
                 device.capabilities().rotational_damping_nmm_s_per_rad),
      options_(options) {
  if (!(options.period_s >= 1e-4 && options.period_s <= 0.1))
    throw std::invalid_argument("servo period must be 0.1 to 100 ms");
  if (!(options.spin_us >= 0) || options.spin_us > 0.9e6 * options.period_s)
    throw std::invalid_argument("servo spin time must be 0 to 90 % of the period");
  if (!(options.duration_s > 0) || options.duration_s > 24 * 3600)
    throw std::invalid_argument("servo duration must be > 0 s and at most a day");
  const std::size_t capacity = std::size_t(options.duration_s / options.period_s * 1.05) + 1000;
  period_us_.assign(std::min<std::size_t>(capacity, 100000000), 0.f);
  compute_us_.assign(period_us_.size(), 0.f);
  DeviceState s;
  device_.read(s);  // the starting position (a sim device advances one period)
  state_ = s;
  held_from_mm_ = s.position_mm;
  held_from_R_ = s.orientation;
  six_dof_ = device_.capabilities().senses_orientation;
  renderer_.reset(s.position_mm);
}

void ServoLoop::record_to(std::function<void(const TickRecord*, std::size_t)> sink,
                          std::size_t capacity) {
  sink_ = std::move(sink);
  ring_.assign(std::max<std::size_t>(capacity, 16), TickRecord{});
}

void ServoLoop::set_compliant_stage(CompliantStage* stage) {
  stage_ = stage;
  stage_poses_ = poses_.read();
}

void ServoLoop::fail_device() {
  write_zero();
  device_failed_ = true;
  stats_.error = true;
  stats_.stop_reason = "device error";
  stop_.store(true);
}

void ServoLoop::publish_status(double now_s, const Wrench& command, const RenderOutput& out,
                               const ScenePoses& poses) {
  ServoStats& st = stats_;
  ServoStatus status;
  status.ticks = st.ticks;
  status.time_s = now_s;
  status.probe_mm = state_.position_mm;
  status.proxy_mm = out.proxy_mm;
  status.force_n = command.force_n;
  status.torque_nmm = command.torque_nmm;
  status.rotation_deg = rotation_log_total(state_.orientation) / kRadPerDeg;
  status.contact = out.contact;
  status.body = out.body;
  status.buttons = state_.buttons;
  status.passivity_mj = passivity_.energy_mj();
  status.disc = out.disc;
  status.disc_contact = out.disc_contact;
  status.disc_volume_change = out.disc_volume_change;
  status.disc_indentation_mm = out.disc_indentation_mm;
  status.disc_force_n = out.disc_force_n;
  status.disc_probe_mm = out.disc_probe_mm;
  status.poses = poses;
  status.period_us = timing_.period_us;
  status.compute_us = timing_.compute_us;
  status.recent_jitter_us = std::max(timing_.jitter_block, timing_.jitter_last_block);
  status.recent_compute_us = std::max(timing_.compute_block, timing_.compute_last_block);
  if (stage_) {
    const HookState& h = stage_->state();
    status.hook = h;
    st.hooked_ticks += h.attached;
    st.spine_clamped_ticks += h.clamped;
    st.max_spine_force_n = std::max(st.max_spine_force_n, h.load.force_n.norm());
    st.max_spine_moment_nmm = std::max(st.max_spine_moment_nmm, h.load.moment_nmm.norm());
  }
  status_.write(status);
}

void ServoLoop::tick(double now_s, double period_s) {
  ServoStats& st = stats_;
  if (device_failed_) return;
  if (!device_.read(state_)) {
    fail_device();
    return;
  }
  // The force held over the last period did its work over the device's motion since then.
  passivity_.add(held_force_, state_.position_mm - held_from_mm_, period_s);
  held_from_mm_ = state_.position_mm;
  if (six_dof_) {
    passivity_.add_rotation(
        held_torque_, rotation_log_total(state_.orientation * held_from_R_.transpose()), period_s);
    held_from_R_ = state_.orientation;
  }
  const ScenePoses* poses = &poses_.read();
  if (stage_) {
    stage_poses_.time_s = poses->time_s;
    stage_->update(state_, last_out_, period_s, stage_poses_);
    poses = &stage_poses_;
  }
  ProbeState probe;
  probe.position_mm = state_.position_mm;
  probe.velocity_mm_s = state_.velocity_mm_s;
  const RenderOutput out = renderer_.render(probe, scene_, *poses, period_s);
  last_out_ = out;
  SafetyTick in;
  in.period_s = period_s;
  in.scene_age_s = now_s - poses->time_s;
  in.contact = out.contact;
  in.penetration_mm = out.penetration_mm;
  SafetyReport report;
  Wrench demand;
  demand.force_n = stage_ ? stage_->blend(out.force_n) : out.force_n;
  if (stage_) demand.torque_nmm = stage_->torque();
  const Wrench command = safety_.apply(demand, in, &report);
  if (!device_.write_wrench(command.force_n, command.torque_nmm)) {
    fail_device();
  }
  held_force_ = device_failed_ ? Eigen::Vector3d::Zero() : command.force_n;
  held_torque_ = device_failed_ ? Eigen::Vector3d::Zero() : command.torque_nmm;

  ++st.ticks;
  st.max_force_n = std::max(st.max_force_n, command.force_n.norm());
  st.max_torque_nmm = std::max(st.max_torque_nmm, command.torque_nmm.norm());
  st.torque_clamped_ticks += report.torque_clamped;
  st.torque_limited_ticks += report.torque_limited;
  st.clamped_ticks += report.clamped;
  st.limited_ticks += report.limited;
  st.non_finite_ticks += report.non_finite;
  st.fading_ticks += report.fading;
  st.contact_ticks += out.contact;
  st.truncated_ticks += out.truncated;
  st.max_render_work = std::max(st.max_render_work, out.work);

  publish_status(now_s, command, out, *poses);
  if (!ring_.empty()) record(now_s, command, out, *poses);
}

void ServoLoop::record(double now_s, const Wrench& command, const RenderOutput& out,
                       const ScenePoses& poses) {
  const std::size_t head = ring_head_.load(std::memory_order_relaxed);
  const std::size_t next = (head + 1) % ring_.size();
  if (next == ring_tail_.load(std::memory_order_acquire)) {
    ring_dropped_.fetch_add(1);  // the writer fell behind: never wait for it
  } else {
    TickRecord& r = ring_[head];
    r.t_s = now_s;
    r.tick = stats_.ticks;
    r.probe_mm = state_.position_mm;
    r.force_n = command.force_n;
    r.six_dof = six_dof_;
    r.rotation_deg = (rotation_log_total(state_.orientation) / kRadPerDeg).cast<float>();
    r.torque_nmm = command.torque_nmm.cast<float>();
    r.proxy_mm = out.proxy_mm;
    r.buttons = state_.buttons;
    r.contact = out.contact;
    r.disc = out.disc;
    r.disc_contact = out.disc_contact;
    r.disc_volume_change = float(out.disc_volume_change);
    r.disc_indentation_mm = float(out.disc_indentation_mm);
    r.disc_force_n = out.disc_force_n.cast<float>();
    r.disc_probe_mm = out.disc_probe_mm.cast<float>();
    r.compliant = stage_ != nullptr;
    if (stage_) {
      r.hook = stage_->state();
      const auto& body = stage_->bodies();
      for (int i = 0; i < kSpineVertebrae; ++i) {
        const spine::Pose& p = poses.pose[std::size_t(body[std::size_t(i)])];
        r.R[std::size_t(i)] = p.R.cast<float>();
        r.t[std::size_t(i)] = p.t.cast<float>();
      }
    }
    ring_head_.store(next, std::memory_order_release);
  }
}

void ServoLoop::RecentTiming::add(float period, float compute, float T_us) {
  period_us = period, compute_us = compute;
  jitter_block = std::max(jitter_block, std::abs(period - T_us));
  compute_block = std::max(compute_block, compute);
  if (++in_block == 1000) {
    jitter_last_block = jitter_block, compute_last_block = compute_block;
    jitter_block = compute_block = 0, in_block = 0;
  }
}

double ServoLoop::now_s() const { return monotonic_s() - t0_; }

ServoStats ServoLoop::run(const std::function<void(const ServoStatus&, double)>& every_10ms) {
  std::atomic<bool> done{false};
  std::string error_text;
  t0_ = monotonic_s();
  const double t0 = t0_;
  if (every_10ms) every_10ms(status_.read(), 0.0);  // e.g. the first stamped poses
  auto servo = [&] {
    std::string reason;
    stats_.realtime_priority =
        options_.realtime_priority && set_realtime_priority(options_.priority, &reason);
    stats_.realtime_reason = options_.realtime_priority ? reason : "not asked for";
    const double T = options_.period_s;
    double deadline = t0, last_wake = t0;
    try {
      while (!stop_.load(std::memory_order_relaxed)) {
        deadline += T;
        const timespec ts = to_timespec(deadline - 1e-6 * options_.spin_us);
        while (::clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &ts, nullptr) == EINTR) {}
        while (options_.spin_us > 0 && monotonic_s() < deadline) {}
        const double wake = monotonic_s();
        const double period = wake - last_wake;
        last_wake = wake;
        tick(wake - t0, period);
        const double end = monotonic_s();
        timing_.add(float(period * 1e6), float((end - wake) * 1e6), float(T * 1e6));
        if (samples_ < period_us_.size()) {
          period_us_[samples_] = float(period * 1e6);
          compute_us_[samples_] = float((end - wake) * 1e6);
          ++samples_;
        }
        if (wake - deadline > T || end > deadline + T) ++stats_.missed_deadlines;
        if (end - deadline > 10 * T) deadline = end;  // far behind: do not burst to catch up
        if (wake - t0 >= options_.duration_s) {
          stats_.stop_reason = "duration";
          break;
        }
        if (device_.finished()) {
          stats_.stop_reason = "device finished";
          break;
        }
      }
    } catch (const std::exception& e) {
      error_text = e.what();
    }
    write_zero();
    stats_.seconds = monotonic_s() - t0;
    done.store(true);
  };

  // The recording's writer: drains the ring in blocks, never blocking the servo thread.
  std::thread writer;
  if (!ring_.empty() && sink_) {
    writer = std::thread([&] {
      std::vector<TickRecord> block;
      auto drain = [&] {
        block.clear();
        std::size_t tail = ring_tail_.load(std::memory_order_relaxed);
        const std::size_t head = ring_head_.load(std::memory_order_acquire);
        while (tail != head) {
          block.push_back(ring_[tail]);
          tail = (tail + 1) % ring_.size();
        }
        ring_tail_.store(tail, std::memory_order_release);
        if (!block.empty()) sink_(block.data(), block.size());
      };
      while (!done.load()) {
        drain();
        std::this_thread::sleep_for(std::chrono::milliseconds(20));
      }
      drain();
    });
  }
  std::thread thread(servo);
  while (!done.load()) {
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
    if (every_10ms && !done.load()) every_10ms(status_.read(), monotonic_s() - t0);
  }
  thread.join();
  if (writer.joinable()) writer.join();

  if (!error_text.empty()) {
    stats_.error = true;
    stats_.stop_reason = error_text;
  } else if (stats_.stop_reason.empty()) {
    stats_.stop_reason = stats_.error ? "device error" : "stopped";
  }
  std::vector<float> period(period_us_.begin(), period_us_.begin() + long(samples_));
  std::vector<float> compute(compute_us_.begin(), compute_us_.begin() + long(samples_));
  // The first period is measured from the start time, not from a previous tick.
  if (!period.empty()) period.erase(period.begin());
  stats_.period_us = percentiles(period);
  stats_.compute_us = percentiles(compute);
  stats_.rate_hz = stats_.seconds > 0 ? double(stats_.ticks) / stats_.seconds : 0;
  stats_.passivity_min_mj = passivity_.minimum_mj();
  stats_.passivity_final_mj = passivity_.energy_mj();
  return stats_;
}

}  // namespace spinesim::haptics

// The servo loop, the safety chain and the passivity observer: each link of the chain on its
// own; fuzzed trajectories (random, fast, starting inside a vertebra) never command more than the
// device's peak force; the sim hand pressing a wall at the usable stiffness stays passive and
// settles while a wall far too stiff is reported; a tick allocates nothing; the thread keeps
// time and zeroes the force at the end.
#include "haptics_fixtures.hpp"
#include "spinesim/haptics/latency_probe.hpp"
#include "spinesim/haptics/servo.hpp"

#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <limits>
#include <new>
#include <random>
#include <thread>

namespace sh = spinesim::haptics;

// --- allocation counter (allocation_counter.hpp): the replacement operators -----------------
namespace spinesim::haptics::testing {
std::atomic<bool> g_count_allocations{false};
std::atomic<long> g_allocations{0};
}  // namespace spinesim::haptics::testing
using spinesim::haptics::testing::g_allocations;
using spinesim::haptics::testing::g_count_allocations;

void* operator new(std::size_t n) {
  if (g_count_allocations.load(std::memory_order_relaxed)) g_allocations.fetch_add(1);
  if (void* p = std::malloc(n ? n : 1)) return p;
  throw std::bad_alloc();
}
void operator delete(void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }

namespace {

sh::Trajectory line_script(const Eigen::Vector3d& from, const Eigen::Vector3d& to, double seconds,
                           double hold_s = 0) {
  sh::Trajectory t;
  t.t_s = {0.0, seconds, seconds + hold_s + 1e-3};
  t.position_mm = {from, to, to};
  t.buttons = {0, 0, 0};
  return t;
}

// Identity poses stamped at `t` (what the scene's publisher writes while it is alive).
sh::ScenePoses fresh_poses(double t) {
  sh::ScenePoses p;
  p.time_s = t;
  return p;
}

sh::Scene wall_scene() {
  sh::Scene scene;
  scene.add_body("wall", sh::square_plane(200, 10));  // z = 0, normal +z
  return scene;
}

}  // namespace

TEST(SafetyChain, NonFiniteBecomesZero) {
  sh::SafetyOptions o;
  o.start_ramp_s = 0;
  sh::SafetyChain chain(o);
  sh::SafetyReport r;
  const double nan = std::numeric_limits<double>::quiet_NaN();
  EXPECT_EQ(chain.apply(Eigen::Vector3d(nan, 1, 0), {}, &r), Eigen::Vector3d::Zero());
  EXPECT_TRUE(r.non_finite);
  EXPECT_EQ(chain.apply(Eigen::Vector3d(0, INFINITY, 0), {}, &r), Eigen::Vector3d::Zero());
}

TEST(SafetyChain, ClampKeepsTheDirection) {
  sh::SafetyOptions o;
  o.start_ramp_s = 0;
  o.continuous_window_s = 1e6;  // the continuous limiter out of the way
  sh::SafetyChain chain(o);
  sh::SafetyReport r;
  const Eigen::Vector3d f(30, -40, 0);
  const Eigen::Vector3d out = chain.apply(f, {}, &r);
  EXPECT_TRUE(r.clamped);
  EXPECT_NEAR(out.norm(), o.peak_force_n, 1e-12);
  EXPECT_NEAR(out.normalized().dot(f.normalized()), 1.0, 1e-12);
}

TEST(SafetyChain, ContinuousLimitHoldsTheRmsAtTheRating) {
  sh::SafetyOptions o;
  o.start_ramp_s = 0;
  sh::SafetyChain chain(o);
  double last = 0;
  for (int i = 0; i < 20000; ++i) last = chain.apply(Eigen::Vector3d(0, 2.5, 0), {}).norm();
  EXPECT_NEAR(last, o.continuous_force_n, 0.01);
  EXPECT_NEAR(chain.rms_force_n(), 2.5, 0.01);
  // A short press below the rating passes untouched.
  sh::SafetyChain fresh(o);
  EXPECT_NEAR(fresh.apply(Eigen::Vector3d(0, 0.5, 0), {}).norm(), 0.5, 1e-12);
}

TEST(SafetyChain, RampsOnStartAndOnPenetratingContact) {
  sh::SafetyOptions o;
  sh::SafetyChain chain(o);
  sh::SafetyTick t;
  const Eigen::Vector3d f(0, 0.5, 0);
  EXPECT_NEAR(chain.apply(f, t).norm(), 0.5 * 0.001 / o.start_ramp_s, 1e-9);
  for (int i = 0; i < 1000; ++i) chain.apply(f, t);
  EXPECT_NEAR(chain.apply(f, t).norm(), 0.5, 1e-9);
  // Contact begins 3 mm in: the force starts from zero again.
  t.contact = true;
  t.penetration_mm = 3;
  EXPECT_LT(chain.apply(f, t).norm(), 0.5 * 0.01);
  for (int i = 0; i < 300; ++i) chain.apply(f, t);
  EXPECT_NEAR(chain.apply(f, t).norm(), 0.5, 1e-9);
  // Contact beginning at the surface is not ramped.
  t.contact = false;
  chain.apply(f, t);
  t.contact = true;
  t.penetration_mm = 0.1;
  EXPECT_NEAR(chain.apply(f, t).norm(), 0.5, 1e-9);
}

TEST(SafetyChain, WatchdogFadesOnLateTicksAndStaleData) {
  sh::SafetyOptions o;
  o.start_ramp_s = 0;
  sh::SafetyChain chain(o);
  const Eigen::Vector3d f(0, 0.5, 0);
  sh::SafetyTick late;
  late.period_s = 0.005;
  double out = 1;
  for (int i = 0; i < 10; ++i) out = chain.apply(f, late).norm();
  EXPECT_EQ(out, 0.0);
  sh::SafetyTick ok;
  for (int i = 0; i < 100; ++i) out = chain.apply(f, ok).norm();
  EXPECT_NEAR(out, 0.5, 1e-9);
  sh::SafetyTick stale;
  stale.scene_age_s = 1.0;
  for (int i = 0; i < 60; ++i) out = chain.apply(f, stale).norm();
  EXPECT_EQ(out, 0.0);
}

TEST(SafetyChain, FuzzedTrajectoriesNeverExceedThePeakForce) {
  // Random and fast device motion around and inside a vertebra, both renderers with absurd
  // stiffness, random NaN forces, late ticks and stale scenes: the commanded force stays finite
  // and at most the peak.
  sh::Scene scene;
  scene.add_body("L3", sh::testing::vertebra("L3").surface);
  scene.sample_surfaces(0.6);  // coarse: the force law does not matter here, only its bound
  const auto poses = sh::testing::identity_poses();
  const auto& caps = sh::device_model("touch");
  std::mt19937 rng(23);
  std::normal_distribution<double> step(0, 3);
  std::uniform_real_distribution<double> u(0, 1);
  const Eigen::Vector3d centre = scene.body(0).tree.vertices().colwise().mean();
  double largest = 0;
  for (int run = 0; run < 20; ++run) {
    sh::ProxyParameters pp;
    pp.radius_mm = 2 + 8 * u(rng);
    pp.stiffness_n_per_mm = 50;
    sh::GaoGibsonParameters gp;
    gp.radius_mm = pp.radius_mm;
    gp.stiffness = 50;
    gp.damping = 1;
    sh::SphereProxyRenderer proxy(pp);
    sh::GaoGibsonRenderer gg(gp);
    sh::ForceRenderer& renderer = run % 2 ? static_cast<sh::ForceRenderer&>(gg) : proxy;
    sh::SafetyChain chain(sh::SafetyOptions::for_device(caps));
    Eigen::Vector3d x = centre;  // starts inside the vertebral body
    renderer.reset(x);
    for (int tick = 0; tick < 2000; ++tick) {
      const Eigen::Vector3d v(step(rng), step(rng), step(rng));
      x += v;
      x = centre + (x - centre).cwiseMax(-60).cwiseMin(60);
      sh::ProbeState p{x, v * 1000};
      auto out = renderer.render(p, scene, poses, 1e-3);
      if (u(rng) < 0.01) out.force_n.x() = std::nan("");
      sh::SafetyTick t;
      t.period_s = u(rng) < 0.02 ? 0.004 : 0.001;
      t.scene_age_s = u(rng) < 0.01 ? 1.0 : 0.0;
      t.contact = out.contact;
      t.penetration_mm = out.penetration_mm;
      const Eigen::Vector3d f = chain.apply(out.force_n, t);
      ASSERT_TRUE(f.allFinite());
      ASSERT_LE(f.norm(), caps.peak_force_n * (1 + 1e-12));
      largest = std::max(largest, f.norm());
    }
  }
  EXPECT_GT(largest, 0.5 * caps.continuous_force_n);  // the fuzz did produce forces
}

TEST(Passivity, UsableStiffnessWallIsPassiveAndSettles) {
  const auto& caps = sh::device_model("touch");
  const double T = 1e-3;
  ASSERT_LT(caps.usable_stiffness_n_per_mm, sh::passive_stiffness_limit(caps, T));
  const sh::Scene scene = wall_scene();
  sh::TripleBuffer<sh::ScenePoses> poses{sh::ScenePoses{}};
  // The hand moves the set-point 4 mm into the wall (probe radius 3) and holds it there.
  auto device = sh::make_sim_device(
      line_script(Eigen::Vector3d(0, 0, 10), Eigen::Vector3d(0, 0, -1), 0.3, 2.0), caps, T);
  device->open();
  sh::ProxyParameters pp;
  pp.radius_mm = 3;
  pp.stiffness_n_per_mm = caps.usable_stiffness_n_per_mm;
  sh::SphereProxyRenderer proxy(pp);
  sh::ServoOptions so;
  so.duration_s = 3;
  sh::ServoLoop loop(*device, proxy, scene, poses, sh::SafetyOptions::for_device(caps), so);
  std::vector<double> z;
  for (int k = 1; k <= 2300; ++k) {
    poses.write(fresh_poses(k * T));
    loop.tick(k * T, T);
    z.push_back(loop.status().read().probe_mm.z());
  }
  EXPECT_GE(loop.passivity().minimum_mj(), -1e-6);
  // Settled: the last 200 ms move less than 1 µm, at the equilibrium of hand and wall springs:
  // k_h (z_set − z) = K (r − z) → z = (k_h z_set + K r) / (k_h + K).
  const double kh = sh::HandModel().stiffness_n_per_mm, K = pp.stiffness_n_per_mm;
  const double expected = (kh * -1.0 + K * 3.0) / (kh + K);
  double spread = 0;
  for (std::size_t i = z.size() - 200; i < z.size(); ++i)
    spread = std::max(spread, std::abs(z[i] - z.back()));
  EXPECT_LT(spread, 1e-3);
  EXPECT_NEAR(z.back(), expected, 0.01);
}

TEST(Passivity, TooStiffWallIsReported) {
  const auto& caps = sh::device_model("touch");
  const double T = 1e-3;
  const sh::Scene scene = wall_scene();
  sh::TripleBuffer<sh::ScenePoses> poses{sh::ScenePoses{}};
  auto device = sh::make_sim_device(
      line_script(Eigen::Vector3d(0, 0, 10), Eigen::Vector3d(0, 0, -1), 0.3, 1.0), caps, T);
  device->open();
  sh::ProxyParameters pp;
  pp.radius_mm = 3;
  pp.stiffness_n_per_mm = 5 * sh::passive_stiffness_limit(caps, T);  // 5× the passive limit
  sh::SphereProxyRenderer proxy(pp);
  sh::SafetyOptions safety = sh::SafetyOptions::for_device(caps);
  safety.peak_force_n = safety.continuous_force_n = 1e3;  // see the wall, not the limits
  sh::ServoOptions so;
  so.duration_s = 2;
  sh::ServoLoop loop(*device, proxy, scene, poses, safety, so);
  for (int k = 1; k <= 1300; ++k) {
    poses.write(fresh_poses(k * T));
    loop.tick(k * T, T);
  }
  EXPECT_LT(loop.passivity().minimum_mj(), -1.0)
      << "the observer must see the injected energy; " << loop.passivity().energy_mj() << " "
      << loop.status().read().probe_mm.z();
}

TEST(ServoLoop, TicksDoNotAllocate) {
  const auto& caps = sh::device_model("touch");
  sh::Scene scene;
  scene.add_body("L3", sh::testing::vertebra("L3").surface);
  scene.add_body("L4", sh::testing::vertebra("L4").surface);
  scene.sample_surfaces(0.3);
  sh::TripleBuffer<sh::ScenePoses> poses{sh::ScenePoses{}};
  const Eigen::Vector3d c = scene.body(0).tree.vertices().colwise().mean();
  for (int which = 0; which < 2; ++which) {
    auto device = sh::make_sim_device(
        line_script(c + Eigen::Vector3d(0, 0, 40), c + Eigen::Vector3d(0, -20, -60), 1.0), caps,
        1e-3);
    device->open();
    sh::ProxyParameters pp;
    sh::GaoGibsonParameters gp;
    sh::SphereProxyRenderer proxy(pp);
    sh::GaoGibsonRenderer gg(gp);
    sh::ForceRenderer& r = which ? static_cast<sh::ForceRenderer&>(gg) : proxy;
    sh::ServoOptions so;
    so.duration_s = 2;
    sh::ServoLoop loop(*device, r, scene, poses, sh::SafetyOptions::for_device(caps), so);
    loop.record_to([](const sh::TickRecord*, std::size_t) {}, 4096);
    g_allocations = 0;
    g_count_allocations = true;
    for (int k = 1; k <= 1000; ++k) {
      poses.write(fresh_poses(k * 1e-3));
      loop.tick(k * 1e-3, 1e-3);
    }
    g_count_allocations = false;
    EXPECT_EQ(g_allocations.load(), 0) << r.name();
    EXPECT_GT(loop.stats().contact_ticks, 10) << r.name();
  }
}

TEST(ServoLoop, ThreadKeepsTimeAndZeroesTheForceAtTheEnd) {
  const auto& caps = sh::device_model("touch");
  const sh::Scene scene = wall_scene();
  sh::TripleBuffer<sh::ScenePoses> poses{sh::ScenePoses{}};
  auto device = sh::make_null_device(Eigen::Vector3d(0, 0, 1), caps, 1e-3, 0);
  device->open();
  sh::ProxyParameters pp;
  pp.radius_mm = 3;
  sh::SphereProxyRenderer proxy(pp);
  sh::ServoOptions so;
  so.duration_s = 0.5;
  so.realtime_priority = false;
  sh::ServoLoop loop(*device, proxy, scene, poses, sh::SafetyOptions::for_device(caps), so);
  std::size_t recorded = 0;
  loop.record_to([&](const sh::TickRecord*, std::size_t n) { recorded += n; }, 1 << 12);
  // The scene publisher is this thread: it stamps the poses once, so the data go stale after
  // 50 ms and the watchdog fades the force — which is what a stalled slow thread must cause.
  sh::ServoStatus last;
  const auto stats = loop.run([&](const sh::ServoStatus& s, double) { last = s; });
  EXPECT_EQ(stats.stop_reason, "duration");
  EXPECT_NEAR(double(stats.ticks), 500, 25);
  // The status carries the loop's own timing (for a viewer's panel) and the poses rendered.
  EXPECT_GT(last.ticks, 400);
  EXPECT_GT(last.period_us, 0);
  EXPECT_GT(last.compute_us, 0);
  EXPECT_GE(last.recent_compute_us, last.compute_us);
  EXPECT_GE(last.recent_jitter_us, std::abs(last.period_us - 1000.f));
  EXPECT_TRUE(last.poses.pose[0].R.isIdentity());
  EXPECT_NEAR(stats.period_us.p50, 1000, 100);
  EXPECT_EQ(recorded, std::size_t(stats.ticks));
  EXPECT_GT(stats.fading_ticks, 300);
  EXPECT_EQ(stats.realtime_reason, "not asked for");
}

// The floor probe: a bare periodic thread. Its counts are consistent (it cannot wake more often
// than its period allows, late ≤ all), its percentiles ordered, and stop() is idempotent.
TEST(LatencyProbe, CountsItsWakeUpsAndStopsCleanly) {
  sh::LatencyProbe probe;
  const double T = 1e-3;
  const auto t0 = std::chrono::steady_clock::now();
  probe.start(T, false, 0, 1.0);
  std::this_thread::sleep_for(std::chrono::milliseconds(200));
  const sh::LatencyProbeStats s = probe.stop();
  const double elapsed =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  EXPECT_GE(s.wakeups, 1);
  EXPECT_LE(s.wakeups, std::int64_t(elapsed / T) + 2);
  EXPECT_LE(s.late, s.wakeups);
  EXPECT_GE(s.latency_us.p50, 0);
  EXPECT_LE(s.latency_us.p50, s.latency_us.p99);
  EXPECT_LE(s.latency_us.p99, s.latency_us.p999);
  EXPECT_LE(s.latency_us.p999, s.latency_us.max);
  EXPECT_FALSE(s.realtime_priority);
  EXPECT_EQ(s.realtime_reason, "not asked for");
  EXPECT_EQ(probe.stop().wakeups, s.wakeups);  // idempotent
  // Started again, it starts from zero.
  probe.start(T, false, 0, 0.1);
  std::this_thread::sleep_for(std::chrono::milliseconds(20));
  EXPECT_LE(probe.stop().wakeups, s.wakeups);
}

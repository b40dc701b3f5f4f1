// Hostile hands against the tick's bounds: every hostile trajectory (haptics/hostile.hpp) on two
// vertebrae, through the servo's own tick with the simulated hand. The commanded force never
// exceeds the device's peak, the collision work of a tick never exceeds its bound, and the proxy
// never enters a bone — also when the bound is made so small that it is reached all the time.
#include "haptics_fixtures.hpp"
#include "spinesim/haptics/hostile.hpp"
#include "spinesim/haptics/servo.hpp"

#include <gtest/gtest.h>

#include <string>

namespace sh = spinesim::haptics;

namespace {

const sh::Scene& two_vertebrae() {
  static const sh::Scene scene = [] {
    sh::Scene s;
    s.add_body("L3", sh::testing::vertebra("L3").surface);
    s.add_body("L4", sh::testing::vertebra("L4").surface);
    s.sample_surfaces(0.5);
    return s;
  }();
  return scene;
}

struct HostileRun {
  sh::ServoStats stats;
  int proxy_inside_ticks = 0;  ///< ticks whose proxy overlapped a bone (checked every 5th)
};

// The trajectory through ServoLoop::tick (untimed), the proxy checked against the bones.
HostileRun run(const std::string& name, sh::ForceRenderer& renderer, double radius_mm,
               bool check_proxy) {
  const sh::Scene& scene = two_vertebrae();
  const auto& caps = sh::device_model("touch");
  const double T = 1e-3;
  const sh::Trajectory script = sh::hostile_trajectory(name, scene);
  auto device = sh::make_sim_device(script, caps, T);
  device->open();
  renderer.reset(script.position_mm.front());
  sh::TripleBuffer<sh::ScenePoses> poses{sh::ScenePoses{}};
  sh::ServoOptions so;
  so.duration_s = script.duration_s();
  sh::ServoLoop loop(*device, renderer, scene, poses, sh::SafetyOptions::for_device(caps), so);
  HostileRun r;
  const int ticks = int(script.duration_s() / T);
  for (int k = 1; k <= ticks; ++k) {
    sh::ScenePoses p;
    p.time_s = k * T;
    poses.write(p);
    loop.tick(k * T, T);
    if (check_proxy && k % 5 == 0 &&
        !sh::testing::clear_of_surfaces(scene, p, loop.status().read().proxy_mm, radius_mm, 1e-6))
      ++r.proxy_inside_ticks;
  }
  r.stats = loop.stats();
  return r;
}

}  // namespace

TEST(HostileTrajectories, TheForceStaysUnderThePeakAndTheWorkUnderItsBound) {
  const double peak = sh::device_model("touch").peak_force_n;
  for (const std::string& name : sh::hostile_names()) {
    sh::ProxyParameters pp;
    pp.radius_mm = 4;
    sh::SphereProxyRenderer proxy(pp);
    // start-inside begins with the proxy in the bone it is leaving.
    const HostileRun p = run(name, proxy, pp.radius_mm, name != "start-inside");
    EXPECT_LE(p.stats.max_force_n, peak * (1 + 1e-12)) << name;
    EXPECT_LE(p.stats.max_render_work, pp.max_work) << name;
    EXPECT_EQ(p.proxy_inside_ticks, 0) << name;
    EXPECT_EQ(p.stats.non_finite_ticks, 0) << name;
    // (A proxy that starts inside leaves through the one-sided surface without a contact.)
    if (name != "skim" && name != "start-inside")
      EXPECT_GT(p.stats.contact_ticks, 20) << name << ": the hand met no bone";

    sh::GaoGibsonParameters gp;
    gp.radius_mm = 4;
    gp.sample_spacing_mm = 0.5;
    sh::GaoGibsonRenderer gg(gp);
    const HostileRun g = run(name, gg, gp.radius_mm, false);
    EXPECT_LE(g.stats.max_force_n, peak * (1 + 1e-12)) << name;
    EXPECT_LE(g.stats.max_render_work, gp.max_triangles) << name;
  }
}

// With a bound of 64 units the sweeps reach it on many ticks: the proxy then moves only as far
// as the search proved free, so it still never enters a bone, and it catches up later.
TEST(HostileTrajectories, AtASmallBoundTheProxyLagsButNeverEntersABone) {
  for (const std::string name : {"sweep", "teleport"}) {
    sh::ProxyParameters pp;
    pp.radius_mm = 4;
    pp.max_work = 64;
    sh::SphereProxyRenderer proxy(pp);
    const HostileRun r = run(name, proxy, pp.radius_mm, true);
    EXPECT_GT(r.stats.truncated_ticks, 10) << name;
    EXPECT_LE(r.stats.max_render_work, 64) << name;
    EXPECT_EQ(r.proxy_inside_ticks, 0) << name;
    EXPECT_GT(r.stats.contact_ticks, 20) << name;
  }
}

TEST(HostileTrajectories, EveryOneIsAValidScriptAndAnUnknownNameIsOneLine) {
  for (const std::string& name : sh::hostile_names()) {
    const sh::Trajectory t = sh::hostile_trajectory(name, two_vertebrae());
    ASSERT_GE(t.t_s.size(), 2u) << name;
    for (std::size_t k = 1; k < t.t_s.size(); ++k) ASSERT_GT(t.t_s[k], t.t_s[k - 1]) << name;
    EXPECT_GT(t.duration_s(), 0.5) << name;
    EXPECT_LT(t.duration_s(), 5) << name;
  }
  // The sweep is at least 2 m/s.
  const sh::Trajectory s = sh::hostile_trajectory("sweep", two_vertebrae());
  double fastest = 0;
  for (std::size_t k = 1; k < s.t_s.size(); ++k)
    fastest = std::max(
        fastest, (s.position_mm[k] - s.position_mm[k - 1]).norm() / (s.t_s[k] - s.t_s[k - 1]));
  EXPECT_GE(fastest, 2000);
  try {
    sh::hostile_trajectory("wobble", two_vertebrae());
    ADD_FAILURE() << "accepted an unknown name";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("teleport"), std::string::npos);
  }
  EXPECT_THROW(sh::hostile_trajectory("sweep", sh::Scene{}), std::invalid_argument);
}

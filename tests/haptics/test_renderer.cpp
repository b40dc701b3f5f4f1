// The two force renderers: the Gao–Gibson probe-normal force on a plane against its integral in
// closed form, and the sphere proxy's promise — it never enters a surface, however fast the
// device moves — on planes and on vertebrae.
#include "haptics_fixtures.hpp"
#include "spinesim/haptics/renderer.hpp"

#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include <cmath>
#include <random>

namespace sh = spinesim::haptics;
namespace sm = spinesim::mesh;

namespace {

// ∫ (r − |p − c|) dA over the part of the plane z = 0 inside the ball of radius r centred at
// height h: π r (r² − h²) − (2π/3)(r³ − |h|³).
double plane_depth_integral(double r, double h) {
  if (std::abs(h) >= r) return 0;
  return M_PI * r * (r * r - h * h) - 2.0 * M_PI / 3.0 * (r * r * r - std::pow(std::abs(h), 3));
}

sh::Scene plane_scene(double spacing) {
  sh::Scene scene;
  scene.add_body("plane", sh::square_plane(60, 2));
  if (spacing > 0) scene.sample_surfaces(spacing);
  return scene;
}

}  // namespace

TEST(GaoGibson, PlaneForceIsTheDepthIntegral) {
  const sh::Scene scene = plane_scene(0.1);
  const auto poses = sh::testing::identity_poses();
  for (double r : {3.0, 6.0}) {
    sh::GaoGibsonParameters p;
    p.radius_mm = r;
    p.law = sh::GaoGibsonLaw::eq_4_9;
    p.stiffness = 0.02;  // N/mm³
    p.sample_spacing_mm = 0.1;
    p.max_triangles = 4096;
    sh::GaoGibsonRenderer gg(p);
    for (double depth = 0.25; depth < 2 * r; depth += 0.25) {
      sh::ProbeState probe;
      probe.position_mm = Eigen::Vector3d(0.3, -0.7, r - depth);
      const auto out = gg.render(probe, scene, poses, 1e-3);
      const double expected = p.stiffness * plane_depth_integral(r, r - depth);
      EXPECT_NEAR(out.force_n.norm(), expected, 0.01 * expected + 1e-6) << r << " " << depth;
      // Eq 4.11: along the plane's normal, away from the plane while the centre is above it.
      if (depth < r - 0.1) EXPECT_GT(out.force_n.z(), 0.999 * out.force_n.norm());
      if (depth > r + 0.1) EXPECT_LT(out.force_n.z(), -0.999 * out.force_n.norm());
    }
  }
}

TEST(GaoGibson, Eq410ProbesOfTwoSizesMeetAtTheSmallProbesPeak) {
  // With eq 4.10 the force is k × (depth integral) / (π r²); for r and 2r at depth r both are
  // k r / 3 exactly in the continuum (thesis fig 4.19: "nearly the same").
  const sh::Scene scene = plane_scene(0.1);
  const auto poses = sh::testing::identity_poses();
  const double r = 3.0;
  auto force = [&](double radius, double depth) {
    sh::GaoGibsonParameters p;
    p.radius_mm = radius;
    p.stiffness = 0.5;
    sh::GaoGibsonRenderer gg(p);
    sh::ProbeState probe;
    probe.position_mm = Eigen::Vector3d(0, 0, radius - depth);
    return gg.render(probe, scene, poses, 1e-3).force_n.norm();
  };
  EXPECT_NEAR(force(r, r), 0.5 * r / 3, 0.01 * 0.5 * r / 3);
  EXPECT_NEAR(force(2 * r, r), force(r, r), 0.01 * force(r, r));
  for (double depth : {0.5, 1.0, 2.0}) EXPECT_GT(force(r, depth), force(2 * r, depth)) << depth;
}

TEST(GaoGibson, DampingResistsPenetrationRateAndNeverPulls) {
  const sh::Scene scene = plane_scene(0.2);
  const auto poses = sh::testing::identity_poses();
  sh::GaoGibsonParameters p;
  p.radius_mm = 4;
  p.damping = 0.01;
  sh::GaoGibsonRenderer gg(p);
  sh::ProbeState probe;
  probe.position_mm = Eigen::Vector3d(0, 0, 3);
  const double still = gg.render(probe, scene, poses, 1e-3).force_n.z();
  probe.velocity_mm_s = Eigen::Vector3d(0, 0, -50);  // pressing in
  EXPECT_GT(gg.render(probe, scene, poses, 1e-3).force_n.z(), still);
  probe.velocity_mm_s = Eigen::Vector3d(0, 0, 1e6);  // leaving very fast
  EXPECT_GE(gg.render(probe, scene, poses, 1e-3).force_n.z(), 0.0);
}

TEST(SphereProxy, PlaneSpringAndSliding) {
  const sh::Scene scene = plane_scene(0);
  const auto poses = sh::testing::identity_poses();
  sh::ProxyParameters p;
  p.radius_mm = 4;
  p.stiffness_n_per_mm = 0.5;
  sh::SphereProxyRenderer proxy(p);
  proxy.reset(Eigen::Vector3d(0, 0, 10));
  sh::ProbeState probe;
  for (int i = 0; i <= 100; ++i) {  // down through the plane, 0.1 mm per tick
    probe.position_mm = Eigen::Vector3d(0, 0, 10 - 0.1 * i);
    const auto out = proxy.render(probe, scene, poses, 1e-3);
    const double behind = std::max(0.0, p.radius_mm - probe.position_mm.z());
    EXPECT_NEAR(out.force_n.z(), p.stiffness_n_per_mm * behind, 1e-3) << i;
    EXPECT_GE(out.proxy_mm.z(), p.radius_mm - 1e-9);
  }
  for (int i = 1; i <= 50; ++i) {  // slide sideways while pressed 2 mm in
    probe.position_mm = Eigen::Vector3d(0.2 * i, 0, 2);
    const auto out = proxy.render(probe, scene, poses, 1e-3);
    EXPECT_NEAR(out.proxy_mm.x(), probe.position_mm.x(), 1e-6);
    EXPECT_NEAR(out.force_n.z(), 1.0, 1e-3);
    EXPECT_NEAR(out.force_n.x(), 0.0, 1e-6);
  }
  probe.position_mm = Eigen::Vector3d(5, 0, 20);  // let go
  const auto out = proxy.render(probe, scene, poses, 1e-3);
  EXPECT_FALSE(out.contact);
  EXPECT_EQ(out.force_n, Eigen::Vector3d::Zero());
}

TEST(SphereProxy, FastSweepAcrossASpinousProcessStaysOnItsSide) {
  const auto& v = sh::testing::vertebra("T6");
  const auto solid = sm::parametric_vertebra("T6", SPINESIM_DATA_DIR);
  sh::Scene scene;
  scene.add_body("T6", v.surface);
  scene.sample_surfaces(0.25);
  const auto poses = sh::testing::identity_poses();
  // The spinous process is the solid's last part; cross it at mid length, left to right.
  const auto& spinous = solid.parts.back();
  const Eigen::Vector3d mid_local = 0.5 * (spinous.a + spinous.b);
  auto world = [&](const Eigen::Vector3d& local) {
    return Eigen::Vector3d(solid.frame.origin_mm + solid.frame.axes * local);
  };
  const double r = 2.0, side = spinous.half_width_mm + r + 1.5;
  const Eigen::Vector3d left = world(mid_local + Eigen::Vector3d(side, 0, 0));
  const Eigen::Vector3d right = world(mid_local - Eigen::Vector3d(side, 0, 0));
  const Eigen::Vector3d lateral = solid.frame.axes.col(0);

  for (int steps : {1, 3, 50}) {  // 1: the whole crossing in one tick (about 10 m/s)
    sh::ProxyParameters p;
    p.radius_mm = r;
    sh::SphereProxyRenderer proxy(p);
    proxy.reset(left);
    sh::ProbeState probe;
    sh::RenderOutput out;
    for (int i = 1; i <= steps; ++i) {
      probe.position_mm = left + (right - left) * double(i) / steps;
      out = proxy.render(probe, scene, poses, 1e-3);
      ASSERT_TRUE(sh::testing::clear_of_surfaces(scene, poses, out.proxy_mm, r, 1e-6))
          << steps << " " << i;
    }
    EXPECT_GT((out.proxy_mm - world(mid_local)).dot(lateral), 0) << steps;
    EXPECT_TRUE(out.contact);
    EXPECT_GT(out.force_n.dot(lateral), 0) << "pulls the hand back to its side";
  }
  // The penalty method, for comparison: with the probe's centre inside the process its sphere
  // holds no surface point (no force at all), and past the far face it pushes on through.
  sh::GaoGibsonParameters g;
  g.radius_mm = r;
  sh::GaoGibsonRenderer gg(g);
  sh::ProbeState probe;
  probe.position_mm = world(mid_local);
  EXPECT_EQ(gg.render(probe, scene, poses, 1e-3).force_n.norm(), 0.0);
  probe.position_mm = world(mid_local - Eigen::Vector3d(spinous.half_width_mm + 1, 0, 0));
  EXPECT_LT(gg.render(probe, scene, poses, 1e-3).force_n.dot(lateral), 0);
}

TEST(SphereProxy, SweepAcrossTheGapBetweenTwoVertebraeNeverEntersEither) {
  // Pressed 3 mm into the front of L3's body, the device slides down across the L3-L4 disc space
  // (empty in the rigid scene, 11 mm high, wider than the 8 mm probe) to L4's body — in one
  // tick, in five, and slowly. The proxy may dip into the gap but never into a vertebra, and
  // pulled straight forward afterwards it comes free.
  sh::Scene scene;
  scene.add_body("L3", sh::testing::vertebra("L3").surface);
  scene.add_body("L4", sh::testing::vertebra("L4").surface);
  const auto poses = sh::testing::identity_poses();
  const auto l3 = sm::parametric_vertebra("L3", SPINESIM_DATA_DIR);
  const auto l4 = sm::parametric_vertebra("L4", SPINESIM_DATA_DIR);
  const double r = 4.0;
  auto pressed = [&](const sm::ParametricVertebra& v) {
    const Eigen::Vector3d front = v.frame.axes.col(2);
    const double half_depth = 0.5 * (v.lower_depth_mm + v.upper_depth_mm) / 2;
    return Eigen::Vector3d(v.frame.origin_mm + (half_depth + r - 3.0) * front);
  };
  const Eigen::Vector3d from = pressed(l3), to = pressed(l4);
  for (int steps : {1, 5, 100}) {
    sh::ProxyParameters p;
    p.radius_mm = r;
    sh::SphereProxyRenderer proxy(p);
    proxy.reset(from + 20 * l3.frame.axes.col(2));  // start in front, then press in
    sh::ProbeState probe;
    probe.position_mm = from;
    ASSERT_TRUE(proxy.render(probe, scene, poses, 1e-3).contact);
    for (int i = 1; i <= steps; ++i) {
      probe.position_mm = from + (to - from) * double(i) / steps;
      const auto out = proxy.render(probe, scene, poses, 1e-3);
      ASSERT_TRUE(sh::testing::clear_of_surfaces(scene, poses, out.proxy_mm, r, 1e-6))
          << steps << " " << i;
    }
    sh::RenderOutput out;
    for (int i = 1; i <= 60; ++i) {
      probe.position_mm = to + 0.5 * i * l4.frame.axes.col(2);
      out = proxy.render(probe, scene, poses, 1e-3);
      ASSERT_TRUE(sh::testing::clear_of_surfaces(scene, poses, out.proxy_mm, r, 1e-6));
    }
    EXPECT_FALSE(out.contact) << steps << ": the proxy stayed caught";
  }
}

TEST(SphereProxy, RandomFastTrajectoriesNeverEnterTwoVertebrae) {
  sh::Scene scene;
  scene.add_body("L3", sh::testing::vertebra("L3").surface);
  scene.add_body("L4", sh::testing::vertebra("L4").surface);
  sh::ScenePoses poses = sh::testing::identity_poses();
  const Eigen::Vector3d lo =
      scene.body(0).tree.bounds_min().cwiseMin(scene.body(1).tree.bounds_min());
  const Eigen::Vector3d hi =
      scene.body(0).tree.bounds_max().cwiseMax(scene.body(1).tree.bounds_max());
  std::mt19937 rng(17);
  std::uniform_real_distribution<double> u(0, 1);
  std::normal_distribution<double> step(0, 4.0);  // mm per tick: up to ~10 m/s bursts
  int contacts = 0;
  for (double r : {2.0, 6.0}) {
    sh::ProxyParameters p;
    p.radius_mm = r;
    sh::SphereProxyRenderer proxy(p);
    Eigen::Vector3d device = Eigen::Vector3d(0, 0.5 * (lo.y() + hi.y()), hi.z() + r + 5);
    proxy.reset(device);
    for (int tick = 0; tick < 2500; ++tick) {
      device += Eigen::Vector3d(step(rng), step(rng), step(rng));
      device = device.cwiseMax(lo - Eigen::Vector3d::Constant(10))
                   .cwiseMin(hi + Eigen::Vector3d::Constant(10));
      sh::ProbeState probe;
      probe.position_mm = device;
      const auto out = proxy.render(probe, scene, poses, 1e-3);
      ASSERT_TRUE(sh::testing::clear_of_surfaces(scene, poses, out.proxy_mm, r, 1e-6))
          << r << " " << tick;
      ASSERT_TRUE(out.force_n.allFinite());
      contacts += out.contact;
    }
  }
  EXPECT_GT(contacts, 300);
}

TEST(SphereProxy, RidesAMovingVertebra) {
  sh::Scene scene;
  scene.add_body("plane", sh::square_plane(60, 2));
  sh::ScenePoses poses = sh::testing::identity_poses();
  sh::ProxyParameters p;
  p.radius_mm = 3;
  sh::SphereProxyRenderer proxy(p);
  proxy.reset(Eigen::Vector3d(0, 0, 5));
  sh::ProbeState probe;
  probe.position_mm = Eigen::Vector3d(0, 0, 1);  // pressed 2 mm into the plane
  auto out = proxy.render(probe, scene, poses, 1e-3);
  ASSERT_TRUE(out.contact);
  const double skin = 2 * p.skin_mm;  // the proxy rests a skin's width off the surface
  EXPECT_NEAR(out.proxy_mm.z(), 3, skin);
  // The plane moves 1 mm sideways and 0.5 mm up: the proxy goes with it.
  poses.pose[0].t = Eigen::Vector3d(1, 0, 0.5);
  EXPECT_NEAR((proxy.proxy_world(poses) - Eigen::Vector3d(1, 0, 3.5)).norm(), 0, skin);
  out = proxy.render(probe, scene, poses, 1e-3);
  EXPECT_NEAR(out.proxy_mm.z(), 3.5, skin);
  EXPECT_NEAR(out.force_n.z(), 0.5 * 2.5, 0.5 * skin);
}

TEST(Renderers, RefuseANonPositiveRadius) {
  sh::ProxyParameters p;
  p.radius_mm = 0;
  EXPECT_THROW(sh::SphereProxyRenderer{p}, std::invalid_argument);
  sh::GaoGibsonParameters g;
  g.radius_mm = -1;
  EXPECT_THROW(sh::GaoGibsonRenderer{g}, std::invalid_argument);
  g.radius_mm = std::nan("");
  EXPECT_THROW(sh::GaoGibsonRenderer{g}, std::invalid_argument);
}

// Bodies are found by name: a second body of a name already in the scene is refused (a rib
// named as a vertebra once took that vertebra's poses).
TEST(Scene, RefusesASecondBodyOfTheSameName) {
  sh::Scene scene;
  scene.add_body("L4", sh::square_plane(10, 2));
  EXPECT_THROW(scene.add_body("L4", sh::square_plane(10, 2)), std::invalid_argument);
  scene.add_body("rib_L4", sh::square_plane(10, 2));
  EXPECT_EQ(scene.size(), 2);
  EXPECT_EQ(scene.index("L4"), 0);
  EXPECT_EQ(scene.index("rib_L4"), 1);
}

// Disc palpation: free of the disc no force and the probe is the device; pressed in, the
// simulated probe stays on the surface side of the device and the coupling spring balances the
// disc's contact force (what the hand feels is what the disc pushes with); the felt stiffness
// never exceeds the coupling's; pressing in and out in cycles is passive (the rigid stage's
// observer); the thread steps at its rate; bad options are refused.
#include "spinesim/haptics/disc_palpation.hpp"
#include "spinesim/haptics/safety.hpp"
#include "spinesim/mesh/disc_geometry.hpp"
#include "spinesim/mesh/material.hpp"
#include "spinesim/mesh/structured_disc.hpp"

#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <thread>

namespace sh = spinesim::haptics;
namespace mss = spinesim::mss;
namespace mesh = spinesim::mesh;
using Eigen::Vector3d;

namespace {

const mss::MssModel& disc() {
  static const mss::MssModel m = [] {
    mesh::StructuredDiscOptions o;  // 2400 tets, surface nodes 2.8-3.7 mm apart
    o.sectors = 40;
    o.layers = 4;
    const mesh::TetMesh t =
        mesh::mesh_structured_disc(mesh::disc_dimensions("L4-L5", SPINESIM_DATA_DIR), o);
    return mss::MssModel(t, mesh::load_material("real-disc", SPINESIM_DATA_DIR));
  }();
  return m;
}

/// The disc's most anterior surface point (local frame: +z anterior) and its outward normal.
std::pair<Vector3d, Vector3d> anterior_wall() {
  const auto& V = disc().mesh().V;
  Eigen::Index best = 0;
  for (Eigen::Index i = 0; i < V.rows(); ++i)
    if (std::abs(V(i, 1)) < 1e-9 && V(i, 2) > V(best, 2)) best = i;  // mid-height node
  return {V.row(best).transpose(), Vector3d(0, 0, 1)};
}

sh::DiscPalpationOptions options() {
  sh::DiscPalpationOptions o;
  o.coupling_stiffness_n_per_mm = 0.5;
  o.probe_radius_mm = 4;
  o.realtime_priority = false;
  return o;
}

mss::Boundary held_plates() {
  mss::Boundary bc;
  bc.plate_center_mm = mss::default_plate_center(disc().mesh());
  return bc;
}

}  // namespace

TEST(DiscPalpation, FreeOfTheDiscThereIsNoForce) {
  sh::DiscPalpation p(disc(), held_plates(), options());
  const auto [wall, n] = anterior_wall();
  const sh::DiscContact& c = p.step(wall + 10.0 * n);
  EXPECT_FALSE(c.contact);
  EXPECT_EQ(c.probe_mm, wall + 10.0 * n);
  EXPECT_EQ(c.force_n.norm(), 0.0);
  EXPECT_EQ(c.volume_change, 0.0);
  EXPECT_FALSE(c.failed);
}

TEST(DiscPalpation, StartedInsideTheDiscItWaitsUntilTheDeviceIsOut) {
  sh::DiscPalpation p(disc(), held_plates(), options());
  const auto [wall, n] = anterior_wall();
  EXPECT_FALSE(p.step(wall - 8.0 * n).contact);       // inside the annulus
  EXPECT_FALSE(p.step(wall - 2.0 * n).contact);       // still overlapping the wall
  EXPECT_FALSE(p.step(wall + 6.0 * n).contact);       // out: armed
  const sh::DiscContact& c = p.step(wall + 3.5 * n);  // radius 4: touching from outside
  EXPECT_TRUE(c.contact);
  EXPECT_GT((c.probe_mm - (wall + 3.5 * n)).dot(n), 0.0);  // held outside, pushing the hand out
}

TEST(DiscPalpation, CouplingBalancesTheDiscsForceAndBoundsTheFeltStiffness) {
  const sh::DiscPalpationOptions o = options();
  sh::DiscPalpation p(disc(), held_plates(), o);
  const auto [wall, n] = anterior_wall();
  // Approach from outside, press 4 mm past the wall over 200 ms, hold 300 ms.
  p.step(wall + 10.0 * n);
  sh::DiscContact c;
  double previous_felt = 0, previous_depth = 0, max_stiffness = 0;
  for (int k = 0; k < 500; ++k) {
    const double depth = 4.0 * std::min(1.0, k / 200.0) - o.probe_radius_mm + 0.5;
    c = p.step(wall - depth * n);
    ASSERT_FALSE(c.failed) << "step " << k;
    const double felt = (o.coupling_stiffness_n_per_mm * (c.probe_mm - (wall - depth * n))).dot(n);
    if (depth > previous_depth)
      max_stiffness = std::max(max_stiffness, (felt - previous_felt) / (depth - previous_depth));
    previous_felt = felt, previous_depth = depth;
  }
  ASSERT_TRUE(c.contact);
  const Vector3d device = wall - previous_depth * n;
  const Vector3d felt = o.coupling_stiffness_n_per_mm * (c.probe_mm - device);
  EXPECT_GT(felt.dot(n), 0.5);                   // pushed back out, by more than half a newton
  EXPECT_GT((c.probe_mm - device).dot(n), 0.0);  // the simulated probe is nearer the surface
  // Settled: the spring on the probe balances the disc's push on it.
  EXPECT_LT((felt - c.force_n).norm(), 0.02 * c.force_n.norm())
      << "felt " << felt.transpose() << " disc " << c.force_n.transpose();
  EXPECT_LE(max_stiffness, o.coupling_stiffness_n_per_mm * 1.001);
  EXPECT_LT(c.volume_change, 0.0);  // pressed in, the disc loses a little volume
  EXPECT_GT(c.volume_change, -0.05);
}

TEST(DiscPalpation, PressingInAndOutIsPassive) {
  const sh::DiscPalpationOptions o = options();
  sh::DiscPalpation p(disc(), held_plates(), o);
  const auto [wall, n] = anterior_wall();
  sh::PassivityObserver observer;
  Vector3d held = Vector3d::Zero(), last = wall + 2.0 * n;
  p.step(wall + 10.0 * n);
  for (int k = 0; k < 1500; ++k) {  // three 0.5 s cycles, 5 mm into the disc at the deepest
    const double depth = -2.0 + 3.5 * (1 - std::cos(2 * M_PI * k / 500.0));
    const Vector3d device = wall - depth * n;
    observer.add(held, device - last, 1e-3);
    last = device;
    const sh::DiscContact& c = p.step(device);
    held = c.contact ? Vector3d(o.coupling_stiffness_n_per_mm * (c.probe_mm - device))
                     : Vector3d::Zero();
  }
  EXPECT_GE(observer.minimum_mj(), -1e-9);
  EXPECT_GT(observer.energy_mj(), 0.0);  // the disc dissipated some of the hand's work
}

TEST(DiscPalpation, ThreadStepsAtItsRateAndTheRendererAddsTheCoupling) {
  sh::DiscPalpation p(disc(), held_plates(), options());
  const auto [wall, n] = anterior_wall();
  const Vector3d device = wall - 0.5 * n;  // probe radius 4: overlapping the wall
  p.set_device(wall + 10.0 * n);           // from outside
  p.start();
  // Wait for steps, not for time (a loaded machine runs fewer a second): 20 outside, 50 in.
  const auto wait_for = [&](std::int64_t steps) {
    for (int k = 0; k < 20000 && p.latest().step < steps; ++k)
      std::this_thread::sleep_for(std::chrono::milliseconds(1));
  };
  wait_for(20);
  p.set_device(device);
  wait_for(p.latest().step + 50);
  const sh::DiscContact c = p.latest();
  p.stop();
  EXPECT_GE(p.stats().steps, 70);
  EXPECT_EQ(p.stats().step_us.size(), std::size_t(p.stats().steps));
  EXPECT_TRUE(c.contact);
  // The renderer: no rigid bodies, so the force is the coupling's.
  sh::ProxyParameters pp;
  pp.radius_mm = 4;
  sh::SphereProxyRenderer rigid(pp);
  sh::DiscCouplingRenderer r(rigid, p);
  sh::Scene empty;
  sh::ScenePoses poses;
  sh::ProbeState probe;
  probe.position_mm = device;
  const sh::RenderOutput out = r.render(probe, empty, poses, 1e-3);
  EXPECT_TRUE(out.contact);
  const Vector3d want = 0.5 * (r.disc().probe_mm - device);
  EXPECT_LT((out.force_n - want).norm(), 1e-12);
}

TEST(DiscPalpation, BadOptionsAreRefused) {
  for (auto bad : {+[](sh::DiscPalpationOptions& o) { o.coupling_stiffness_n_per_mm = 0; },
                   +[](sh::DiscPalpationOptions& o) { o.probe_radius_mm = -1; },
                   +[](sh::DiscPalpationOptions& o) { o.probe_radius_mm = 1; },  // slips through
                   +[](sh::DiscPalpationOptions& o) { o.dt_s = 0; },
                   +[](sh::DiscPalpationOptions& o) { o.newton_iterations = 0; },
                   +[](sh::DiscPalpationOptions& o) { o.coupling_damping_n_s_per_mm = NAN; }}) {
    sh::DiscPalpationOptions o = options();
    bad(o);
    EXPECT_THROW(sh::DiscPalpation(disc(), held_plates(), o), std::invalid_argument);
  }
}

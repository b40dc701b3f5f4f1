// Disc palpation: free of the disc no force and the probe is the device; pressed in, the
// simulated probe stays on the surface side of the device and the coupling spring balances the
// disc's contact force (what the hand feels is what the disc pushes with); the felt stiffness
// never exceeds the coupling's; pressing in and out in cycles is passive (the rigid stage's
// observer); the thread steps at its rate; bad options are refused.
#include "disc_fixture.hpp"
#include "spinesim/haptics/disc_palpation.hpp"
#include "spinesim/haptics/safety.hpp"
#include "spinesim/mesh/disc_geometry.hpp"
#include "spinesim/mesh/material.hpp"
#include "spinesim/mesh/structured_disc.hpp"

#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <cstdlib>
#include <thread>

namespace sh = spinesim::haptics;
namespace mss = spinesim::mss;
namespace mesh = spinesim::mesh;
using Eigen::Vector3d;

namespace {

const mss::MssModel& disc() {
  static const mss::MssModel m(spinesim::test::structured_l4l5_disc(),
                               mesh::load_material("real-disc", SPINESIM_DATA_DIR));
  return m;
}

std::pair<Vector3d, Vector3d> anterior_wall() {
  return spinesim::test::anterior_wall(disc().mesh());
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
  for (const double scale : {1.0, 30.0}) {
    sh::DiscPalpationOptions o = options();
    o.force_scale = scale;  // 30: the probe is placed by the disc's local model
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
    std::printf("force scale %.0f: hand's work on the felt force, least %.4f mJ, end %.4f mJ\n",
                scale, observer.minimum_mj(), observer.energy_mj());
    EXPECT_GE(observer.minimum_mj(), -1e-9);
    EXPECT_GT(observer.energy_mj(), 0.0);  // the disc dissipated some of the hand's work
  }
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

namespace {

std::vector<Vector3d> press_path(double depth, double press_s = 0.4) {
  return spinesim::test::press_path(disc().mesh(), options().probe_radius_mm, depth, press_s);
}

}  // namespace

TEST(DiscPalpation, ForceScaleDeformsTheDiscAndKeepsTheFeltStiffness) {
  // Scaled, the disc meets s k_c and the hand feels a 1/s share: the disc is indented far more
  // for the same hand travel, and the felt stiffness stays within k_c.
  const std::vector<Vector3d> path = press_path(3.0);
  double indentation[2] = {0, 0};
  for (const int i : {0, 1}) {
    sh::DiscPalpationOptions o = options();
    o.force_scale = i ? 30.0 : 1.0;
    sh::DiscPalpation p(disc(), held_plates(), o);
    const Vector3d n = anterior_wall().second;
    double previous_felt = 0, previous_depth = -1e9, max_stiffness = 0;
    for (std::size_t k = 0; k < 600; ++k) {
      const sh::DiscContact& c = p.step(path[k]);
      ASSERT_FALSE(c.failed);
      indentation[i] = std::max(indentation[i], c.indentation_mm);
      const double felt =
          c.contact ? o.coupling_stiffness_n_per_mm * (c.probe_mm - path[k]).dot(n) : 0.0;
      const double depth = -path[k].dot(n);
      if (depth > previous_depth && previous_depth > -1e8 && felt > 0)
        max_stiffness = std::max(max_stiffness, (felt - previous_felt) / (depth - previous_depth));
      previous_felt = felt, previous_depth = depth;
    }
    std::printf(
        "force scale %.0f: wall indented %.3f mm at 3 mm of hand travel, felt stiffness "
        "at most %.3f N/mm\n",
        o.force_scale, indentation[i], max_stiffness);
    EXPECT_LE(max_stiffness, o.coupling_stiffness_n_per_mm * 1.001);
  }
  EXPECT_GT(indentation[0], 0.0);
  EXPECT_GT(indentation[1], 5.0 * indentation[0]);
  EXPECT_GT(indentation[1], 0.5);  // visibly: half a millimetre and more
}

TEST(DiscPalpation, MultirateLocalModelFollowsTheSynchronousSolve) {
  // The disc stepped every 10 ms with the local contact model between steps, against the disc
  // stepped every 1 ms: the felt force along the same hand path, a brisk press (30 mm/s).
  const std::vector<Vector3d> path = press_path(3.0, 0.1);
  sh::DiscPalpationOptions sync = options();
  sync.force_scale = 30;
  sh::DiscPalpationOptions multi = sync;
  multi.multirate = true;
  multi.dt_s = 10e-3;
  const auto reference = sh::palpate_offline(disc(), held_plates(), sync, path, 1e-3);
  const auto run = sh::palpate_offline(disc(), held_plates(), multi, path, 1e-3);
  const sh::ForceError e = sh::force_error(run, reference);
  if (std::getenv("MR_TRACE"))
    for (std::size_t k = 0; k < path.size(); k += 5)
      std::printf("%zu %.3f %.3f\n", k, run[k].norm(), reference[k].norm());
  // Without the local model (each step's force held for the next 10 ms): the error to beat.
  std::vector<Vector3d> held(path.size(), Vector3d::Zero());
  for (std::size_t k = 1; k < path.size(); ++k) held[k] = run[k - (k - 1) % 10];
  const sh::ForceError zero_order = sh::force_error(held, reference);
  std::printf(
      "multirate (10 ms worker, local model at 1 kHz) vs synchronous 1 ms: peak %.2f N, "
      "RMS error %.2f %%, max %.2f %%; force held between steps: RMS %.2f %%\n",
      e.peak_n, 100 * e.relative_rms(), 100 * e.relative_max(), 100 * zero_order.relative_rms());
  EXPECT_GT(e.peak_n, 10.0);  // hundreds of newtons' scale: tens of N on this coarse disc
  EXPECT_LT(e.relative_rms(), 0.05);
  EXPECT_LT(e.relative_max(), 0.15);  // the largest at the first touch, within a worker period
  EXPECT_LT(e.relative_rms(), zero_order.relative_rms());
  // Passive: the hand's work on the felt force (1/s of the disc's) never goes negative.
  sh::PassivityObserver observer;
  for (std::size_t k = 1; k < path.size(); ++k)
    observer.add(run[k - 1] / multi.force_scale, path[k] - path[k - 1], 1e-3);
  EXPECT_GE(observer.minimum_mj(), -1e-9);
  EXPECT_THROW(sh::palpate_offline(disc(), held_plates(), sync, path, 2e-3), std::invalid_argument);
}

TEST(DiscPalpation, LocalModelWithoutAStepRendersNothing) {
  const sh::DiscContact none;
  const sh::LocalContact c = sh::evaluate_local_model(none, 15.0, Vector3d(1, 2, 3));
  EXPECT_FALSE(c.contact);
  EXPECT_EQ(c.probe_mm, Vector3d(1, 2, 3));
  EXPECT_EQ(c.force_n, Vector3d::Zero());
}

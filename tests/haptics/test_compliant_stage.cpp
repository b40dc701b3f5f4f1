// The compliant stage: relative poses move the centres as the displacements say; the hook
// attaches only on a press while touching a vertebra, at the proxy; the spine force is the
// scaled spring, clamped, ramped in and out, and the hand feels its reaction; a closed loop with
// a scripted hand drags a vertebra the way it pulls without allocating; the multirate spine's
// local model reproduces its own solve and predicts a nearby one.
#include "spinesim/haptics/compliant_stage.hpp"
#include "spinesim/haptics/servo.hpp"

#include "allocation_counter.hpp"
#include "column_fixture.hpp"

#include <gtest/gtest.h>

#include <chrono>
#include <thread>

namespace sh = spinesim::haptics;
namespace sp = spinesim::spine;
using Eigen::Vector3d;
using spinesim::haptics::testing::at;
using spinesim::haptics::testing::Column;
using spinesim::haptics::testing::touching;

namespace {

/// A linear spine: the hooked vertebra translates by F / k, the others by half that.
class LinearSpine final : public sh::SpineResponse {
 public:
  explicit LinearSpine(double k, double max_n = 600) : k_(k), max_(max_n) {}
  const char* name() const override { return "linear"; }
  void predict(const sh::HookLoad& load, sh::SpineDisplacement& d) override {
    d.setZero();
    if (load.vertebra < 0) return;
    for (int i = 0; i < sh::kSpineVertebrae; ++i)
      d.row(i).head<3>() = (i == load.vertebra ? 1.0 : 0.5) * load.force_n.transpose() / k_;
  }
  const sh::SpineDisplacement& baseline() const override { return base_; }
  double max_force_n() const override { return max_; }

 private:
  double k_, max_;
  sh::SpineDisplacement base_ = sh::SpineDisplacement::Zero();
};

}  // namespace

TEST(CompliantStage, RelativePosesTakeOneDisplacementToTheOther) {
  Column col;
  sh::SpineDisplacement from = sh::SpineDisplacement::Random() * 10,
                        to = sh::SpineDisplacement::Random() * 10;
  sh::ScenePoses poses;
  sh::relative_poses(col.centres, from, to, col.body_of, poses);
  for (int i = 0; i < sh::kSpineVertebrae; ++i) {
    const Vector3d c = col.centres[std::size_t(i)];
    const Vector3d moved_from = c + from.row(i).head<3>().transpose();
    const Vector3d moved_to = c + to.row(i).head<3>().transpose();
    EXPECT_LT((poses.pose[std::size_t(i)].apply(moved_from) - moved_to).norm(), 1e-9);
    EXPECT_LT((poses.pose[std::size_t(i)].R * poses.pose[std::size_t(i)].R.transpose() -
               Eigen::Matrix3d::Identity())
                  .norm(),
              1e-12);
  }
  sh::relative_poses(col.centres, from, from, col.body_of, poses);
  EXPECT_LT((poses.pose[3].R - Eigen::Matrix3d::Identity()).norm(), 1e-12);
  EXPECT_LT(poses.pose[3].t.norm(), 1e-9);
}

TEST(CompliantStage, HooksOnlyOnAPressWhileTouchingAVertebra) {
  Column col;
  LinearSpine spine(10);
  sh::CouplingParameters p;
  p.ramp_s = 0;
  sh::CompliantStage stage(spine, col.centres, col.body_of, p);
  sh::ScenePoses poses;
  const Vector3d proxy = col.centres[2] + Vector3d(0, 0, 9);
  stage.update(at(proxy, 1), sh::RenderOutput{}, 1e-3, poses);  // pressed, no contact
  EXPECT_FALSE(stage.state().attached);
  stage.update(at(proxy, 1), touching(2, proxy), 1e-3, poses);  // held, not a new press
  EXPECT_FALSE(stage.state().attached);
  stage.update(at(proxy, 0), touching(2, proxy), 1e-3, poses);
  stage.update(at(proxy, 1), touching(2, proxy), 1e-3, poses);  // the press
  ASSERT_TRUE(stage.state().attached);
  EXPECT_EQ(stage.state().load.vertebra, 2);
  EXPECT_LT((stage.state().load.point_mm - proxy).norm(), 1e-12);  // poses were identity
  stage.update(at(proxy, 0), touching(2, proxy), 1e-3, poses);
  EXPECT_FALSE(stage.state().attached);
  EXPECT_EQ(stage.state().load.vertebra, -1);  // no ramp: released at once
}

TEST(CompliantStage, SpringLoadsTheSpineScaledAndTheHandFeelsItsReaction) {
  Column col;
  const double k_spine = 20;  // N/mm
  LinearSpine spine(k_spine);
  sh::CouplingParameters p;
  p.stiffness_n_per_mm = 0.2;
  p.force_scale = 50;
  p.ramp_s = 0.1;
  sh::CompliantStage stage(spine, col.centres, col.body_of, p);
  sh::ScenePoses poses;
  const Vector3d hook = col.centres[0] + Vector3d(0, 0, 5);
  stage.update(at(hook, 0), touching(0, hook), 1e-3, poses);
  stage.update(at(hook, 1), touching(0, hook), 1e-3, poses);
  // Pull 10 mm forward and hold: the gain ramps to 1 over 0.1 s, then the spring and the spine
  // settle where k_c·s·(probe − hook) = k_spine·(hook − hook0), hook − hook0 = d.
  const Vector3d pull = hook + Vector3d(0, 0, 10);
  double last_gain = 0;
  for (int k = 0; k < 400; ++k) {
    stage.update(at(pull, 1), sh::RenderOutput{}, 1e-3, poses);
    EXPECT_GE(stage.state().gain, last_gain);
    last_gain = stage.state().gain;
  }
  EXPECT_DOUBLE_EQ(stage.state().gain, 1.0);
  const double ks = p.stiffness_n_per_mm * p.force_scale;  // 10 N/mm on the spine
  const double d = ks * 10 / (ks + k_spine);               // series springs
  EXPECT_NEAR(stage.state().hook_mm.z() - hook.z(), d, 1e-6);
  EXPECT_NEAR(stage.state().load.force_n.z(), k_spine * d, 1e-4);
  EXPECT_LT((stage.state().felt_force_n + stage.state().load.force_n / p.force_scale).norm(),
            1e-12);
  // The vertebra below moved half as far (the linear spine's rule), through the poses.
  EXPECT_NEAR(poses.pose[1].apply(col.centres[1]).z() - col.centres[1].z(), d / 2, 1e-6);
  // With contact force c the hand feels the spring alone once hooked.
  EXPECT_LT((stage.blend(Vector3d(1, 2, 3)) - stage.state().felt_force_n).norm(), 1e-12);
  // Release: the gain ramps down to zero, the spine returns.
  for (int k = 0; k < 200; ++k) stage.update(at(pull, 0), sh::RenderOutput{}, 1e-3, poses);
  EXPECT_EQ(stage.state().gain, 0.0);
  EXPECT_LT((poses.pose[0].t).norm(), 1e-12);
}

TEST(CompliantStage, SpineForceIsClampedToWhatTheResponseAnswersFor) {
  Column col;
  LinearSpine spine(1e6, 100);  // rigid, 100 N at most
  sh::CouplingParameters p;
  p.ramp_s = 0;
  p.force_scale = 1000;
  sh::CompliantStage stage(spine, col.centres, col.body_of, p);
  sh::ScenePoses poses;
  const Vector3d hook = col.centres[5];
  stage.update(at(hook, 0), touching(5, hook), 1e-3, poses);
  stage.update(at(hook, 1), touching(5, hook), 1e-3, poses);
  stage.update(at(hook + Vector3d(30, 0, 0), 1), sh::RenderOutput{}, 1e-3, poses);
  EXPECT_TRUE(stage.state().clamped);
  EXPECT_NEAR(stage.state().load.force_n.norm(), 100, 1e-9);
  EXPECT_NEAR(stage.state().felt_force_n.norm(), 0.1, 1e-12);
}

TEST(CompliantStage, BadCouplingIsRefused) {
  Column col;
  LinearSpine spine(10);
  sh::CouplingParameters p;
  p.stiffness_n_per_mm = 0;
  EXPECT_THROW(sh::CompliantStage(spine, col.centres, col.body_of, p), std::invalid_argument);
  p = sh::CouplingParameters();
  p.force_scale = -1;
  EXPECT_THROW(sh::CompliantStage(spine, col.centres, col.body_of, p), std::invalid_argument);
  auto missing = col.body_of;
  missing[4] = -1;
  EXPECT_THROW(sh::CompliantStage(spine, col.centres, missing, sh::CouplingParameters()),
               std::invalid_argument);
}

TEST(CompliantStage, ClosedLoopDragMovesTheVertebraWithoutAllocating) {
  Column col;
  LinearSpine spine(20);
  const auto& caps = sh::device_model("touch");
  // The hand comes down onto T1's box from the front, presses the button, pulls forward 20 mm.
  const Vector3d c = col.centres[0];
  sh::Trajectory script;
  script.t_s = {0, 0.3, 0.4, 1.4, 2.0};
  script.position_mm = {c + Vector3d(0, 0, 20), c + Vector3d(0, 0, 7), c + Vector3d(0, 0, 7),
                        c + Vector3d(0, 0, 27), c + Vector3d(0, 0, 27)};
  script.buttons = {0, 0, 1, 1, 1};
  auto device = sh::make_sim_device(script, caps, 1e-3);
  device->open();
  sh::ProxyParameters pp;
  pp.radius_mm = 3;
  sh::SphereProxyRenderer proxy(pp);
  sh::TripleBuffer<sh::ScenePoses> poses{sh::ScenePoses{}};
  sh::ServoOptions so;
  so.duration_s = 3;
  sh::ServoLoop loop(*device, proxy, col.scene, poses, sh::SafetyOptions::for_device(caps), so);
  sh::CouplingParameters p;
  p.stiffness_n_per_mm = 0.2;
  p.force_scale = 100;
  sh::CompliantStage stage(spine, col.centres, col.body_of, p);
  loop.set_compliant_stage(&stage);
  loop.record_to([](const sh::TickRecord*, std::size_t) {}, 4096);
  long allocations = 0;
  {
    sh::testing::CountAllocations count;
    for (int k = 1; k <= 2000; ++k) {
      sh::ScenePoses fresh;
      fresh.time_s = k * 1e-3;
      poses.write(fresh);
      loop.tick(k * 1e-3, 1e-3);
    }
    allocations = count.allocations();
  }
  EXPECT_EQ(allocations, 0);
  const sh::HookState& h = stage.state();
  ASSERT_TRUE(h.attached);
  EXPECT_EQ(h.load.vertebra, 0);
  EXPECT_GT(h.hook_mm.z() - c.z(), 2.0);  // T1 came forward
  EXPECT_GT(h.load.force_n.z(), 40.0);    // pulled by the scaled spring
  EXPECT_LT(std::abs(h.load.force_n.x()), 1e-6 * h.load.force_n.norm() + 1e-9);
  EXPECT_GT(loop.passivity().minimum_mj(), -1.0);  // the coupling injected no energy
}

TEST(MultirateSpine, LocalModelReproducesItsSolveAndPredictsANearbyOne) {
  const sp::SpineModel m = sp::load_spine_model(SPINESIM_DATA_DIR);
  sh::MultirateOptions o;
  sh::MultirateSpine spine(m, o);
  sh::HookLoad load;
  load.vertebra = 0;
  load.point_mm = m.vertebrae[0].centre_mm + Vector3d(0, 5, -40);
  load.force_n = Vector3d(0, 0, 150);
  const sh::LocalSpineModel local = spine.solve(load);
  // Its solve, directly: the relative displacement is solve − gravity.
  sp::ExternalLoad l;
  l.vertebra = 0;
  l.force_n = load.force_n;
  l.has_point = true;
  l.point_mm = load.point_mm;
  const sp::SpineSolution direct = sp::solve_spine(m, {l}, o.solve);
  EXPECT_LT((local.relative - (direct.displacement - spine.baseline())).cwiseAbs().maxCoeff(),
            1e-9);
  // The worker publishes it; predict() at F0 returns it, at F0 + ΔF follows the sensitivity.
  spine.start();
  spine.publish(load);
  sh::SpineDisplacement d;
  for (int k = 0; k < 5000; ++k) {
    spine.predict(load, d);
    if (d.cwiseAbs().maxCoeff() > 0) break;
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  spine.stop();
  EXPECT_LT((d - local.relative).cwiseAbs().maxCoeff(), 1e-9);
  EXPECT_GE(spine.stats().solves, 1);
  EXPECT_GT(local.relative(0, 2), 1.0);  // T1 comes forward by millimetres under 150 N
}

namespace {

/// Largest tick-to-tick change of T1's predicted displacement while the force on T1 grows
/// steadily and the worker keeps publishing new local models (about 1.5 s of 1 ms ticks).
double largest_tick_jump_mm(const sp::SpineModel& m, int handover_ticks, int& models_seen) {
  sh::MultirateOptions o;
  o.handover_ticks = handover_ticks;
  sh::MultirateSpine spine(m, o);
  sh::HookLoad load;
  load.vertebra = 0;
  load.point_mm = m.vertebrae[0].centre_mm + Vector3d(0, 5, -40);
  spine.start();
  sh::SpineDisplacement d, last;
  double jump = 0;
  bool started = false;
  models_seen = 0;
  // 1.5 s, longer until the worker has handed over 8 models (a slow build), at most 4.5 s.
  for (int k = 0; k < 4500 && (k < 1500 || spine.model_in_use() < 8); ++k) {
    load.force_n = Vector3d(0.12 * k, 0, 0.05 * k);  // up to 540 N lateral, 225 N anterior
    spine.predict(load, d);
    if (started) jump = std::max(jump, (d.row(0).head<3>() - last.row(0).head<3>()).norm());
    started = started || d.cwiseAbs().maxCoeff() > 0;
    last = d;
    spine.publish(load);
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  spine.stop();
  models_seen = int(spine.stats().solves);
  return jump;
}

}  // namespace

// A new local model takes over gradually: without the handover the prediction steps by the
// previous model's error at each update; with it the steps shrink (by about the handover length
// when the updates are further apart than the handover).
TEST(MultirateSpine, NewLocalModelsAreBlendedInWithoutAStep) {
  const sp::SpineModel m = sp::load_spine_model(SPINESIM_DATA_DIR);
  int n0 = 0, n20 = 0;
  const double at_once = largest_tick_jump_mm(m, 0, n0);
  const double blended = largest_tick_jump_mm(m, 20, n20);
#if defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_THREAD__)
  // The sanitized builds solve 5-15 times slower; the worker's thread still ran beside the ticks.
  if (n0 < 5 || n20 < 5)
    GTEST_SKIP() << "the worker made " << n0 << " and " << n20
                 << " models in 4.5 s: too slow here to compare handovers";
#endif
  ASSERT_GE(n0, 5);  // the worker kept up (else there is nothing to compare)
  ASSERT_GE(n20, 5);
  // Steady growth alone moves T1 about S·ΔF ≈ 0.01-0.02 mm a tick; the updates add more.
  EXPECT_GT(at_once, 0.03);
  EXPECT_LT(blended, 0.5 * at_once) << "at once " << at_once << " mm, blended " << blended << " mm";
  RecordProperty("jump_at_once_um", int(1000 * at_once));
  RecordProperty("jump_blended_um", int(1000 * blended));
  EXPECT_THROW(
      {
        sh::MultirateOptions o;
        o.handover_ticks = -1;
        sh::MultirateSpine bad(m, o);
      },
      std::invalid_argument);
}

// With the rib cage attached, every update poses the ribs and the sternum from the thoracic
// vertebrae's poses exactly as spine::rib_cage_poses does, and still allocates nothing.
TEST(CompliantStage, TheRibCageFollowsTheThoraxWithoutAllocating) {
  Column col;
  sp::ModelOptions o;
  o.rib_cage = true;
  const sp::SpineModel m = sp::load_spine_model(SPINESIM_DATA_DIR, o);
  std::vector<int> ribs;
  for (std::size_t b = 0; b < m.rib_cage->body_centres_mm.size(); ++b) {
    ribs.push_back(col.scene.size());
    col.scene.add_body("rib" + std::to_string(b), spinesim::haptics::testing::box(
                                                      Vector3d(100, 600 - 10.0 * double(b), 0), 3));
  }
  LinearSpine spine(20);
  sh::CompliantStage stage(spine, col.centres, col.body_of, sh::CouplingParameters());
  EXPECT_THROW(stage.attach_rib_cage(*m.rib_cage, m.vertebrae, {1, 2}), std::invalid_argument);
  stage.attach_rib_cage(*m.rib_cage, m.vertebrae, ribs);
  sh::ScenePoses poses;
  const Vector3d c = col.centres[0];
  stage.update(at(c + Vector3d(0, 0, 7), 1), touching(0, c + Vector3d(0, 0, 5)), 1e-3, poses);
  ASSERT_TRUE(stage.state().attached);
  long allocations = 0;
  {
    sh::testing::CountAllocations count;
    for (int k = 1; k <= 300; ++k)
      stage.update(at(c + Vector3d(0, 0, 7 + 0.05 * k), 1), touching(0, c + Vector3d(0, 0, 5)),
                   1e-3, poses);
    allocations = count.allocations();
  }
  EXPECT_EQ(allocations, 0);
  std::vector<sp::Pose> P(m.vertebrae.size());
  for (int i = 0; i < sh::kSpineVertebrae; ++i)
    P[std::size_t(i)] = poses.pose[std::size_t(col.body_of[std::size_t(i)])];
  const auto expected = sp::rib_cage_poses(*m.rib_cage, m.vertebrae, P);
  for (std::size_t b = 0; b < ribs.size(); ++b) {
    EXPECT_LT((poses.pose[std::size_t(ribs[b])].R - expected[b].R).norm(), 1e-14) << b;
    EXPECT_LT((poses.pose[std::size_t(ribs[b])].t - expected[b].t).norm(), 1e-11) << b;
  }
  EXPECT_GT(poses.pose[std::size_t(ribs[0])].t.norm(), 0.01);  // the pulled thorax moved R1
}

// 6-DOF: the capability records (torque or none, the torsional Colgate–Brown limit); the safety
// chain's torque links one by one and under fuzzed wrenches (never above the peak torque, a
// non-finite torque zeroes the force too, a device without torque motors gets none); the
// simulated stylus follows the scripted turn and a held torque turns it by τ / k; trajectories
// read and refuse the rotation columns; the compliant stage's torsional spring meets the analytic
// equilibrium of a linear spine; a scripted twist through the servo loop turns the hooked
// vertebra, is felt as a torque opposing the turn, stays passive, allocates nothing, and its
// recording replays the turn; the multirate spine's moment sensitivity predicts a solve.
#include "allocation_counter.hpp"
#include "column_fixture.hpp"
#include "haptics_fixtures.hpp"
#include "spinesim/common/constants.hpp"
#include "spinesim/common/rotation.hpp"
#include "spinesim/haptics/compliant_stage.hpp"
#include "spinesim/haptics/recording.hpp"
#include "spinesim/haptics/servo.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <random>

namespace sh = spinesim::haptics;
namespace sp = spinesim::spine;
using Eigen::Matrix3d;
using Eigen::Vector3d;
using spinesim::kRadPerDeg;
using spinesim::rotation_exp;
using spinesim::rotation_log;
using spinesim::haptics::testing::at;
using spinesim::haptics::testing::Column;
using spinesim::haptics::testing::touching;

namespace {

/// A linear spine that takes moments: the hooked vertebra translates by F / k and turns by
/// M / k_turn (deg per N·mm), about its centre; the others do nothing.
class TwistableSpine final : public sh::SpineResponse {
 public:
  TwistableSpine(double k_n_per_mm, double k_nmm_per_deg, double max_moment = 15000)
      : k_(k_n_per_mm), k_turn_(k_nmm_per_deg), max_moment_(max_moment) {}
  const char* name() const override { return "twistable"; }
  void predict(const sh::HookLoad& load, sh::SpineDisplacement& d) override {
    d.setZero();
    if (load.vertebra < 0) return;
    d.row(load.vertebra).head<3>() = load.force_n.transpose() / k_;
    d.row(load.vertebra).tail<3>() = load.moment_nmm.transpose() / k_turn_;
  }
  const sh::SpineDisplacement& baseline() const override { return base_; }
  double max_force_n() const override { return 600; }
  double max_moment_nmm() const override { return max_moment_; }

 private:
  double k_, k_turn_, max_moment_;
  sh::SpineDisplacement base_ = sh::SpineDisplacement::Zero();
};

Matrix3d about_y(double deg) { return rotation_exp(Vector3d(0, deg * kRadPerDeg, 0)); }

}  // namespace

TEST(SixDof, ModelsRecordTheirTorqueOrNoneAndTheTorsionalLimit) {
  const auto& sigma = sh::device_model("sigma.7");
  EXPECT_TRUE(sigma.senses_orientation);
  EXPECT_TRUE(sigma.renders_torque());
  EXPECT_GE(sigma.peak_torque_nmm, sigma.continuous_torque_nmm);
  const auto& premium = sh::device_model("premium-1.5-6dof");
  EXPECT_TRUE(premium.renders_torque());
  EXPECT_EQ(premium.peak_torque_nmm, 170);  // the weakest axis (Rz) for all three
  const auto& omega6 = sh::device_model("omega.6");
  EXPECT_TRUE(omega6.senses_orientation);
  EXPECT_FALSE(omega6.renders_torque());
  EXPECT_FALSE(sh::device_model("touch").senses_orientation);
  // Colgate–Brown for the torsion: 2 b_r / T, and nothing for a device without torque.
  EXPECT_NEAR(sh::passive_rotational_stiffness_limit(sigma, 1e-3),
              2 * sigma.rotational_damping_nmm_s_per_rad / 1e-3, 1e-9);
  EXPECT_EQ(sh::passive_rotational_stiffness_limit(omega6, 1e-3), 0.0);
  for (const auto& m : sh::device_models())
    if (m.renders_torque())
      EXPECT_LT(m.usable_rotational_stiffness_nmm_per_rad,
                sh::passive_rotational_stiffness_limit(m, 1e-3))
          << m.model;
}

TEST(SixDof, SafetyChainClampsLimitsRampsAndFadesTheTorque) {
  sh::SafetyOptions o = sh::SafetyOptions::for_device(sh::device_model("sigma.7"));
  ASSERT_GT(o.peak_torque_nmm, 0);
  o.start_ramp_s = 0;
  o.continuous_window_s = 1e6;  // the continuous limiter out of the way
  sh::SafetyChain chain(o);
  sh::SafetyReport r;
  // Clamp, keeping the direction.
  const Vector3d big(3000, -4000, 0);
  sh::Wrench w = chain.apply(sh::Wrench{Vector3d(0, 1, 0), big}, {}, &r);
  EXPECT_TRUE(r.torque_clamped);
  EXPECT_NEAR(w.torque_nmm.norm(), o.peak_torque_nmm, 1e-9);
  EXPECT_NEAR(w.torque_nmm.normalized().dot(big.normalized()), 1.0, 1e-12);
  EXPECT_NEAR(w.force_n.y(), 1.0, 1e-12);  // the force is untouched
  // A non-finite torque zeroes both.
  w = chain.apply(sh::Wrench{Vector3d(0, 1, 0), Vector3d(std::nan(""), 0, 0)}, {}, &r);
  EXPECT_TRUE(r.non_finite);
  EXPECT_EQ(w.force_n, Vector3d::Zero());
  EXPECT_EQ(w.torque_nmm, Vector3d::Zero());
  // Continuous: a sustained demand above the rating is held at it.
  sh::SafetyOptions c = sh::SafetyOptions::for_device(sh::device_model("premium-1.5-6dof"));
  c.start_ramp_s = 0;
  sh::SafetyChain sustained(c);
  double last = 0;
  for (int i = 0; i < 20000; ++i)
    last = sustained.apply(sh::Wrench{Vector3d::Zero(), Vector3d(0, 150, 0)}, {}).torque_nmm.norm();
  EXPECT_NEAR(last, c.continuous_torque_nmm, 0.5);
  EXPECT_NEAR(sustained.rms_torque_nmm(), 150, 0.5);
  // The start ramp and the watchdog act on the torque as on the force.
  sh::SafetyOptions ramped = sh::SafetyOptions::for_device(sh::device_model("sigma.7"));
  sh::SafetyChain start(ramped);
  EXPECT_NEAR(start.apply(sh::Wrench{Vector3d::Zero(), Vector3d(0, 0, 100)}, {}).torque_nmm.norm(),
              100 * 0.001 / ramped.start_ramp_s, 1e-9);
  sh::SafetyTick late;
  late.period_s = 0.005;
  double out = 1;
  for (int i = 0; i < 10; ++i)
    out = chain.apply(sh::Wrench{Vector3d::Zero(), Vector3d(0, 0, 100)}, late).torque_nmm.norm();
  EXPECT_EQ(out, 0.0);
  // A device without torque motors gets none, whatever is asked.
  sh::SafetyChain none(sh::SafetyOptions::for_device(sh::device_model("omega.6")));
  EXPECT_EQ(none.apply(sh::Wrench{Vector3d::Zero(), Vector3d(50, 0, 0)}, {}).torque_nmm,
            Vector3d::Zero());
  // Bad ratings are refused.
  sh::SafetyOptions bad;
  bad.peak_torque_nmm = 10;  // with no continuous rating
  EXPECT_THROW(sh::SafetyChain{bad}, std::invalid_argument);
  bad.continuous_torque_nmm = 20;  // above the peak
  EXPECT_THROW(sh::SafetyChain{bad}, std::invalid_argument);
}

TEST(SixDof, FuzzedWrenchesNeverExceedThePeakTorque) {
  for (const char* model : {"sigma.7", "premium-1.5-6dof", "omega.6"}) {
    const auto& caps = sh::device_model(model);
    sh::SafetyChain chain(sh::SafetyOptions::for_device(caps));
    std::mt19937 rng(7);
    std::normal_distribution<double> big(0, 5000);
    std::uniform_real_distribution<double> u(0, 1);
    double largest = 0;
    for (int tick = 0; tick < 20000; ++tick) {
      sh::Wrench demand{Vector3d(big(rng), big(rng), big(rng)) / 100,
                        Vector3d(big(rng), big(rng), big(rng))};
      if (u(rng) < 0.01) demand.torque_nmm.z() = std::numeric_limits<double>::infinity();
      sh::SafetyTick t;
      t.period_s = u(rng) < 0.02 ? 0.004 : 0.001;
      t.scene_age_s = u(rng) < 0.01 ? 1.0 : 0.0;
      const sh::Wrench w = chain.apply(demand, t);
      ASSERT_TRUE(w.force_n.allFinite() && w.torque_nmm.allFinite());
      ASSERT_LE(w.force_n.norm(), caps.peak_force_n * (1 + 1e-12));
      ASSERT_LE(w.torque_nmm.norm(), caps.peak_torque_nmm * (1 + 1e-12));
      largest = std::max(largest, w.torque_nmm.norm());
    }
    if (caps.renders_torque())
      EXPECT_GT(largest, 0.5 * caps.continuous_torque_nmm) << model;
    else
      EXPECT_EQ(largest, 0.0) << model;
  }
}

TEST(SixDof, SimStylusFollowsTheScriptedTurnAndAHeldTorqueTurnsItByTauOverK) {
  const auto& caps = sh::device_model("sigma.7");
  sh::Trajectory script;
  script.t_s = {0, 0.5, 3};
  script.position_mm = {Vector3d::Zero(), Vector3d::Zero(), Vector3d::Zero()};
  script.buttons = {0, 0, 0};
  script.rotation_deg = {Vector3d::Zero(), Vector3d(0, 30, 0), Vector3d(0, 30, 0)};
  EXPECT_NEAR(rotation_log(script.orientation_at(0.25)).y() / kRadPerDeg, 15, 1e-9);
  EXPECT_NEAR(script.angular_velocity_at(0.25).y(), 30 * kRadPerDeg / 0.5, 1e-9);
  const sh::HandModel hand;
  auto device = sh::make_sim_device(script, caps, 1e-3, hand);
  device->open();
  sh::DeviceState s;
  for (int k = 0; k < 1500; ++k) device->read(s);
  // Settled on the script's turn.
  EXPECT_NEAR(rotation_log(s.orientation).y() / kRadPerDeg, 30, 0.05);
  EXPECT_LT(s.angular_velocity_rad_s.norm(), 0.01);
  EXPECT_LT((s.orientation * s.orientation.transpose() - Matrix3d::Identity()).norm(), 1e-12);
  // A held torque turns it back by τ / k_grip (the wrist's spring balances it).
  const Vector3d torque(0, -100, 0);
  for (int k = 0; k < 1500; ++k) {
    device->write_wrench(Vector3d::Zero(), torque);
    device->read(s);
  }
  EXPECT_NEAR(rotation_log(s.orientation).y(),
              30 * kRadPerDeg + torque.y() / hand.rotational_stiffness_nmm_per_rad, 1e-4);
  // A force-only command holds no torque; a device without torque motors ignores it.
  device->write_force(Vector3d::Zero());
  for (int k = 0; k < 1500; ++k) device->read(s);
  EXPECT_NEAR(rotation_log(s.orientation).y() / kRadPerDeg, 30, 0.05);
  auto omega6 = sh::make_sim_device(script, sh::device_model("omega.6"), 1e-3, hand);
  omega6->open();
  for (int k = 0; k < 1500; ++k) {
    omega6->write_wrench(Vector3d::Zero(), torque);
    omega6->read(s);
  }
  EXPECT_NEAR(rotation_log(s.orientation).y() / kRadPerDeg, 30, 0.05);
  // A 3-DOF device keeps the identity.
  auto touch = sh::make_sim_device(script, sh::device_model("touch"), 1e-3, hand);
  touch->open();
  touch->read(s);
  EXPECT_EQ(s.orientation, Matrix3d::Identity());
}

TEST(SixDof, TrajectoriesReadTheRotationColumnsAndRefuseBadOnes) {
  const auto dir = std::filesystem::temp_directory_path() / "spinesim_six_dof";
  std::filesystem::create_directories(dir);
  const auto write = [&](const std::string& name, const std::string& text) {
    const std::string path = (dir / name).string();
    std::ofstream(path) << text;
    return path;
  };
  const sh::Trajectory t = sh::read_trajectory(
      write("twist.csv",
            "t_s,x_mm,y_mm,z_mm,button,fx_n,rx_deg,ry_deg,rz_deg\n0,1,2,3,0,9,0,0,0\n"
            "1,1,2,3,1,9,0,40,0\n"));
  ASSERT_TRUE(t.has_orientation());
  EXPECT_NEAR(rotation_log(t.orientation_at(0.5)).y() / kRadPerDeg, 20, 1e-9);
  EXPECT_EQ(t.position_at(0.5), Vector3d(1, 2, 3));
  EXPECT_FALSE(
      sh::read_trajectory(write("plain.csv", "t_s,x_mm,y_mm,z_mm\n0,0,0,0\n")).has_orientation());
  EXPECT_THROW(sh::read_trajectory(write("short.csv",
                                         "t_s,x_mm,y_mm,z_mm,button,rx_deg,ry_deg,"
                                         "rz_deg\n0,0,0,0,0,1,2\n")),
               std::invalid_argument);
  EXPECT_THROW(sh::read_trajectory(write("far.csv",
                                         "t_s,x_mm,y_mm,z_mm,button,rx_deg,ry_deg,"
                                         "rz_deg\n0,0,0,0,0,0,190,0\n")),
               std::invalid_argument);
  EXPECT_THROW(sh::read_trajectory(write("nan.csv",
                                         "t_s,x_mm,y_mm,z_mm,button,rx_deg,ry_deg,"
                                         "rz_deg\n0,0,0,0,0,0,nan,0\n")),
               std::invalid_argument);
  std::filesystem::remove_all(dir);
}

TEST(SixDof, TorsionalSpringMeetsTheAnalyticEquilibriumOfALinearSpine) {
  // Hooked at T1's centre (so the turn moves no hook point), the stylus turned θ about y: the
  // vertebra turns ψ = M / k_t and M = s k_r (θ − ψ), so M = s k_r θ / (1 + s k_r / k_t), and the
  // hand feels −M / s.
  Column col;
  const double k_turn_deg = 200;  // N·mm per degree
  TwistableSpine spine(50, k_turn_deg);
  sh::CouplingParameters p;
  p.ramp_s = 0;
  p.force_scale = 30;
  p.rotational_stiffness_nmm_per_rad = 300;
  sh::CompliantStage stage(spine, col.centres, col.body_of, p);
  ASSERT_TRUE(stage.twists());
  sh::ScenePoses poses;
  const Vector3d c = col.centres[0];
  const Matrix3d grip = about_y(-10);  // any orientation at the press: only the turn counts
  stage.update(at(c, 0, grip), touching(0, c), 1e-3, poses);
  stage.update(at(c, 1, grip), touching(0, c), 1e-3, poses);
  const double theta = 25 * kRadPerDeg;
  for (int k = 0; k < 3; ++k)
    stage.update(at(c, 1, about_y(25) * grip), sh::RenderOutput{}, 1e-3, poses);
  const double sk = p.force_scale * p.rotational_stiffness_nmm_per_rad;
  const double k_t = k_turn_deg / kRadPerDeg;  // N·mm/rad
  const double M = sk * theta / (1 + sk / k_t);
  const sh::HookState& h = stage.state();
  EXPECT_NEAR(h.load.moment_nmm.y(), M, 1e-3 * M);
  EXPECT_LT(h.load.moment_nmm.cwiseAbs()(0) + h.load.moment_nmm.cwiseAbs()(2), 1e-6 * M);
  EXPECT_NEAR(h.felt_torque_nmm.y(), -M / p.force_scale, 1e-3 * M / p.force_scale);
  EXPECT_NEAR(h.twist_deg.y(), (theta - M / k_t) / kRadPerDeg, 1e-3);
  EXPECT_NEAR(stage.torque().y(), h.felt_torque_nmm.y(), 1e-12);
  // The vertebra turned by ψ in the scene.
  EXPECT_NEAR(rotation_log(poses.pose[0].R).y(), M / k_t, 1e-6);
  // Released: no moment, no torque.
  stage.update(at(c, 0, about_y(25) * grip), sh::RenderOutput{}, 1e-3, poses);
  EXPECT_EQ(stage.state().felt_torque_nmm, Vector3d::Zero());
  // The moment is clamped to what the response answers for.
  TwistableSpine weak(50, 1e6, 500);  // rigid in turning, 500 N·mm at most
  sh::CompliantStage clamped(weak, col.centres, col.body_of, p);
  clamped.update(at(c, 0), touching(0, c), 1e-3, poses);
  clamped.update(at(c, 1), touching(0, c), 1e-3, poses);
  clamped.update(at(c, 1, about_y(25)), sh::RenderOutput{}, 1e-3, poses);
  EXPECT_TRUE(clamped.state().clamped);
  EXPECT_NEAR(clamped.state().load.moment_nmm.norm(), 500, 1e-6);
  // Without rotational stiffness, or with a response that knows no moments, nothing twists.
  sh::CouplingParameters flat = p;
  flat.rotational_stiffness_nmm_per_rad = 0;
  EXPECT_FALSE(sh::CompliantStage(spine, col.centres, col.body_of, flat).twists());
  TwistableSpine forces_only(50, k_turn_deg, 0);
  EXPECT_FALSE(sh::CompliantStage(forces_only, col.centres, col.body_of, p).twists());
  sh::CouplingParameters negative = p;
  negative.rotational_stiffness_nmm_per_rad = -1;
  EXPECT_THROW(sh::CompliantStage(spine, col.centres, col.body_of, negative),
               std::invalid_argument);
}

namespace {

/// A sigma.7 in the simulated hand comes to T1's box, presses, turns the stylus 30° about the
/// spine's axis, holds, turns back and lets go.
sh::Trajectory twist_script(const Vector3d& c) {
  sh::Trajectory script;
  script.t_s = {0, 0.3, 0.4, 0.6, 1.6, 2.2, 3.2, 3.4};
  const Vector3d away = c + Vector3d(0, 0, 20), touch = c + Vector3d(0, 0, 7);
  script.position_mm = {away, touch, touch, touch, touch, touch, touch, touch};
  script.buttons = {0, 0, 1, 1, 1, 1, 1, 0};
  script.rotation_deg = {Vector3d::Zero(), Vector3d::Zero(),   Vector3d::Zero(),
                         Vector3d::Zero(), Vector3d(0, 30, 0), Vector3d(0, 30, 0),
                         Vector3d::Zero(), Vector3d::Zero()};
  return script;
}

struct TwistRig {
  Column col;
  TwistableSpine spine{50, 200};
  const sh::DeviceCapabilities& caps = sh::device_model("sigma.7");
  std::unique_ptr<sh::Device> device;
  sh::SphereProxyRenderer proxy{[] {
    sh::ProxyParameters pp;
    pp.radius_mm = 3;
    return pp;
  }()};
  sh::TripleBuffer<sh::ScenePoses> poses{sh::ScenePoses{}};
  std::unique_ptr<sh::ServoLoop> loop;
  std::unique_ptr<sh::CompliantStage> stage;
  TwistRig() {
    device = sh::make_sim_device(twist_script(col.centres[0]), caps, 1e-3);
    device->open();
    sh::ServoOptions so;
    so.duration_s = 3.6;
    so.realtime_priority = false;
    loop = std::make_unique<sh::ServoLoop>(*device, proxy, col.scene, poses,
                                           sh::SafetyOptions::for_device(caps), so);
    sh::CouplingParameters p;
    p.stiffness_n_per_mm = 0.5;
    p.force_scale = 30;
    p.rotational_stiffness_nmm_per_rad = caps.usable_rotational_stiffness_nmm_per_rad;
    stage = std::make_unique<sh::CompliantStage>(spine, col.centres, col.body_of, p);
    loop->set_compliant_stage(stage.get());
  }
};

}  // namespace

TEST(SixDof, ScriptedTwistIsFeltOpposingTheTurnPassiveAndWithoutAllocating) {
  TwistRig rig;
  long allocations = 0;
  double most_turned_deg = 0, torque_at_most = 0, largest_torque = 0;
  for (int k = 1; k <= 3800; ++k) {  // the release's 0.3 s ramp ends at 3.7 s
    sh::ScenePoses fresh;
    fresh.time_s = k * 1e-3;
    rig.poses.write(fresh);
    {
      sh::testing::CountAllocations count;
      rig.loop->tick(k * 1e-3, 1e-3);
      allocations += count.allocations();
    }
    const sh::ServoStatus& st = rig.loop->status().read();
    largest_torque = std::max(largest_torque, st.torque_nmm.norm());
    const double turned = rotation_log(st.poses.pose[0].R).y() / kRadPerDeg;
    if (turned > most_turned_deg) most_turned_deg = turned, torque_at_most = st.torque_nmm.y();
  }
  EXPECT_EQ(allocations, 0);
  // T1 followed the turn (by less than the stylus: the spine resists) and the hand felt it.
  EXPECT_GT(most_turned_deg, 5.0);
  EXPECT_LT(most_turned_deg, 30.0);
  EXPECT_LT(torque_at_most, -10.0);  // opposing the +y turn
  EXPECT_LE(largest_torque, rig.caps.peak_torque_nmm * (1 + 1e-12));
  EXPECT_GT(rig.loop->stats().max_spine_moment_nmm, 1000.0);
  EXPECT_GT(rig.loop->passivity().minimum_mj(), -1.0);  // the torsional coupling injected none
  // After the release nothing is held.
  EXPECT_EQ(rig.stage->state().felt_torque_nmm, Vector3d::Zero());
  EXPECT_EQ(rig.loop->status().read().torque_nmm, Vector3d::Zero());
}

TEST(SixDof, ARecordedTwistReplaysTheTurn) {
  // The loop on its thread, recording: the file's rotation columns replay the stylus's turn.
  TwistRig rig;
  const std::string path =
      (std::filesystem::temp_directory_path() / "spinesim_six_dof_twist.csv").string();
  sh::HapticRecordingWriter writer(path, "test", nullptr, "", false, true);
  rig.loop->record_to([&](const sh::TickRecord* rows, std::size_t n) { writer.append(rows, n); },
                      8192);
  const sh::ServoStats st = rig.loop->run([&](const sh::ServoStatus&, double now) {
    sh::ScenePoses fresh;
    fresh.time_s = now;
    rig.poses.write(fresh);
  });
  writer.finish();
  EXPECT_FALSE(st.error) << st.stop_reason;
  EXPECT_GT(st.max_torque_nmm, 10.0);
  const sh::Trajectory replay = sh::read_trajectory(path);
  ASSERT_TRUE(replay.has_orientation());
  double replayed_most = 0;
  for (const auto& r : replay.rotation_deg) replayed_most = std::max(replayed_most, r.y());
  EXPECT_GT(replayed_most, 25.0);  // the stylus got to about the script's 30°
  EXPECT_LT(replayed_most, 31.0);
  auto replayer = sh::make_replay_device(replay, rig.caps, 1e-3);
  replayer->open();
  sh::DeviceState s;
  for (int k = 0; k < 1900; ++k) replayer->read(s);  // 1.9 s: the turn is held
  EXPECT_NEAR(rotation_log(s.orientation).y() / kRadPerDeg, replayed_most, 2.0);
  std::filesystem::remove(path);
}

TEST(MultirateSpine, MomentSensitivityPredictsANearbySolve) {
  const sp::SpineModel m = sp::load_spine_model(SPINESIM_DATA_DIR);
  sh::MultirateOptions o;
  sh::MultirateSpine spine(m, o);
  sh::HookLoad load;
  load.vertebra = 0;
  load.point_mm = m.vertebrae[0].centre_mm + Vector3d(0, 5, -40);
  load.force_n = Vector3d(0, 0, 50);
  load.moment_nmm = Vector3d(0, 2000, 0);
  load.twist = true;
  const sh::LocalSpineModel local = spine.solve(load, nullptr, true);
  EXPECT_GT(local.sensitivity.col(4).cwiseAbs().maxCoeff(), 0);  // ∂d/∂M_y was differenced
  // A solve 1 N·m further on: the linear prediction is closer to it than the model's own point.
  sp::ExternalLoad l;
  l.vertebra = 0;
  l.force_n = load.force_n;
  l.moment_nmm = load.moment_nmm + Vector3d(0, 1000, 0);
  l.has_point = true;
  l.point_mm = load.point_mm;
  const sp::SpineSolution direct = sp::solve_spine(m, {l}, o.solve);
  const sh::SpineDisplacement truth = direct.displacement - spine.baseline();
  sh::SpineDisplacement predicted = local.relative;
  for (int i = 0; i < sh::kSpineVertebrae; ++i)
    for (int c = 0; c < 6; ++c) predicted(i, c) += local.sensitivity(6 * i + c, 4) * 1000;
  const double change = (truth - local.relative).cwiseAbs().maxCoeff();
  const double error = (truth - predicted).cwiseAbs().maxCoeff();
  EXPECT_GT(truth(0, 4) - local.relative(0, 4), 0.1);  // T1 turns further about y (deg)
  EXPECT_LT(error, 0.2 * change) << "change " << change << ", error " << error;
  RecordProperty("change_milli", int(1000 * change));
  RecordProperty("error_milli", int(1000 * error));
}

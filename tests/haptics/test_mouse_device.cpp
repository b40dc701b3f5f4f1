// The `mouse` device: the simulated hand follows the pointer's set-point at the speed limit (a
// cursor jump is a glide), settles on it, balances a held force where the hand's spring says
// (x = set-point + F / k), holds a non-finite set-point, passes the buttons, and finishes when
// the window closes.
#include "spinesim/haptics/device.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

namespace sh = spinesim::haptics;

namespace {

struct Rig {
  sh::TripleBuffer<sh::PointerInput> input;
  std::unique_ptr<sh::Device> device;
  const double T = 1e-3, speed = 250;
  sh::HandModel hand;
  explicit Rig(const Eigen::Vector3d& start) {
    device = sh::make_mouse_device(input, start, sh::device_model("touch"), T, speed, hand);
    device->open();
  }
  sh::DeviceState run(int ticks) {
    sh::DeviceState s;
    for (int i = 0; i < ticks; ++i) EXPECT_TRUE(device->read(s));
    return s;
  }
  void point(const Eigen::Vector3d& p, unsigned buttons = 0, bool quit = false) {
    input.write({p, buttons, true, quit});
  }
};

}  // namespace

TEST(MouseDevice, AJumpOfTheCursorIsAGlideAtTheSpeedLimitThatSettlesOnIt) {
  Rig rig(Eigen::Vector3d(10, 20, 30));
  const Eigen::Vector3d target(110, 20, 30);  // 100 mm away
  rig.point(target);
  // The set-point needs 100 / 250 = 0.4 s; the hand lags it. Never ahead of the glide by more
  // than the hand's overshoot allows, and nowhere near the target after 0.1 s.
  double most = 0;
  for (int i = 1; i <= 100; ++i) {
    const auto s = rig.run(1);
    most = std::max(most, s.position_mm.x() - 10);
    EXPECT_LT(s.position_mm.x() - 10, rig.speed * i * rig.T + 2.0) << i;
  }
  EXPECT_LT(most, 30);
  const auto s = rig.run(3000);  // 3 s: settled (the hand's own damping)
  EXPECT_NEAR((s.position_mm - target).norm(), 0, 0.05);
  EXPECT_NEAR(s.velocity_mm_s.norm(), 0, 0.5);
}

TEST(MouseDevice, AHeldForceIsBalancedByTheHandsSpring) {
  Rig rig(Eigen::Vector3d::Zero());
  const Eigen::Vector3d f(0.4, -0.2, 0.1);  // N, within the Touch's continuous 0.88 N
  rig.device->write_force(f);
  const auto s = rig.run(5000);
  // Static equilibrium: k (set - x) + F = 0 (the damping terms vanish at rest).
  const Eigen::Vector3d expected = f / rig.hand.stiffness_n_per_mm;
  EXPECT_NEAR((s.position_mm - expected).norm(), 0, 1e-3) << s.position_mm.transpose();
}

// A set-point far behind a wall: the hand pushes with the device's continuous force at most, so
// a wall holding that force stops the stylus.
TEST(MouseDevice, TheHandPushesWithAtMostTheContinuousForce) {
  Rig rig(Eigen::Vector3d::Zero());
  rig.point(Eigen::Vector3d(0, 0, -200));
  const double most = sh::device_model("touch").continuous_force_n;
  sh::DeviceState s;
  double deepest = 0;
  for (int i = 0; i < 4000; ++i) {
    rig.device->read(s);
    // A wall at z = -10 mm, 2 N/mm (penalty), clamped at the device's peak force.
    const double pen = std::max(0.0, -10 - s.position_mm.z());
    rig.device->write_force(Eigen::Vector3d(0, 0, std::min(2 * pen, 3.3)));
    deepest = std::max(deepest, pen);
  }
  EXPECT_NEAR(std::max(0.0, -10 - s.position_mm.z()), most / 2, 0.02);  // at rest: 2 pen = most
  // On the way in the stylus arrives at up to about the glide speed: the wall also takes its
  // kinetic energy, pen <= F/k + v sqrt(m/k) (+30 % for the hand's own overshoot of the glide).
  // Without the limit the grip spring pushed it 180 mm through.
  const double m = 0.15, k = 2000, v = 0.25;  // kg, N/m, m/s
  EXPECT_LT(deepest, most / 2 + 1.3 * 1e3 * v * std::sqrt(m / k));
}

TEST(MouseDevice, NonFiniteSetPointIsHeldButtonsPassAndQuitFinishes) {
  Rig rig(Eigen::Vector3d(1, 2, 3));
  // Before the pointer has given a set-point (the input's default: inactive, at the origin) the
  // hand holds the start.
  EXPECT_NEAR((rig.run(200).position_mm - Eigen::Vector3d(1, 2, 3)).norm(), 0, 1e-9);
  rig.point(Eigen::Vector3d(std::nan(""), 0, 0), 1);
  const auto s = rig.run(500);
  EXPECT_TRUE(s.position_mm.allFinite());
  EXPECT_NEAR((s.position_mm - Eigen::Vector3d(1, 2, 3)).norm(), 0, 1e-9);
  EXPECT_EQ(s.buttons, 1u);
  EXPECT_FALSE(rig.device->finished());
  rig.point(Eigen::Vector3d(1, 2, 3), 0, true);
  rig.run(1);
  EXPECT_TRUE(rig.device->finished());
  EXPECT_THROW(
      sh::make_mouse_device(rig.input, Eigen::Vector3d::Zero(), sh::device_model("touch"), 1e-3, 0),
      std::invalid_argument);
}

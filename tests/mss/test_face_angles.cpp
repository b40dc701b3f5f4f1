// The face kernel of the angle springs (mss/src/face_angles.hpp) against the reference
// element angle_spring (elements.hpp), and its small-angle atan2 against std::atan2.
#include "face_angles.hpp"

#include "spinesim/mss/elements.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

namespace spinesim::mss {
namespace {

TEST(FaceAngles, SmallAngleAtan2MatchesStdAtan2OnBothBranches) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  double worst = 0.0;
  for (int i = 0; i < 20000; ++i) {
    const double x = u(rng), y = (i % 2 ? 0.12 : 2.0) * u(rng);  // half near the series range
    const double ref = std::atan2(y, x);
    worst = std::max(worst, std::abs(small_angle_atan2(y, x) - ref));
  }
  EXPECT_LT(worst, 4e-16);
  // Right at the switch-over point the two branches agree.
  EXPECT_NEAR(small_angle_atan2(0.0999999999, 1.0), std::atan2(0.0999999999, 1.0), 2e-17);
  EXPECT_NEAR(small_angle_atan2(0.1, 1.0), std::atan2(0.1, 1.0), 2e-17);
}

// Energy and gradient equal the sum of three angle_spring calls (one per corner).
TEST(FaceAngles, EqualsThreeAngleSpringsAtRandomDeformations) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (int trial = 0; trial < 200; ++trial) {
    Eigen::Vector3d X[3], x[3];
    for (auto& p : X) p = Eigen::Vector3d(u(rng), u(rng), u(rng)) * 2.0;
    const double amplitude = trial < 100 ? 0.05 : 0.6;  // series branch, then atan2 branch
    for (int c = 0; c < 3; ++c) x[c] = X[c] + amplitude * Eigen::Vector3d(u(rng), u(rng), u(rng));
    FaceRest rest;
    double rest_rad[3];
    for (int c = 0; c < 3; ++c) {
      rest_rad[c] = angle_at(X[c], X[(c + 1) % 3], X[(c + 2) % 3]);
      rest.cos0[c] = std::cos(rest_rad[c]);
      rest.sin0[c] = std::sin(rest_rad[c]);
    }
    const double k = 3.7;
    double g[3][3] = {{0, 0, 0}, {0, 0, 0}, {0, 0, 0}};
    const double e =
        face_angle_springs<true>(x[0].data(), x[1].data(), x[2].data(), k, rest, g[0], g[1], g[2]);
    EXPECT_DOUBLE_EQ(e, face_angle_springs<false>(x[0].data(), x[1].data(), x[2].data(), k, rest,
                                                  nullptr, nullptr, nullptr));
    double e_ref = 0.0;
    Eigen::Vector3d g_ref[3] = {Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero(),
                                Eigen::Vector3d::Zero()};
    for (int c = 0; c < 3; ++c) {
      const int n[3] = {c, (c + 1) % 3, (c + 2) % 3};
      Vector9d gc;
      e_ref += angle_spring(x[n[0]], x[n[1]], x[n[2]], k, rest_rad[c], &gc);
      for (int a = 0; a < 3; ++a) g_ref[n[a]] += gc.segment<3>(3 * a);
    }
    const double scale = std::max({g_ref[0].norm(), g_ref[1].norm(), g_ref[2].norm()});
    EXPECT_NEAR(e, e_ref, 1e-12 * std::max(e_ref, 1e-12));
    for (int c = 0; c < 3; ++c)
      EXPECT_LT((Eigen::Map<Eigen::Vector3d>(g[c]) - g_ref[c]).norm(), 1e-11 * scale) << trial;
  }
}

TEST(FaceAngles, RestFaceHasZeroEnergyAndForce) {
  const Eigen::Vector3d a(0, 0, 0), b(2, 0, 0), c(0.5, 1.5, 0.2);
  FaceRest rest;
  const Eigen::Vector3d p[3] = {a, b, c};
  for (int k = 0; k < 3; ++k) {
    const double t = angle_at(p[k], p[(k + 1) % 3], p[(k + 2) % 3]);
    rest.cos0[k] = std::cos(t), rest.sin0[k] = std::sin(t);
  }
  double g[3][3] = {{0, 0, 0}, {0, 0, 0}, {0, 0, 0}};
  EXPECT_NEAR(face_angle_springs<true>(a.data(), b.data(), c.data(), 1.0, rest, g[0], g[1], g[2]),
              0.0, 1e-30);
  for (auto& gi : g)
    for (double v : gi) EXPECT_NEAR(v, 0.0, 1e-14);
}

}  // namespace
}  // namespace spinesim::mss

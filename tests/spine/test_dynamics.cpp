// The spine's natural modes: the mass matrix is the point masses' kinetic energy (a rigid turn
// of the whole trunk about the pelvis has the inertia Σ m r² summed here directly), the
// eigen-solver returns an analytic two-mass chain's frequencies, and the spine's modes scale as
// 1/√mass when every mass is doubled.
#include "spinesim/spine/dynamics.hpp"
#include "spinesim/spine/kinematics.hpp"

#include <gtest/gtest.h>

#include <cmath>

namespace sp = spinesim::spine;

namespace {
const std::string kData = SPINESIM_DATA_DIR;
}

TEST(SpineDynamics, TheMassMatrixIsThePointMassesKineticEnergy) {
  sp::ModelOptions o;
  o.muscles = o.iap = false;
  for (int j = 0; j + 1 < 17; ++j) o.fused_joints.push_back(j);  // only L5-S1 turns
  const sp::SpineModel m = sp::load_spine_model(kData, o);
  const Eigen::VectorXd theta = Eigen::VectorXd::Zero(sp::dof_count(m));
  const Eigen::MatrixXd M = sp::mass_matrix(m, theta);
  // A small flexion of L5-S1 at unit rate: each mass's velocity from its own displacement.
  Eigen::VectorXd turn = Eigen::VectorXd::Zero(sp::dof_count(m));
  turn[3 * 16] = 1;  // flexion of L5-S1
  const double h = 1e-5;
  const std::vector<sp::Pose> p = sp::vertebra_poses(m, h * turn);
  double two_t = 0;  // Σ m |v|² for a unit rate, by the masses' own displacements
  for (const sp::PointLoad& w : m.weights) {
    const double mass = w.force_n.norm() / 9.81;
    const Eigen::Vector3d v = (sp::place(p, w.body, w.point_mm) - w.point_mm) / h;
    two_t += mass * v.squaredNorm();
  }
  EXPECT_NEAR(turn.dot(M * turn), two_t, 1e-4 * two_t);
  EXPECT_GT(two_t, 1e6);  // tens of kg at hundreds of mm
  EXPECT_LE((M - M.transpose()).cwiseAbs().maxCoeff(), 1e-9 * M.cwiseAbs().maxCoeff());
  sp::ModelOptions weightless = o;
  weightless.gravity = false;
  EXPECT_THROW(sp::mass_matrix(sp::load_spine_model(kData, weightless), theta),
               std::invalid_argument);
}

// Two masses m on a chain of two springs k (wall–k–m–k–m): ω² = (3 ∓ √5)/2 · k/m.
TEST(SpineDynamics, TheEigenSolverGivesATwoMassChainsFrequencies) {
  const double k = 2000, m = 3;  // N·mm, kg·mm²
  Eigen::MatrixXd K(3, 3), M = Eigen::MatrixXd::Zero(3, 3);
  K << 2 * k, -k, 0, -k, k, 0, 0, 0, 1;
  M(0, 0) = M(1, 1) = m;
  const sp::NaturalModes modes = sp::natural_modes(K, M, {0, 1}, 2);
  for (int i = 0; i < 2; ++i) {
    const double lambda = (3 + (i == 0 ? -1 : 1) * std::sqrt(5.0)) / 2 * k / m;
    EXPECT_NEAR(modes.frequency_hz[i], std::sqrt(1000 * lambda) / (2 * M_PI), 1e-9);
    const Eigen::VectorXd phi = modes.shape.col(i);
    EXPECT_NEAR(phi.dot(M * phi), 1, 1e-9);
  }
  Eigen::MatrixXd unstable = K;
  unstable(1, 1) = -k;
  EXPECT_THROW(sp::natural_modes(unstable, M, {0, 1}, 2), std::invalid_argument);
  EXPECT_NEAR(sp::ramp_overshoot_bound(2, 0.5), 1 / (M_PI), 1e-12);
  EXPECT_EQ(sp::ramp_overshoot_bound(2, 0.01), 1.0);  // a step at most doubles the static answer
  // The bound is the envelope of the exact undamped overshoot |sin x| / x, x = π T_r f1.
  for (double tr : {0.05, 0.3, 0.77, 2.0, 9.0}) {
    const double x = M_PI * tr * 2;
    EXPECT_GE(sp::ramp_overshoot_bound(2, tr), std::abs(std::sin(x)) / x - 1e-15);
  }
}

TEST(SpineDynamics, StandingModesScaleAsOneOverTheRootOfTheMass) {
  const sp::SpineModel m = sp::load_spine_model(kData);
  const sp::SpineSolution s = sp::solve_spine(m, {});
  const sp::NaturalModes modes = sp::spine_natural_modes(m, {}, s, 4);
  ASSERT_EQ(modes.frequency_hz.size(), 4);
  EXPECT_GT(modes.frequency_hz[0], 0.1);
  EXPECT_LT(modes.frequency_hz[0], 100);
  for (int i = 1; i < 4; ++i) EXPECT_GE(modes.frequency_hz[i], modes.frequency_hz[i - 1]);
  std::vector<int> free;
  for (int c = 0; c < sp::dof_count(m); ++c) free.push_back(c);
  const Eigen::MatrixXd K = sp::stiffness_matrix(m, {}, s.recruitment.force_n, s.theta);
  const Eigen::MatrixXd M = sp::mass_matrix(m, s.theta);
  const sp::NaturalModes heavy = sp::natural_modes(K, 2 * M, free, 4);
  for (int i = 0; i < 4; ++i)
    EXPECT_NEAR(heavy.frequency_hz[i], modes.frequency_hz[i] / std::sqrt(2.0),
                1e-9 * modes.frequency_hz[i]);
  std::printf("standing modes (Hz): %.3f %.3f %.3f %.3f, mass %.1f kg\n", modes.frequency_hz[0],
              modes.frequency_hz[1], modes.frequency_hz[2], modes.frequency_hz[3], modes.mass_kg);
}

// Private pieces of the nonlinear solvers (fem/src/): the rigid plate's kinematics inside the
// nonlinear disc's Newton — ∂(R(θ) a)/∂θ against central differences, at rest and at large
// rotations — and the line search shared by the Newton solvers (newton_steps.hpp).
#include "newton_steps.hpp"
#include "plate_newton.hpp"

#include "spinesim/common/rotation.hpp"

#include <gtest/gtest.h>

namespace spinesim::fem::detail {
namespace {

TEST(PlateKinematics, RotatedArmJacobianIsTheDerivativeOfTheRotation) {
  const Eigen::Vector3d arm(12.0, -3.0, 7.5);
  for (const Eigen::Vector3d theta :
       {Eigen::Vector3d::Zero().eval(), Eigen::Vector3d(0.01, -0.02, 0.005),
        Eigen::Vector3d(0.3, 0.9, -0.4), Eigen::Vector3d(0, 2.5, 0)}) {
    const Eigen::Matrix3d J = rotated_arm_jacobian(theta, arm);
    const double h = 1e-6;
    for (int d = 0; d < 3; ++d) {
      Eigen::Vector3d tp = theta, tm = theta;
      tp(d) += h, tm(d) -= h;
      const Eigen::Vector3d fd = (rotation_exp(tp) * arm - rotation_exp(tm) * arm) / (2 * h);
      EXPECT_LE((fd - J.col(d)).norm(), 1e-8 * arm.norm()) << "theta " << theta.transpose();
    }
  }
  // R(θ) is the rotation by |θ| about θ: it keeps the axis and turns the arm by |θ|.
  const Eigen::Vector3d axis_turn(0, 0.5, 0);
  EXPECT_LE((rotation_exp(axis_turn) * Eigen::Vector3d::UnitY() - Eigen::Vector3d::UnitY()).norm(),
            1e-15);
  EXPECT_NEAR((rotation_exp(axis_turn) * Eigen::Vector3d::UnitX()).dot(Eigen::Vector3d::UnitX()),
              std::cos(0.5), 1e-15);
}

// Far from a solution the potential decides (Armijo); a step that raises the potential measurably
// is refused even though the residual falls; near a solution, where the predicted decrease is
// below the potential's rounding, a step that lowers the residual is taken.
TEST(LineSearch, ThePotentialDecidesUnlessItsRoundingSwampsTheSlope) {
  // Π(α) = α² − α, r(α) = |2α − 1|: α = 1 gives no decrease, α = ½ is the minimum.
  const auto parabola = [](double a) { return TrialPoint{a * a - a, std::abs(2 * a - 1)}; };
  EXPECT_EQ(backtrack({0.0, 1.0}, -1.0, 1.0, parabola), 0.5);
  // The residual falls along the step but Π is 1e-3 of its size higher: refused at every α.
  const auto uphill = [](double a) { return TrialPoint{1.0 + 1e-3, 1.0 - 0.5 * a}; };
  EXPECT_EQ(backtrack({1.0, 1.0}, -1e-20, 1.0, uphill), 0.0);
  // A slope of 1e-20 on a potential of size 1 whose evaluations carry rounding of 1e-13: Armijo
  // cannot hold at α = 1 (Π comes out 1e-13 high), the residual falls a thousandfold, taken.
  const auto noisy = [](double a) { return TrialPoint{1.0 + 1e-13, 1e-3 * (1 - a) + 1e-12}; };
  EXPECT_EQ(backtrack({1.0, 1e-3}, -1e-20, 1.0, noisy), 1.0);
  // Inadmissible trial states (an inverted element: non-finite Π) are stepped over.
  const auto inverted_beyond_half = [](double a) {
    return TrialPoint{a > 0.5 ? std::nan("") : -a, 1 - a};
  };
  EXPECT_EQ(backtrack({0.0, 1.0}, -1.0, 1.0, inverted_beyond_half), 0.5);
}

// The convergence test: both the correction and the residual within tolerance, or — once the
// correction is at rounding — the residual within its rounding floor, a thousand times that.
TEST(IncrementConverged, NeedsASmallCorrectionAndAResidualAtTolerance) {
  const double tol = 1e-10;
  EXPECT_TRUE(increment_converged(0.5e-10, 0.5, 1e-11, 1e-3, tol));  // both within
  EXPECT_FALSE(increment_converged(2e-10, 0.5, 1e-11, 1e-3, tol));   // residual above, step not
                                                                     // at rounding
  EXPECT_TRUE(increment_converged(2e-10, 0.5, 1e-14, 1e-3, tol));    // residual at its floor
  EXPECT_FALSE(increment_converged(2e-7, 0.5, 1e-14, 1e-3, tol));    // far above the floor
  EXPECT_FALSE(increment_converged(1e-12, 0.5, 2e-10, 1e-3, tol));   // correction too large
  EXPECT_TRUE(increment_converged(5e-8, 1000.0, 1e-9, 50.0, tol));   // scales with f and u
}

// The ramp: a failing increment is halved, the counts kept, and after too many halvings in a row
// the failure names where the ramp stopped.
TEST(LoadRamp, FailingIncrementsAreHalvedAndAStuckRampSaysWhere) {
  NewtonOptions o;
  o.load_increments = 2, o.max_cutbacks = 3;
  HyperelasticSolution sol;
  std::vector<double> tried;
  // Steps longer than 0.3 of the load fail.
  double at = 0;
  const std::string ok = ramp(o, sol, "the test load", [&](double to) {
    tried.push_back(to);
    if (to - at > 0.3) return false;
    at = to;
    return true;
  });
  EXPECT_EQ(ok, "");
  EXPECT_DOUBLE_EQ(at, 1.0);
  EXPECT_EQ(sol.cutbacks, 1);  // 0.5 failed, then steps of 0.25
  EXPECT_EQ(sol.increments, 4);
  EXPECT_DOUBLE_EQ(tried.front(), 0.5);

  HyperelasticSolution stuck;
  const std::string why = ramp(o, stuck, "the test load", [](double) { return false; });
  EXPECT_NE(why.find("from 0.000000 to 0.062500 of the test load after 3 halvings"),
            std::string::npos)
      << why;
  EXPECT_EQ(stuck.cutbacks, 3);
}

}  // namespace
}  // namespace spinesim::fem::detail

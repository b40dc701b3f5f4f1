// Identification from measured windows (window_fit.hpp): the residual's scale, recovery of known
// parameters from windows the model itself makes, active bounds, leave-one-out on a consistent
// model, threads, a model that fails in part of the space, and bad input.
#include "spinesim/calibration/window_fit.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <stdexcept>

namespace spinesim::calibration {
namespace {

// Three parameters, four power-law quantities (like stiffnesses of a disc in its moduli).
Eigen::VectorXd power_model(const Eigen::VectorXd& p) {
  Eigen::VectorXd q(4);
  q << 2.0 * p(0) * std::sqrt(p(1)), 0.5 * p(0) * p(2), p(1) * p(1) / p(2), 3.0 * p(0);
  return q;
}

std::vector<FitParameter> three_parameters(double start = 1.0) {
  return {{"a", "MPa", start, 0.1, 10.0}, {"b", "", start, 0.1, 10.0}, {"c", "", start, 0.1, 10.0}};
}

// Windows of ±20 % around the model's values at `truth` (geometric centre = the value).
std::vector<WindowTarget> windows_around(const Eigen::VectorXd& truth) {
  const Eigen::VectorXd q = power_model(truth);
  std::vector<WindowTarget> t;
  for (Eigen::Index i = 0; i < q.size(); ++i)
    t.push_back({"q" + std::to_string(i), q(i) / 1.2, q(i) * 1.2});
  return t;
}

TEST(WindowResidual, IsMinusOneZeroAndOneAtTheWindowsLowCentreAndHigh) {
  const WindowTarget t{"x", 2.0, 8.0};
  EXPECT_NEAR(window_residual(2.0, t), -1.0, 1e-15);
  EXPECT_NEAR(window_residual(4.0, t), 0.0, 1e-15);
  EXPECT_NEAR(window_residual(8.0, t), 1.0, 1e-15);
  EXPECT_NEAR(window_residual(16.0, t), 2.0, 1e-14);  // a half-width is a factor 2 here
  EXPECT_TRUE(std::isnan(window_residual(0.0, t)));
  EXPECT_TRUE(std::isnan(window_residual(std::numeric_limits<double>::quiet_NaN(), t)));
}

TEST(WindowFit, RecoversTheParametersWhoseValuesCentreTheWindows) {
  Eigen::VectorXd truth(3);
  truth << 2.5, 0.4, 3.0;
  const WindowFit fit = fit_to_windows(power_model, three_parameters(), windows_around(truth),
                                       {true, true, true, true});
  ASSERT_TRUE(fit.success) << fit.status;
  for (int j = 0; j < 3; ++j) EXPECT_NEAR(fit.parameters(j) / truth(j), 1.0, 1e-5) << j;
  EXPECT_LT(fit.objective, 1e-10);
  EXPECT_TRUE(fit.active_bounds.empty());
  EXPECT_LT(fit.iterations, 30);  // Gauss–Newton on a problem that is linear in ln p
}

TEST(WindowFit, StopsAtAPublishedBoundAndSaysSo) {
  Eigen::VectorXd truth(3);
  truth << 20.0, 0.4, 3.0;  // a beyond its upper bound 10
  const WindowFit fit = fit_to_windows(power_model, three_parameters(), windows_around(truth),
                                       {true, true, true, true});
  ASSERT_TRUE(fit.success) << fit.status;
  EXPECT_NEAR(fit.parameters(0), 10.0, 1e-3);
  ASSERT_EQ(fit.active_bounds.size(), 1u);
  EXPECT_NE(fit.active_bounds[0].find("a at upper bound (10 MPa)"), std::string::npos)
      << fit.active_bounds[0];
  EXPECT_GT(fit.objective, 0.1);  // the windows cannot all be met
}

// Residuals whose best fit leaves ½|r|² = 1 (ln a is asked to be 1 and -1), plus a deterministic
// noise of 1e-7 that changes with every bit of p — what a static solve's tolerance does to a
// forward-difference Jacobian (its noise is ~1e-7 / 1e-3 = 1e-4 in the gradient).
Eigen::VectorXd noisy_inconsistent_model(const Eigen::VectorXd& p) {
  Eigen::VectorXd r(3);
  r << std::log(p(0)) - 1.0, std::log(p(0)) + 1.0, std::log(p(1)) - 0.5;
  for (Eigen::Index i = 0; i < r.size(); ++i)
    r(i) += 1e-7 * std::sin(1e9 * p(0) + 3e8 * p(1) + static_cast<double>(i));
  return r;
}

TEST(LeastSquaresFit, StopsOnceTheObjectiveStallsUnderNoise) {
  const std::vector<FitParameter> parameters = {{"a", "", 3.0, 0.01, 100.0},
                                                {"b", "", 3.0, 0.01, 100.0}};
  WindowFitOptions strict;  // Ipopt's own rules only (acceptable: 15 iterations at 1e-5)
  strict.ipopt.max_iterations = 60;
  WindowFitOptions stall = strict;
  stall.ipopt.stall_iterations = 3;
  stall.ipopt.stall_change = 1e-6;
  const LeastSquaresFit a = fit_least_squares(noisy_inconsistent_model, parameters, strict);
  const LeastSquaresFit b = fit_least_squares(noisy_inconsistent_model, parameters, stall);
  ASSERT_TRUE(b.success) << b.status;
  EXPECT_EQ(b.status, "Objective_Stalled");
  EXPECT_NEAR(b.objective, 1.0, 1e-6);
  EXPECT_NEAR(std::log(b.parameters(0)), 0.0, 1e-3);
  EXPECT_NEAR(std::log(b.parameters(1)), 0.5, 1e-3);
  // Without the stall rule the noise keeps Ipopt from both of its levels to the iteration limit.
  EXPECT_LT(b.iterations, a.iterations) << a.status;
  EXPECT_LE(b.iterations, 15);
}

TEST(WindowFit, RefusesBadIpoptStoppingRules) {
  Eigen::VectorXd truth(3);
  truth << 2.5, 0.4, 3.0;
  WindowFitOptions o;
  o.ipopt.acceptable_iterations = -1;
  EXPECT_THROW(fit_to_windows(power_model, three_parameters(), windows_around(truth),
                              {true, true, true, true}, o),
               std::invalid_argument);
  o = WindowFitOptions();
  o.ipopt.stall_change = 0;
  EXPECT_THROW(fit_to_windows(power_model, three_parameters(), windows_around(truth),
                              {true, true, true, true}, o),
               std::invalid_argument);
}

TEST(WindowFit, TwoThreadsGiveTheSameFitToTheLastBit) {
  Eigen::VectorXd truth(3);
  truth << 2.5, 0.4, 3.0;
  WindowFitOptions two;
  two.threads = 2;
  const auto t = windows_around(truth);
  const WindowFit a = fit_to_windows(power_model, three_parameters(), t, {true, true, true, true});
  const WindowFit b =
      fit_to_windows(power_model, three_parameters(), t, {true, true, true, true}, two);
  EXPECT_EQ(a.parameters, b.parameters);
  EXPECT_EQ(a.iterations, b.iterations);
}

TEST(WindowFit, StepsAroundWhereTheModelGivesNoValue) {
  Eigen::VectorXd truth(3);
  truth << 2.5, 0.4, 3.0;
  // No value for a > 4 (a load case that does not converge there); the truth lies below.
  const QuantityModel partial = [](const Eigen::VectorXd& p) -> Eigen::VectorXd {
    if (p(0) > 4.0) return Eigen::VectorXd::Constant(4, std::numeric_limits<double>::quiet_NaN());
    return power_model(p);
  };
  auto params = three_parameters(3.9);
  const WindowFit fit =
      fit_to_windows(partial, params, windows_around(truth), {true, true, true, true});
  ASSERT_TRUE(fit.success) << fit.status;
  EXPECT_NEAR(fit.parameters(0) / truth(0), 1.0, 1e-5);
}

TEST(WindowFit, StepsAroundAModelThatThrowsThereEvenOnTwoThreads) {
  Eigen::VectorXd truth(3);
  truth << 2.5, 0.4, 3.0;
  // A solver that throws (no convergence) for a > 4, inside a worker thread.
  const QuantityModel throwing = [](const Eigen::VectorXd& p) -> Eigen::VectorXd {
    if (p(0) > 4.0) throw std::runtime_error("did not converge");
    return power_model(p);
  };
  WindowFitOptions two;
  two.threads = 2;
  const WindowFit fit = fit_to_windows(throwing, three_parameters(3.9), windows_around(truth),
                                       {true, true, true, true}, two);
  ASSERT_TRUE(fit.success) << fit.status;
  EXPECT_NEAR(fit.parameters(0) / truth(0), 1.0, 1e-5);
}

TEST(LeaveOneOut, OnAConsistentModelEachLeftOutQuantityIsPredictedWhereItWasMeasured) {
  Eigen::VectorXd truth(3);
  truth << 2.5, 0.4, 3.0;
  const auto targets = windows_around(truth);
  const std::vector<WindowFit> loo =
      leave_one_out(power_model, three_parameters(), targets, {true, true, true, true});
  ASSERT_EQ(loo.size(), 4u);
  // q3 = 3a alone fixes a; without q3, q0 and q1 and q2 still fix (a, b, c): three equations,
  // three unknowns. Every left-out quantity is then predicted exactly.
  for (int i = 0; i < 4; ++i) {
    ASSERT_TRUE(loo[size_t(i)].success) << i;
    EXPECT_NEAR(loo[size_t(i)].residuals(i), 0.0, 1e-4) << i;
  }
}

TEST(LeaveOneOut, SkipsTargetsNotInUse) {
  Eigen::VectorXd truth(3);
  truth << 2.5, 0.4, 3.0;
  const std::vector<WindowFit> loo = leave_one_out(
      power_model, three_parameters(), windows_around(truth), {true, true, true, false});
  EXPECT_FALSE(loo[3].success);
  EXPECT_EQ(loo[3].parameters.size(), 0);
  EXPECT_TRUE(loo[0].success);
}

TEST(WindowFit, RefusesAnEmptyDataSetBadWindowsAndStartsOutsideTheBounds) {
  Eigen::VectorXd truth(3);
  truth << 2.5, 0.4, 3.0;
  const auto t = windows_around(truth);
  EXPECT_THROW(fit_to_windows(power_model, three_parameters(), t, {false, false, false, false}),
               std::invalid_argument);
  EXPECT_THROW(fit_to_windows(power_model, three_parameters(), t, {true, true}),
               std::invalid_argument);
  auto inverted = t;
  inverted[1] = {"q1", 3.0, 2.0};
  EXPECT_THROW(fit_to_windows(power_model, three_parameters(), inverted, {true, true, true, true}),
               std::invalid_argument);
  EXPECT_THROW(fit_to_windows(power_model, three_parameters(20.0), t, {true, true, true, true}),
               std::invalid_argument);
  auto zero_bound = three_parameters();
  zero_bound[2].lower = 0.0;
  EXPECT_THROW(fit_to_windows(power_model, zero_bound, t, {true, true, true, true}),
               std::invalid_argument);
}

}  // namespace
}  // namespace spinesim::calibration

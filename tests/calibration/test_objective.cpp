// The calibration objective's adjoint gradient against finite differences, and Ipopt recovering
// known scales from a synthetic reference.
#include "spinesim/calibration/calibrate.hpp"
#include "spinesim/calibration/objective.hpp"

#include "calibration_fixtures.hpp"

#include <gtest/gtest.h>

#include <cstdio>

namespace spinesim::calibration {
namespace {

using fixtures::all_terms;
using fixtures::two_materials;
using fixtures::two_region_disc;

struct Problem {
  mesh::TetMesh mesh = two_region_disc();
  mss::MssModel model{mesh, two_materials(), all_terms()};
  Eigen::Vector3d center = mss::default_plate_center(mesh);
  LinearMss lin{model, available_knobs(model.options()), center};
};

Eigen::VectorXd true_scales() {
  Eigen::VectorXd s(9);
  s << 1.7, 0.6, 0.45, 2.2, 1.3, 0.8, 3.0, 0.5, 0.35;
  return s;
}

const std::vector<std::string> kTrain = {"compression", "shear-ap", "flexion", "torsion"};

TEST(Objective, AdjointGradientMatchesFiniteDifferences) {
  Problem p;
  Objective obj(p.lin, fixtures::synthetic_reference(p.lin, p.mesh, true_scales(), p.center),
                kTrain);
  Eigen::VectorXd x(9);
  x << 0.1, -0.2, 0.3, 0.05, -0.4, 0.25, -0.1, 0.2, 0.15;
  const Evaluation ev = obj.evaluate(x, true);
  ASSERT_GT(ev.value, 1e-3);
  ASSERT_GT(ev.displacement, 0.0);
  ASSERT_GT(ev.reaction, 0.0);
  ASSERT_GT(ev.stiffness, 0.0);
  for (Eigen::Index j = 0; j < x.size(); ++j) {
    const double h = 1e-5;
    Eigen::VectorXd xp = x, xm = x;
    xp(j) += h, xm(j) -= h;
    const double fd = (obj.evaluate(xp, false).value - obj.evaluate(xm, false).value) / (2 * h);
    EXPECT_NEAR(ev.gradient(j), fd, 1e-6 * ev.gradient.cwiseAbs().maxCoeff() + 1e-9)
        << knob_name(p.lin.knobs()[std::size_t(j)]);
  }
}

// Each part of J has its own correct derivative: check them one by one with weights switched.
TEST(Objective, EveryPartOfTheGradientIsExact) {
  Problem p;
  const FemReference ref = fixtures::synthetic_reference(p.lin, p.mesh, true_scales(), p.center);
  Eigen::VectorXd x = Eigen::VectorXd::Constant(9, 0.2);
  for (int part = 0; part < 3; ++part) {
    Weights w;
    w.reaction = part == 1 ? 1.0 : 0.0;
    w.stiffness = part == 2 ? 1.0 : 0.0;
    w.regularisation = 0.0;
    Objective obj(p.lin, ref, kTrain, w);
    const Evaluation ev = obj.evaluate(x, true);
    for (Eigen::Index j = 0; j < x.size(); j += 2) {
      Eigen::VectorXd xp = x, xm = x;
      xp(j) += 1e-5, xm(j) -= 1e-5;
      const double fd = (obj.evaluate(xp, false).value - obj.evaluate(xm, false).value) / 2e-5;
      EXPECT_NEAR(ev.gradient(j), fd, 1e-6 * ev.gradient.cwiseAbs().maxCoeff() + 1e-12)
          << "part " << part;
    }
  }
}

TEST(Objective, ZeroAtTheTrueScalesAndPositiveElsewhere) {
  Problem p;
  Weights w;
  w.regularisation = 0.0;
  Objective obj(p.lin, fixtures::synthetic_reference(p.lin, p.mesh, true_scales(), p.center),
                kTrain, w);
  const Evaluation at_truth = obj.evaluate(true_scales().array().log(), true);
  EXPECT_LT(at_truth.value, 1e-20);
  EXPECT_LT(at_truth.gradient.norm(), 1e-9);
  ASSERT_EQ(at_truth.cases.size(), 8u);
  for (const CaseError& c : at_truth.cases) EXPECT_LT(c.displacement_error, 1e-10) << c.name;
  EXPECT_GT(obj.evaluate(Eigen::VectorXd::Zero(9), false).value, 1e-3);
}

// Where the residuals vanish the Gauss–Newton matrix is the exact Hessian: compare it with
// central differences of the adjoint gradient there.
TEST(Objective, GaussNewtonIsTheHessianAtZeroResidual) {
  Problem p;
  Objective obj(p.lin, fixtures::synthetic_reference(p.lin, p.mesh, true_scales(), p.center),
                kTrain);
  const Eigen::VectorXd x = true_scales().array().log();
  const Evaluation ev = obj.evaluate(x, true, true);
  ASSERT_EQ(ev.gauss_newton.rows(), 9);
  EXPECT_LT((ev.gauss_newton - ev.gauss_newton.transpose()).norm(), 1e-12 * ev.gauss_newton.norm());
  for (Eigen::Index j = 0; j < x.size(); ++j) {
    Eigen::VectorXd xp = x, xm = x;
    xp(j) += 1e-5, xm(j) -= 1e-5;
    const Eigen::VectorXd fd =
        (obj.evaluate(xp, true).gradient - obj.evaluate(xm, true).gradient) / 2e-5;
    EXPECT_LT((fd - ev.gauss_newton.col(j)).norm(), 1e-6 * ev.gauss_newton.norm())
        << knob_name(p.lin.knobs()[std::size_t(j)]);
  }
}

// Ipopt from Van Gelder (all scales 1) back to the scales that made the reference.
TEST(Calibrate, IpoptRecoversTheScalesOfASyntheticReference) {
  Problem p;
  Weights w;
  w.regularisation = 0.0;
  Objective obj(p.lin, fixtures::synthetic_reference(p.lin, p.mesh, true_scales(), p.center),
                kTrain, w);
  int calls = 0;
  const CalibrationResult r = calibrate(obj, Eigen::VectorXd::Zero(9), IpoptSettings(),
                                        [&](int, double, double) { ++calls; });
  EXPECT_TRUE(r.success) << r.status;
  std::printf("Ipopt: %s after %d iterations, %d evaluations, J %.3g -> %.3g\n", r.status.c_str(),
              r.iterations, r.evaluations, r.start.value, r.final.value);
  EXPECT_GT(calls, 1);
  EXPECT_GT(r.start.value, 1e-2);
  EXPECT_LT(r.final.value, 1e-12);
  for (const CaseError& c : r.final.cases)
    EXPECT_LT(c.displacement_error, 1e-5) << c.name;  // held-out ones too
  const Eigen::VectorXd s = r.log_scales.array().exp();
  for (Eigen::Index j = 0; j < s.size(); ++j)
    EXPECT_NEAR(s(j), true_scales()(j), 1e-3 * true_scales()(j))
        << knob_name(p.lin.knobs()[std::size_t(j)]);
}

TEST(Calibrate, FailuresAreReportedNotHidden) {
  Problem p;
  Objective obj(p.lin, fixtures::synthetic_reference(p.lin, p.mesh, true_scales(), p.center),
                kTrain);
  IpoptSettings bad;
  bad.lower_scale = 2.0, bad.upper_scale = 0.5;
  try {
    calibrate(obj, Eigen::VectorXd::Zero(9), bad);
    FAIL() << "infeasible bounds accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("infeasible bounds"), std::string::npos) << e.what();
  }
  IpoptSettings short_run;
  short_run.max_iterations = 2;
  const CalibrationResult r = calibrate(obj, Eigen::VectorXd::Zero(9), short_run);
  EXPECT_FALSE(r.success);
  EXPECT_EQ(r.status, "Maximum_Iterations_Exceeded");
  EXPECT_THROW(Objective(p.lin, obj.reference(), {"no-such-case"}), std::invalid_argument);
  EXPECT_THROW(Objective(p.lin, obj.reference(), {}), std::invalid_argument);
}

}  // namespace
}  // namespace spinesim::calibration

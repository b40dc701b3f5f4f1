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

namespace {

/// Only L5-S1 turns; passive (no muscles, no IAP), under gravity: a three-coordinate pendulum on a
/// spring, and its equilibrium.
struct OneJoint {
  sp::SpineModel m;
  sp::SpineSolution eq;
  std::vector<int> free;
};

OneJoint one_joint() {
  sp::ModelOptions o;
  o.muscles = o.iap = false;
  for (int j = 0; j + 1 < 17; ++j) o.fused_joints.push_back(j);
  OneJoint p{sp::load_spine_model(kData, o), {}, {48, 49, 50}};
  sp::SolveOptions so;
  so.recruit = false;
  p.eq = sp::solve_spine(p.m, {}, so);
  return p;
}

}  // namespace

// Released from a small displacement along its first mode, the pendulum swings with the period
// the eigen-solver gives (Newmark's period error at 100 steps a period is (ωh)²/12 = 0.3 %), and
// the average-acceleration rule keeps its amplitude (no numerical damping).
TEST(SpineDynamics, AFreeSwingHasTheModesPeriodAndKeepsItsAmplitude) {
  const OneJoint p = one_joint();
  const sp::NaturalModes modes = sp::spine_natural_modes(p.m, {}, p.eq, 1);
  const double f1 = modes.frequency_hz[0], T = 1 / f1;
  const Eigen::VectorXd phi = modes.shape.col(0);
  const double eps = 1e-3 / phi.cwiseAbs().maxCoeff();  // 1 mrad at the largest coordinate
  sp::DynamicsOptions o;
  o.dt_s = T / 100;
  const auto run = sp::integrate_spine(
      p.m,
      [](double, std::vector<sp::ExternalLoad>& l, Eigen::VectorXd& F) {
        l.clear();
        F.resize(0);
      },
      p.eq.theta + eps * phi, 0, 3.2 * T, o);
  const Eigen::MatrixXd M = sp::mass_matrix(p.m, p.eq.theta);
  std::vector<double> q, crossings;
  for (const auto& s : run) q.push_back(phi.dot(M * (s.theta - p.eq.theta)) / eps);
  for (std::size_t k = 1; k < q.size(); ++k)
    if (q[k - 1] > 0 && q[k] <= 0)  // downward crossings, interpolated
      crossings.push_back(run[k - 1].t_s + o.dt_s * q[k - 1] / (q[k - 1] - q[k]));
  ASSERT_GE(crossings.size(), 3u);
  const double period = (crossings.back() - crossings.front()) / double(crossings.size() - 1);
  EXPECT_NEAR(period, T, 0.01 * T) << "f1 " << f1 << " Hz";
  double last = 0;
  for (std::size_t k = q.size() * 2 / 3; k < q.size(); ++k) last = std::max(last, std::abs(q[k]));
  EXPECT_NEAR(last, 1.0, 0.03);  // q starts at φᵀMφ = 1
}

// A load applied suddenly and held. This joint sits near its extension limit under gravity, where
// the range-of-motion bump stiffens it, so the undamped peak is not the linear 2× static; the
// oracle is an independent integration of the same one-coordinate motion (by symmetry torsion
// and lateral bending stay zero) with classical Runge–Kutta at ten times finer steps. With
// damping the motion settles on the static equilibrium.
TEST(SpineDynamics, ASuddenLoadMatchesAnIndependentIntegrationAndDampingSettlesIt) {
  const OneJoint p = one_joint();
  sp::ExternalLoad push;
  push.vertebra = sp::vertebra_index("T1");
  push.force_n = Eigen::Vector3d(0, 0, 2);
  sp::SolveOptions so;
  so.recruit = false;
  const sp::SpineSolution pushed = sp::solve_spine(p.m, {push}, so);
  const double stat = pushed.theta[48] - p.eq.theta[48];
  ASSERT_GT(std::abs(stat), 1e-4);
  const double T = 1 / sp::spine_natural_modes(p.m, {}, p.eq, 1).frequency_hz[0];
  const auto loads = [&](double, std::vector<sp::ExternalLoad>& l, Eigen::VectorXd& F) {
    l = {push};
    F.resize(0);
  };
  sp::DynamicsOptions o;
  o.dt_s = T / 200;
  double peak = 0;
  for (const auto& s : sp::integrate_spine(p.m, loads, p.eq.theta, 0, 1.5 * T, o)) {
    peak = std::max(peak, (s.theta[48] - p.eq.theta[48]) / stat);
    EXPECT_LE(std::abs(s.theta[49] - p.eq.theta[49]) + std::abs(s.theta[50] - p.eq.theta[50]),
              1e-12);
  }
  // θ̈ = −∂Π/∂θ / M (M in N·mm s²: kg·mm² × 1e-3), Runge–Kutta 4 at T/2000.
  const auto accel = [&](double th) {
    Eigen::VectorXd q = p.eq.theta, g;
    q[48] = th;
    sp::potential(p.m, {push}, Eigen::VectorXd(), q, &g);
    return -g[48] / (1e-3 * sp::mass_matrix(p.m, q)(48, 48));
  };
  double th = p.eq.theta[48], v = 0, rk_peak = 0;
  const double h = T / 2000;
  for (int k = 0; k < 3000; ++k) {
    const double k1v = accel(th), k1x = v;
    const double k2v = accel(th + 0.5 * h * k1x), k2x = v + 0.5 * h * k1v;
    const double k3v = accel(th + 0.5 * h * k2x), k3x = v + 0.5 * h * k2v;
    const double k4v = accel(th + h * k3x), k4x = v + h * k3v;
    th += h / 6 * (k1x + 2 * k2x + 2 * k3x + k4x);
    v += h / 6 * (k1v + 2 * k2v + 2 * k3v + k4v);
    rk_peak = std::max(rk_peak, (th - p.eq.theta[48]) / stat);
  }
  EXPECT_NEAR(peak, rk_peak, 0.01 * rk_peak);
  EXPECT_GT(peak, 1.5);  // a sudden load overshoots its static answer
  o.damping_ratio = 0.5;
  const auto damped = sp::integrate_spine(p.m, loads, p.eq.theta, 0, 8 * T, o);
  EXPECT_NEAR((damped.back().theta[48] - p.eq.theta[48]) / stat, 1.0, 0.02);
  o.dt_s = 0.2;
  EXPECT_THROW(sp::integrate_spine(p.m, loads, p.eq.theta, 0, 1, o), std::invalid_argument);
}

// spine_state at a solved posture is the solve's own report: the same joint reactions.
TEST(SpineDynamics, TheStateAtASolvedPostureIsTheSolvesReport) {
  const sp::SpineModel m = sp::load_spine_model(kData);
  sp::ExternalLoad push;
  push.vertebra = sp::vertebra_index("T7");
  push.force_n = Eigen::Vector3d(0, 0, 100);
  const sp::SpineSolution s = sp::solve_spine(m, {push});
  const sp::SpineSolution state = sp::spine_state(m, {push}, s.recruitment.force_n, s.theta);
  ASSERT_EQ(state.joints.size(), s.joints.size());
  for (std::size_t k = 0; k < s.joints.size(); ++k)
    EXPECT_LE((state.joints[k].force_world_n - s.joints[k].force_world_n).norm(), 1e-9)
        << s.joints[k].joint;
  EXPECT_LE((state.displacement - s.displacement).cwiseAbs().maxCoeff(), 1e-12);
  EXPECT_THROW(sp::spine_state(m, {push}, s.recruitment.force_n, Eigen::VectorXd::Zero(3)),
               std::invalid_argument);
}

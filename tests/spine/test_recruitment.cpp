// Muscle recruitment at its optimum, checked from outside the optimiser: the criterion's gradient
// is derived here from its definition (recruitment.hpp: Σ a^p over muscles, a = F/F_max, and joint
// axes, a = |r|/R, R = k·ROM), and the solution must satisfy the KKT conditions of
//   min f(F, r)  s.t.  A F + r = b,  0 ≤ F ≤ F_max
// — r is free, so the multipliers are λ = ∂f/∂r, and every muscle's reduced gradient
// ∂f/∂F − Aᵀλ vanishes inside its bounds, is ≥ 0 at F = 0 and ≤ 0 at F = F_max. A finite-difference
// step along feasible directions (more of one muscle, the joints giving back its moment) must not
// lower the objective.
#include "spinesim/spine/equilibrium.hpp"
#include "spinesim/spine/recruitment.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

namespace sp = spinesim::spine;

namespace {

struct Axis {
  double pos, neg;  ///< strength R for r ≥ 0 and r < 0, N·mm
};

std::vector<Axis> joint_axes(const sp::SpineModel& m) {
  std::vector<Axis> out;
  for (int j : m.recruited_joints) {
    const sp::Joint& jt = m.joints[std::size_t(j)];
    if (jt.fused) continue;
    out.push_back({jt.k_flexion * jt.rom_flexion, jt.k_extension * jt.rom_extension});
    out.push_back({jt.k_torsion * jt.rom_torsion, jt.k_torsion * jt.rom_torsion});
    out.push_back({jt.k_lateral * jt.rom_lateral, jt.k_lateral * jt.rom_lateral});
  }
  return out;
}

double objective(const Eigen::VectorXd& F, const Eigen::VectorXd& fmax, const Eigen::VectorXd& r,
                 const std::vector<Axis>& axes, double p) {
  double f = 0;
  for (Eigen::Index i = 0; i < F.size(); ++i) f += std::pow(std::max(F(i) / fmax(i), 0.0), p);
  for (Eigen::Index k = 0; k < r.size(); ++k)
    f += std::pow(r(k) >= 0 ? r(k) / axes[k].pos : -r(k) / axes[k].neg, p);
  return f;
}

}  // namespace

TEST(Recruitment, SatisfiesTheKktConditionsOfItsCriterion) {
  const sp::SpineModel m = sp::load_spine_model(SPINESIM_DATA_DIR);
  sp::ExternalLoad load;
  load.vertebra = sp::vertebra_index("T7");
  load.force_n = Eigen::Vector3d(0, 0, 300);
  Eigen::MatrixXd A;
  Eigen::VectorXd b;
  std::vector<int> joints;
  sp::recruitment_problem(m, {load}, A, b, joints);
  const sp::Recruitment rec = sp::recruit(m, A, b);
  ASSERT_TRUE(rec.success) << rec.status;
  const double p = sp::RecruitmentOptions().power;
  const std::vector<Axis> axes = joint_axes(m);
  ASSERT_EQ(Eigen::Index(axes.size()), b.size());
  Eigen::VectorXd fmax(Eigen::Index(m.muscles.size()));
  for (std::size_t i = 0; i < m.muscles.size(); ++i)
    fmax(Eigen::Index(i)) = m.muscles[i].max_force_n();
  const Eigen::VectorXd& F = rec.force_n;
  const Eigen::VectorXd& r = rec.reserve_nmm;

  // Feasibility: A F + r = b, 0 ≤ F ≤ F_max.
  EXPECT_LE((A * F + r - b).cwiseAbs().maxCoeff(), 1e-5 * b.cwiseAbs().maxCoeff());
  EXPECT_GE((F.array() / fmax.array()).minCoeff(), -1e-8);
  EXPECT_LE((F.array() / fmax.array()).maxCoeff(), 1 + 1e-8);

  // Stationarity: λ = ∂f/∂r; reduced gradient of each muscle.
  Eigen::VectorXd lambda(r.size());
  for (Eigen::Index k = 0; k < r.size(); ++k) {
    const double a = r(k) >= 0 ? r(k) / axes[k].pos : -r(k) / axes[k].neg;
    lambda(k) = p * std::pow(a, p - 1) * (r(k) >= 0 ? 1 / axes[k].pos : -1 / axes[k].neg);
  }
  Eigen::VectorXd gF(F.size());
  for (Eigen::Index i = 0; i < F.size(); ++i)
    gF(i) = p * std::pow(std::max(F(i) / fmax(i), 0.0), p - 1) / fmax(i);
  const Eigen::VectorXd reduced = gF - A.transpose() * lambda;
  const double scale =
      std::max(gF.cwiseAbs().maxCoeff(), (A.transpose() * lambda).cwiseAbs().maxCoeff());
  int interior = 0, at_zero = 0;
  for (Eigen::Index i = 0; i < F.size(); ++i) {
    const double a = F(i) / fmax(i);
    if (a > 1e-4 && a < 1 - 1e-4) {
      ++interior;
      EXPECT_NEAR(reduced(i), 0, 1e-3 * scale) << m.muscles[std::size_t(i)].name;
    } else if (a <= 1e-4) {
      ++at_zero;
      EXPECT_GE(reduced(i), -1e-3 * scale) << m.muscles[std::size_t(i)].name;
    } else {
      EXPECT_LE(reduced(i), 1e-3 * scale) << m.muscles[std::size_t(i)].name;
    }
  }
  EXPECT_GT(interior, 10);  // the forward force recruits many extensors
  EXPECT_GT(at_zero, 10);   // and leaves the flexors idle

  // Finite differences along feasible directions: more of muscle i, the joints give its moment back.
  const double f0 = objective(F, fmax, r, axes, p);
  for (Eigen::Index i = 0; i < F.size(); ++i) {
    const double h = 1e-4 * fmax(i);
    if (F(i) + h <= fmax(i))
      EXPECT_GE(
          objective(F + h * Eigen::VectorXd::Unit(F.size(), i), fmax, r - h * A.col(i), axes, p),
          f0 - 1e-9 * f0);
    if (F(i) - h >= 0)
      EXPECT_GE(
          objective(F - h * Eigen::VectorXd::Unit(F.size(), i), fmax, r + h * A.col(i), axes, p),
          f0 - 1e-9 * f0);
  }
}

namespace {

struct Problem {
  sp::SpineModel m;
  Eigen::MatrixXd A;
  Eigen::VectorXd b, fmax;
};

Problem forward_push(double co_contraction, double tone) {
  sp::ModelOptions o;
  o.co_contraction = co_contraction;
  o.muscle_tone = tone;
  Problem p{sp::load_spine_model(SPINESIM_DATA_DIR, o), {}, {}, {}};
  sp::ExternalLoad load;
  load.vertebra = sp::vertebra_index("T7");
  load.force_n = Eigen::Vector3d(0, 0, 150);
  std::vector<int> joints;
  sp::recruitment_problem(p.m, {load}, p.A, p.b, joints);
  p.fmax.resize(Eigen::Index(p.m.muscles.size()));
  for (std::size_t i = 0; i < p.m.muscles.size(); ++i)
    p.fmax(Eigen::Index(i)) = p.m.muscles[i].max_force_n();
  return p;
}

}  // namespace

// Resting tone τ is carried, not chosen: with it, the recruitment must equal τ·F_max plus the
// plain recruitment of the load that is left once the tone's own moments are taken off
// (b − A τ F_max) — a second, independent problem. Co-contraction keeps every muscle at or above
// its floor, balances the load, and no feasible step lowers its criterion.
TEST(Recruitment, ToneIsCarriedAndCoContractionIsAFloor) {
  const double tau = 0.03;
  const Problem toned = forward_push(0, tau);
  const sp::Recruitment with_tone = sp::recruit(toned.m, toned.A, toned.b);
  ASSERT_TRUE(with_tone.success) << with_tone.status;
  const Problem plain = forward_push(0, 0);
  const Eigen::VectorXd shifted = plain.b - tau * plain.A * plain.fmax;
  const sp::Recruitment rest = sp::recruit(plain.m, plain.A, shifted);
  ASSERT_TRUE(rest.success) << rest.status;
  ASSERT_LT(rest.activation.maxCoeff(), 1 - tau);  // no upper bound active: the oracle holds
  const Eigen::VectorXd expected = tau * plain.fmax + rest.force_n;
  EXPECT_LE((with_tone.force_n - expected).cwiseAbs().maxCoeff(), 1e-3 * plain.fmax.maxCoeff())
      << (with_tone.force_n - expected).cwiseAbs().maxCoeff();
  EXPECT_GE(with_tone.activation.minCoeff(), tau - 1e-8);

  const double floor = 0.04, p = sp::RecruitmentOptions().power;
  const Problem cc = forward_push(floor, 0);
  const sp::Recruitment co = sp::recruit(cc.m, cc.A, cc.b);
  ASSERT_TRUE(co.success) << co.status;
  const Eigen::VectorXd& F = co.force_n;
  const Eigen::VectorXd& r = co.reserve_nmm;
  EXPECT_GE(co.activation.minCoeff(), floor - 1e-8);
  EXPECT_LE((cc.A * F + r - cc.b).cwiseAbs().maxCoeff(), 1e-5 * cc.b.cwiseAbs().maxCoeff());
  int at_floor = 0;
  const std::vector<Axis> axes = joint_axes(cc.m);
  const double f0 = objective(F, cc.fmax, r, axes, p);
  for (Eigen::Index i = 0; i < F.size(); ++i) {
    const double h = 1e-4 * cc.fmax(i);
    at_floor += F(i) < (floor + 1e-4) * cc.fmax(i);
    EXPECT_GE(objective(F + h * Eigen::VectorXd::Unit(F.size(), i), cc.fmax, r - h * cc.A.col(i),
                        axes, p),
              f0 - 1e-9 * f0);
    if (F(i) - h >= floor * cc.fmax(i))
      EXPECT_GE(objective(F - h * Eigen::VectorXd::Unit(F.size(), i), cc.fmax,
                          r + h * cc.A.col(i), axes, p),
                f0 - 1e-9 * f0);
  }
  EXPECT_GT(at_floor, 10);  // the flexors idle at the floor, not at zero

  sp::ModelOptions bad;
  bad.co_contraction = 0.6;
  EXPECT_THROW(sp::load_spine_model(SPINESIM_DATA_DIR, bad), std::invalid_argument);
  bad.co_contraction = 0;
  bad.muscle_tone = -0.01;
  EXPECT_THROW(sp::load_spine_model(SPINESIM_DATA_DIR, bad), std::invalid_argument);
}

// The rib cage: its energy and forces against an independent sum over its springs at the
// recovered rib poses (each rib and the sternum in equilibrium), the gradient against finite
// differences, invariance under rigid motion of the thorax, mirror symmetry, stiffening.
#include "spinesim/spine/equilibrium.hpp"
#include "spinesim/spine/rib_cage.hpp"

#include <gtest/gtest.h>
#include <Eigen/Eigenvalues>

#include <cmath>

namespace sp = spinesim::spine;
using Eigen::Vector3d;
using Eigen::VectorXd;

namespace {

/// Joints and the rib cage only.
sp::SpineModel caged(bool rib_cage = true) {
  sp::ModelOptions o;
  o.gravity = o.muscles = o.iap = false;
  o.ligaments = sp::Ligaments::Off;
  o.rib_cage = rib_cage;
  return sp::load_spine_model(SPINESIM_DATA_DIR, o);
}

/// A posture bending every thoracic joint a little in every direction.
VectorXd wiggle(const sp::SpineModel& m, double amplitude) {
  VectorXd theta = VectorXd::Zero(sp::dof_count(m));
  for (Eigen::Index i = 0; i < theta.size(); ++i)
    theta[i] = amplitude * std::cos(0.9 * double(i) + 0.4);
  return theta;
}

Vector3d log_of(const Eigen::Matrix3d& R) { return sp::rotation_log(R); }

/// Energy and per-body forces of the cage summed spring by spring at the recovered poses: an
/// independent reading of the springs the cage is built from (the condensation, the
/// corotational frame and the recovery are what is checked).
struct SpringSum {
  double energy = 0;
  std::vector<Vector3d> net_force;  ///< per rib, then the sternum
};
SpringSum sum_springs(const sp::SpineModel& m, const std::vector<sp::Pose>& P) {
  const sp::RibCage& c = *m.rib_cage;
  const auto Q = sp::rib_cage_poses(c, m.vertebrae, P);
  const std::size_t sternum = c.ribs.size();
  SpringSum s;
  s.net_force.assign(Q.size(), Vector3d::Zero());
  for (std::size_t r = 0; r < c.ribs.size(); ++r) {
    const sp::Rib& rib = c.ribs[r];
    const double share = 1.0 / double(rib.vertebrae.size());
    for (int v : rib.vertebrae) {
      const Vector3d d = Q[r].apply(rib.head_mm) - P[std::size_t(v)].apply(rib.head_mm);
      const Vector3d phi = log_of(P[std::size_t(v)].R.transpose() * Q[r].R);
      s.energy += 0.5 * share *
                  (c.k_costovertebral_n_per_mm * d.squaredNorm() +
                   c.k_costovertebral_nmm_per_rad * phi.squaredNorm());
      s.net_force[r] -= share * c.k_costovertebral_n_per_mm * d;
    }
    const std::size_t other = rib.front == sp::RibFront::Sternum ? sternum : r - 2;
    if (rib.front == sp::RibFront::Floating) continue;
    const Vector3d d = Q[r].apply(rib.cartilage_end_mm) - Q[other].apply(rib.cartilage_end_mm);
    s.energy += 0.5 * c.k_cartilage_n_per_mm * d.squaredNorm();
    s.net_force[r] -= c.k_cartilage_n_per_mm * d;
    s.net_force[other] += c.k_cartilage_n_per_mm * d;
  }
  return s;
}

double rotation_about_x_deg(const sp::SpineSolution& s, int vertebra, int axis) {
  return s.displacement(vertebra, 3 + axis);
}

}  // namespace

TEST(SpineRibCage, EnergyIsTheSumOverItsSpringsAndEveryRibIsInEquilibrium) {
  const auto m = caged();
  ASSERT_TRUE(m.rib_cage);
  EXPECT_EQ(m.rib_cage->ribs.size(), 24u);
  for (double a : {1e-4, 1e-3}) {
    const auto P = sp::vertebra_poses(m, wiggle(m, a));
    std::vector<Vector3d> f, tau;
    const double E = sp::rib_cage_energy(*m.rib_cage, m.vertebrae, P, f, tau);
    const SpringSum s = sum_springs(m, P);
    ASSERT_GT(E, 0);
    // Linear springs at small motion: the two agree to the motion's order (geometric terms).
    EXPECT_NEAR(s.energy / E, 1.0, 50 * a) << "amplitude " << a;
    double worst = 0, typical = 0;
    for (const Vector3d& n : s.net_force) worst = std::max(worst, n.norm());
    for (const Vector3d& x : f) typical = std::max(typical, x.norm());
    EXPECT_LT(worst, 50 * a * typical) << "a rib or the sternum is not in equilibrium";
  }
}

TEST(SpineRibCage, RigidMotionOfTheThoraxStrainsNothing) {
  const auto m = caged();
  // Turning the whole thorax (every joint below T12 bent by a finite angle) moves the cage rigidly.
  VectorXd theta = VectorXd::Zero(sp::dof_count(m));
  for (int j = sp::joint_index("T12-L1"); j < int(m.joints.size()); ++j)
    theta.segment<3>(3 * j) = Vector3d(0.15, -0.1, 0.12);
  std::vector<Vector3d> f, tau;
  EXPECT_LT(sp::rib_cage_energy(*m.rib_cage, m.vertebrae, sp::vertebra_poses(m, theta), f, tau),
            1e-18);
  for (std::size_t v = 0; v < f.size(); ++v) {
    EXPECT_LT(f[v].norm(), 1e-9);
    EXPECT_LT(tau[v].norm(), 1e-9);
  }
}

TEST(SpineRibCage, GradientMatchesFiniteDifferencesAtAFiniteBentPosture) {
  const auto m = caged();
  const VectorXd theta = wiggle(m, 0.05);
  VectorXd g;
  sp::potential(m, {}, VectorXd(), theta, &g);
  const double h = 1e-6;
  for (Eigen::Index i = 0; i < theta.size(); ++i) {
    VectorXd tp = theta, tm = theta;
    tp[i] += h;
    tm[i] -= h;
    const double fd =
        (sp::potential(m, {}, VectorXd(), tp) - sp::potential(m, {}, VectorXd(), tm)) / (2 * h);
    EXPECT_NEAR(g[i], fd, 1e-6 * (1 + std::abs(fd))) << "coordinate " << i;
  }
}

TEST(SpineRibCage, TheCageIsItsOwnMirrorImageAndStiffensEveryThoracicDirection) {
  const auto with = caged(true), without = caged(false);
  const auto& c = *with.rib_cage;
  for (std::size_t r = 0; r + 1 < c.ribs.size(); r += 2) {
    EXPECT_EQ(c.ribs[r].head_mm.x(), -c.ribs[r + 1].head_mm.x());
    EXPECT_EQ(c.ribs[r].front_mm.y(), c.ribs[r + 1].front_mm.y());
  }
  EXPECT_LT((c.stiffness - c.stiffness.transpose()).norm(), 1e-9 * c.stiffness.norm());
  EXPECT_GT(Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(c.stiffness).eigenvalues().minCoeff(),
            -1e-6 * c.stiffness.norm());
  // A couple of 2 N·m on T1 about each axis, T12 held: the cage makes the turn smaller.
  sp::SolveOptions o;
  o.recruit = false;
  const int t1 = sp::vertebra_index("T1");
  for (int axis = 0; axis < 3; ++axis) {
    sp::ExternalLoad l;
    l.vertebra = t1;
    l.moment_nmm[axis] = 2000;
    auto hold = [](sp::SpineModel m) {
      for (int j = sp::joint_index("T12-L1"); j < int(m.joints.size()); ++j)
        m.joints[std::size_t(j)].fused = true;
      return m;
    };
    const auto a = sp::solve_spine(hold(with), {l}, o), b = sp::solve_spine(hold(without), {l}, o);
    ASSERT_TRUE(a.converged && b.converged);
    const double ra = std::abs(rotation_about_x_deg(a, t1, axis)),
                 rb = std::abs(rotation_about_x_deg(b, t1, axis));
    EXPECT_LT(ra, 0.99 * rb) << "axis " << axis;
    EXPECT_GT(ra, 0.05 * rb) << "axis " << axis;  // the cage does not weld the spine
    if (axis == 0) {
      EXPECT_TRUE(a.sagittal_solve);
      for (int v = 0; v < 17; ++v) EXPECT_NEAR(a.displacement(v, 0), 0.0, 1e-9);
    }
  }
}

// The real-time poser gives the ribs and the sternum exactly the poses rib_cage_poses gives.
TEST(SpineRibCage, TheRealTimePoserAgreesWithTheRibPoses) {
  const auto m = caged();
  const auto P = sp::vertebra_poses(m, wiggle(m, 0.02));
  const auto expected = sp::rib_cage_poses(*m.rib_cage, m.vertebrae, P);
  sp::RibCagePoser poser(*m.rib_cage, m.vertebrae);
  ASSERT_EQ(poser.bodies(), expected.size());
  std::vector<sp::Pose> thoracic;
  for (int v : m.rib_cage->vertebrae) thoracic.push_back(P[std::size_t(v)]);
  std::vector<sp::Pose> got(poser.bodies());
  poser.pose(thoracic.data(), got.data());
  for (std::size_t b = 0; b < got.size(); ++b) {
    EXPECT_LT((got[b].R - expected[b].R).norm(), 1e-14) << b;
    EXPECT_LT((got[b].t - expected[b].t).norm(), 1e-11) << b;
  }
  // The ribs did move with the bent thorax (the comparison is not between two identities).
  EXPECT_GT((expected[0].t).norm(), 0.1);
}

// Element energies of the mass-spring disc: gradients and Hessians against central differences,
// symmetry and positive semi-definiteness, rest states, momentum (zero net force and moment),
// rigid-motion invariance, and the two places where we depart from the thesis: the apex force
// that (5.13) omits and the barycentre reaction that (5.4) omits.
#include "spinesim/common/constants.hpp"
#include "spinesim/mss/elements.hpp"

#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>

#include <cmath>
#include <functional>
#include <limits>
#include <random>

using namespace spinesim::mss;
using spinesim::kPi;

namespace {

template <int N>
using Vec = Eigen::Matrix<double, N, 1>;
template <int N>
using Mat = Eigen::Matrix<double, N, N>;

// Central differences with step h on mm-sized configurations: truncation h^2 |E'''|/6 ~ 1e-12
// and roundoff eps |E| / h ~ 1e-10, both relative to the derivative's scale, so 1e-6 relative
// to the largest entry leaves a wide margin while catching any wrong term (O(1) relative).
constexpr double kStep_mm = 1e-6;
constexpr double kFdTol = 1e-6;

double max_abs(const Eigen::MatrixXd& M) { return M.cwiseAbs().maxCoeff(); }

// Every element as E(X) on its stacked points X (3 per point, argument order).
template <int N>
struct Element {
  // energy(X, grad, hess, mode)
  std::function<double(const Vec<N>&, Vec<N>*, Mat<N>*, HessianMode)> energy;
  int points() const { return N / 3; }
};

Element<6> edge(double k, double L0) {
  return {[=](const Vec<6>& X, Vec<6>* g, Mat<6>* H, HessianMode m) {
    return edge_spring(X.head<3>(), X.tail<3>(), k, L0, g, H, m);
  }};
}
Element<12> radial(double k, double S0) {
  return {[=](const Vec<12>& X, Vec<12>* g, Mat<12>* H, HessianMode m) {
    return radial_springs(Eigen::Map<const TetPoints>(X.data()), k, S0, g, H, m);
  }};
}
Element<9> angle(double k, double theta0) {
  return {[=](const Vec<9>& X, Vec<9>* g, Mat<9>* H, HessianMode m) {
    return angle_spring(X.segment<3>(0), X.segment<3>(3), X.segment<3>(6), k, theta0, g, H, m);
  }};
}
Element<12> volume(double k, double V0) {
  return {[=](const Vec<12>& X, Vec<12>* g, Mat<12>* H, HessianMode m) {
    return volume_penalty(Eigen::Map<const TetPoints>(X.data()), k, V0, g, H, m);
  }};
}
Element<3> probe(const Eigen::Vector3d& c, double r, double k) {
  return {[=](const Vec<3>& X, Vec<3>* g, Mat<3>* H, HessianMode m) {
    Eigen::Vector3d g3;
    Eigen::Matrix3d H3;
    const double e = probe_contact(X, c, r, k, g ? &g3 : nullptr, H ? &H3 : nullptr, m);
    if (g) *g = g3;
    if (H) *H = H3;
    return e;
  }};
}

template <int N>
Vec<N> gradient(const Element<N>& el, const Vec<N>& X) {
  Vec<N> g;
  el.energy(X, &g, nullptr, HessianMode::exact);
  return g;
}
template <int N>
Mat<N> hessian(const Element<N>& el, const Vec<N>& X, HessianMode mode = HessianMode::exact) {
  Mat<N> H;
  el.energy(X, nullptr, &H, mode);
  return H;
}

// Checks grad against central differences of E, and the exact Hessian against central
// differences of grad (all entries); also that E, grad and H agree whichever are requested.
template <int N>
void expect_derivatives_match(const Element<N>& el, const Vec<N>& X, const char* what) {
  SCOPED_TRACE(what);
  Vec<N> g;
  Mat<N> H;
  const double e = el.energy(X, &g, &H, HessianMode::exact);
  Vec<N> fd_g;
  Mat<N> fd_H;
  for (int i = 0; i < N; ++i) {
    Vec<N> Xp = X, Xm = X;
    Xp(i) += kStep_mm;
    Xm(i) -= kStep_mm;
    fd_g(i) = (el.energy(Xp, nullptr, nullptr, HessianMode::exact) -
               el.energy(Xm, nullptr, nullptr, HessianMode::exact)) /
              (2 * kStep_mm);
    fd_H.col(i) = (gradient(el, Xp) - gradient(el, Xm)) / (2 * kStep_mm);
  }
  ASSERT_GT(max_abs(g), 0.0) << "test configuration is at rest";
  EXPECT_LE(max_abs(fd_g - g), kFdTol * max_abs(g)) << "grad\n"
                                                    << g.transpose() << "\nfd\n"
                                                    << fd_g.transpose();
  EXPECT_LE(max_abs(fd_H - H), kFdTol * max_abs(H)) << "hess\n" << H << "\nfd\n" << fd_H;
  // The same numbers whether or not the derivatives are asked for (to round-off: with FMA
  // contraction, e.g. -march=native, the two paths differ by a few ulps of theta - theta0).
  EXPECT_NEAR(el.energy(X, nullptr, nullptr, HessianMode::exact), e, 1e-12 * std::abs(e));
  EXPECT_EQ(gradient(el, X), g);
  EXPECT_EQ(hessian(el, X), H);
}

template <int N>
void expect_symmetric(const Mat<N>& H, const char* what) {
  EXPECT_LE(max_abs(H - H.transpose()), 1e-13 * max_abs(H)) << what;
}

template <int N>
void expect_psd(const Mat<N>& H, const char* what) {
  const double min_eig = Eigen::SelfAdjointEigenSolver<Mat<N>>(H).eigenvalues().minCoeff();
  EXPECT_GE(min_eig, -1e-10 * H.norm()) << what;
}

template <int N>
double min_eigenvalue(const Mat<N>& H) {
  return Eigen::SelfAdjointEigenSolver<Mat<N>>(H).eigenvalues().minCoeff();
}

// sum_i g_i and sum_i x_i × g_i of a stacked gradient, with the scale sum |x_i||g_i|.
template <int N>
void expect_zero_force_and_moment(const Vec<N>& X, const Vec<N>& g, const char* what) {
  Eigen::Vector3d force = Eigen::Vector3d::Zero(), moment = Eigen::Vector3d::Zero();
  double force_scale = 0, moment_scale = 0;
  for (int i = 0; i < N / 3; ++i) {
    force += g.template segment<3>(3 * i);
    moment += X.template segment<3>(3 * i).cross(g.template segment<3>(3 * i));
    force_scale += g.template segment<3>(3 * i).norm();
    moment_scale += X.template segment<3>(3 * i).norm() * g.template segment<3>(3 * i).norm();
  }
  ASSERT_GT(force_scale, 0.0) << what;
  EXPECT_LE(force.norm(), 1e-13 * force_scale) << what;
  EXPECT_LE(moment.norm(), 1e-13 * moment_scale) << what;
}

// Random configurations: a seeded generator so every run sees the same samples.
class Configs {
 public:
  explicit Configs(unsigned seed) : rng_(seed) {}
  double uniform(double lo, double hi) {
    return std::uniform_real_distribution<double>(lo, hi)(rng_);
  }
  Eigen::Vector3d point(double half_width) {
    return {uniform(-half_width, half_width), uniform(-half_width, half_width),
            uniform(-half_width, half_width)};
  }
  Eigen::Vector3d direction() {
    for (;;) {
      const Eigen::Vector3d v = point(1.0);
      if (v.norm() > 0.1 && v.norm() < 1.0) return v.normalized();
    }
  }
  // A positively oriented, well-shaped tet with ~1.5 mm edges somewhere within 10 mm.
  Vec<12> tet() {
    TetPoints ref;
    ref << 0, 1.5, 0.3, 0.5,  //
        0, 0, 1.4, 0.5,       //
        0, 0, 0, 1.3;
    const Eigen::Vector3d offset = point(10.0);
    for (;;) {
      TetPoints x = ref;
      for (int j = 0; j < 4; ++j) x.col(j) += offset + point(0.25);
      if (tet_signed_volume(x) > 0.2) return Eigen::Map<const Vec<12>>(x.data());
    }
  }
  // Apex and two arm ends, arms 0.5-2 mm, angle kept away from 0 and pi (sin > 0.2).
  Vec<9> angle_points() {
    for (;;) {
      const Eigen::Vector3d x0 = point(10.0);
      const Eigen::Vector3d a = direction() * uniform(0.5, 2.0);
      const Eigen::Vector3d b = direction() * uniform(0.5, 2.0);
      if (a.cross(b).norm() > 0.2 * a.norm() * b.norm()) {
        Vec<9> X;
        X << x0, x0 + a, x0 + b;
        return X;
      }
    }
  }
  Vec<6> edge_points() {
    const Eigen::Vector3d x0 = point(10.0);
    Vec<6> X;
    X << x0, x0 + direction() * uniform(0.5, 2.0);
    return X;
  }
  Eigen::Matrix3d rotation() {
    return Eigen::AngleAxisd(uniform(0.1, kPi), direction()).toRotationMatrix();
  }

 private:
  std::mt19937 rng_;
};

constexpr int kSamples = 8;

double edge_length(const Vec<6>& X) { return (X.tail<3>() - X.head<3>()).norm(); }
double radial_sum(const Vec<12>& X) {
  const TetPoints x = Eigen::Map<const TetPoints>(X.data());
  const Eigen::Vector3d xb = 0.25 * x.rowwise().sum();
  double S = 0;
  for (int j = 0; j < 4; ++j) S += (x.col(j) - xb).norm();
  return S;
}
double angle_of(const Vec<9>& X) {
  return angle_at(X.segment<3>(0), X.segment<3>(3), X.segment<3>(6));
}
double volume_of(const Vec<12>& X) {
  return tet_signed_volume(Eigen::Map<const TetPoints>(X.data()));
}

// Stretched (rest value below the current one) and compressed (above) for each element.
const double kRestFactors[] = {0.7, 1.3};

}  // namespace

// ---------------------------------------------------------------------------------------------
// Finite differences, symmetry, PSD of the projected Hessian

TEST(Edge, DerivativesMatchFiniteDifferences) {
  Configs rng(1);
  for (int s = 0; s < kSamples; ++s)
    for (double f : kRestFactors) {
      const Vec<6> X = rng.edge_points();
      expect_derivatives_match(edge(2.5, f * edge_length(X)), X,
                               f < 1 ? "stretched" : "compressed");
    }
}

TEST(Radial, DerivativesMatchFiniteDifferences) {
  Configs rng(2);
  for (int s = 0; s < kSamples; ++s)
    for (double f : kRestFactors) {
      const Vec<12> X = rng.tet();
      expect_derivatives_match(radial(1.7, f * radial_sum(X)), X,
                               f < 1 ? "stretched" : "compressed");
    }
}

TEST(Angle, DerivativesMatchFiniteDifferences) {
  Configs rng(3);
  for (int s = 0; s < kSamples; ++s)
    for (double dtheta : {-0.4, 0.3}) {
      const Vec<9> X = rng.angle_points();
      expect_derivatives_match(angle(40.0, angle_of(X) + dtheta), X,
                               dtheta < 0 ? "opened" : "closed");
    }
}

TEST(Volume, DerivativesMatchFiniteDifferences) {
  Configs rng(4);
  for (int s = 0; s < kSamples; ++s)
    for (double f : kRestFactors) {
      const Vec<12> X = rng.tet();
      expect_derivatives_match(volume(3.0, f * volume_of(X)), X, f < 1 ? "expanded" : "compressed");
    }
  // An inverted tet (negative signed volume) is still smooth.
  Vec<12> X = rng.tet();
  X.segment<3>(3).swap(X.segment<3>(6));
  expect_derivatives_match(volume(3.0, -volume_of(X)), X, "inverted");
}

TEST(Probe, DerivativesMatchFiniteDifferencesInside) {
  Configs rng(5);
  for (int s = 0; s < kSamples; ++s) {
    const Eigen::Vector3d c = rng.point(10.0);
    const double r = 2.0;
    const Vec<3> x = c + rng.direction() * rng.uniform(0.3, 1.9);
    expect_derivatives_match(probe(c, r, 5.0), x, "inside");
  }
}

TEST(Elements, ExactHessiansSymmetricProjectedSymmetricPsd) {
  Configs rng(6);
  for (int s = 0; s < kSamples; ++s)
    for (double f : kRestFactors) {
      const Vec<6> Xe = rng.edge_points();
      const Vec<12> Xt = rng.tet();
      const Vec<9> Xa = rng.angle_points();
      const auto e = edge(2.5, f * edge_length(Xe));
      const auto r = radial(1.7, f * radial_sum(Xt));
      const auto a = angle(40.0, f * angle_of(Xa));
      const auto v = volume(3.0, f * volume_of(Xt));
      expect_symmetric(hessian(e, Xe), "edge exact");
      expect_symmetric(hessian(r, Xt), "radial exact");
      expect_symmetric(hessian(a, Xa), "angle exact");
      expect_symmetric(hessian(v, Xt), "volume exact");
      const auto Pe = hessian(e, Xe, HessianMode::projected);
      const auto Pr = hessian(r, Xt, HessianMode::projected);
      const auto Pa = hessian(a, Xa, HessianMode::projected);
      const auto Pv = hessian(v, Xt, HessianMode::projected);
      expect_symmetric(Pe, "edge projected");
      expect_symmetric(Pr, "radial projected");
      expect_symmetric(Pa, "angle projected");
      expect_symmetric(Pv, "volume projected");
      expect_psd(Pe, "edge projected");
      expect_psd(Pr, "radial projected");
      expect_psd(Pa, "angle projected");
      expect_psd(Pv, "volume projected");
      const Vec<3> c = rng.point(10.0);
      const auto Pp =
          hessian(probe(c, 2.0, 5.0), Vec<3>(c + rng.direction()), HessianMode::projected);
      expect_symmetric(Pp, "probe projected");
      expect_psd(Pp, "probe projected");
    }
}

TEST(Elements, ExactHessiansAreIndefiniteWhereProjectionMatters) {
  // Otherwise the projection would be pointless: a compressed edge, a bent angle spring away
  // from rest and a probe-pressed node have negative curvature directions.
  Configs rng(7);
  const Vec<6> Xe = rng.edge_points();
  EXPECT_LT(min_eigenvalue(hessian(edge(2.5, 1.3 * edge_length(Xe)), Xe)), 0.0);
  const Vec<9> Xa = rng.angle_points();
  EXPECT_LT(min_eigenvalue(hessian(angle(40.0, angle_of(Xa) + 0.3), Xa)), 0.0);
  const Vec<3> x(1.0, 0.0, 0.0);
  EXPECT_LT(min_eigenvalue(hessian(probe(Eigen::Vector3d::Zero(), 2.0, 5.0), x)), 0.0);
}

TEST(Elements, ProjectedEqualsExactWhereTheyCoincide) {
  Configs rng(8);
  for (int s = 0; s < kSamples; ++s) {
    // Stretched edge and stretched radial sum: the transverse term is already >= 0.
    const Vec<6> Xe = rng.edge_points();
    const auto e = edge(2.5, 0.7 * edge_length(Xe));
    EXPECT_LE(max_abs(hessian(e, Xe, HessianMode::projected) - hessian(e, Xe)),
              1e-14 * max_abs(hessian(e, Xe)));
    const Vec<12> Xt = rng.tet();
    const auto r = radial(1.7, 0.7 * radial_sum(Xt));
    EXPECT_LE(max_abs(hessian(r, Xt, HessianMode::projected) - hessian(r, Xt)),
              1e-14 * max_abs(hessian(r, Xt)));
    // At rest the curvature term (theta - theta0) H_theta, (V - V0) H_V vanishes.
    const Vec<9> Xa = rng.angle_points();
    const auto a = angle(40.0, angle_of(Xa));
    EXPECT_EQ(hessian(a, Xa, HessianMode::projected), hessian(a, Xa));
    const auto v = volume(3.0, volume_of(Xt));
    EXPECT_EQ(hessian(v, Xt, HessianMode::projected), hessian(v, Xt));
  }
}

TEST(Edge, CompressedProjectedHessianIsAxialOnly) {
  // k uu^T per block: the compressed spring gives no transverse stiffness.
  const Eigen::Vector3d x0(1, 2, 3), x1(1, 2, 5);  // l = 2 mm along z
  Matrix6d H;
  edge_spring(x0, x1, 3.0, 2.5, nullptr, &H, HessianMode::projected);
  Eigen::Matrix3d K = Eigen::Matrix3d::Zero();
  K(2, 2) = 3.0;
  EXPECT_LE(max_abs(H.topLeftCorner<3, 3>() - K), 1e-15);
  EXPECT_LE(max_abs(H.topRightCorner<3, 3>() + K), 1e-15);
}

// ---------------------------------------------------------------------------------------------
// Rest state, momentum, rigid motions

TEST(Elements, ZeroEnergyAndGradientAtRest) {
  Configs rng(9);
  for (int s = 0; s < kSamples; ++s) {
    const Vec<6> Xe = rng.edge_points();
    const Vec<12> Xt = rng.tet();
    const Vec<9> Xa = rng.angle_points();
    Vec<6> ge;
    Vec<12> gr, gv;
    Vec<9> ga;
    // Zero to round-off: the rest length/angle/volume is recomputed by another code path, which
    // with FMA contraction (-march=native) can differ in the last bit (angle: E ~ 1e-31 N·mm).
    EXPECT_LE(edge(2.5, edge_length(Xe)).energy(Xe, &ge, nullptr, HessianMode::exact), 1e-26);
    EXPECT_LE(radial(1.7, radial_sum(Xt)).energy(Xt, &gr, nullptr, HessianMode::exact), 1e-26);
    EXPECT_LE(angle(40.0, angle_of(Xa)).energy(Xa, &ga, nullptr, HessianMode::exact), 1e-26);
    EXPECT_LE(volume(3.0, volume_of(Xt)).energy(Xt, &gv, nullptr, HessianMode::exact), 1e-26);
    EXPECT_LE(max_abs(ge), 1e-12);
    EXPECT_LE(max_abs(gr), 1e-12);
    EXPECT_LE(max_abs(ga), 1e-12);
    EXPECT_LE(max_abs(gv), 1e-12);
  }
}

TEST(Elements, GradientsHaveZeroNetForceAndMoment) {
  // Each energy is invariant under translations and rotations, so its forces are in
  // equilibrium: sum g_i = 0 and sum x_i × g_i = 0.
  Configs rng(10);
  for (int s = 0; s < kSamples; ++s)
    for (double f : kRestFactors) {
      const Vec<6> Xe = rng.edge_points();
      const Vec<12> Xt = rng.tet();
      const Vec<9> Xa = rng.angle_points();
      expect_zero_force_and_moment(Xe, gradient(edge(2.5, f * edge_length(Xe)), Xe), "edge");
      expect_zero_force_and_moment(Xt, gradient(radial(1.7, f * radial_sum(Xt)), Xt), "radial");
      expect_zero_force_and_moment(Xa, gradient(angle(40.0, f * angle_of(Xa)), Xa), "angle");
      expect_zero_force_and_moment(Xt, gradient(volume(3.0, f * volume_of(Xt)), Xt), "volume");
    }
}

template <int N>
void expect_rigid_invariant(const Element<N>& el, const Vec<N>& X, const Eigen::Matrix3d& R,
                            const Eigen::Vector3d& t, const char* what) {
  Vec<N> Y, gX, gY;
  for (int i = 0; i < N / 3; ++i)
    Y.template segment<3>(3 * i) = R * X.template segment<3>(3 * i) + t;
  const double eX = el.energy(X, &gX, nullptr, HessianMode::exact);
  const double eY = el.energy(Y, &gY, nullptr, HessianMode::exact);
  // Translating by ~10 mm costs ~1e-15 relative in the differences of coordinates.
  EXPECT_NEAR(eY, eX, 1e-10 * eX) << what;
  // ... and the gradient turns with the body.
  Vec<N> RgX;
  for (int i = 0; i < N / 3; ++i)
    RgX.template segment<3>(3 * i) = R * gX.template segment<3>(3 * i);
  EXPECT_LE(max_abs(gY - RgX), 1e-10 * max_abs(gX)) << what;
}

TEST(Elements, InvariantUnderRigidMotion) {
  Configs rng(11);
  for (int s = 0; s < kSamples; ++s) {
    const Eigen::Matrix3d R = rng.rotation();
    const Eigen::Vector3d t = rng.point(10.0);
    const Vec<6> Xe = rng.edge_points();
    const Vec<12> Xt = rng.tet();
    const Vec<9> Xa = rng.angle_points();
    expect_rigid_invariant(edge(2.5, 0.7 * edge_length(Xe)), Xe, R, t, "edge");
    expect_rigid_invariant(radial(1.7, 1.3 * radial_sum(Xt)), Xt, R, t, "radial");
    expect_rigid_invariant(angle(40.0, angle_of(Xa) + 0.3), Xa, R, t, "angle");
    expect_rigid_invariant(volume(3.0, 0.7 * volume_of(Xt)), Xt, R, t, "volume");
  }
}

// ---------------------------------------------------------------------------------------------
// Angles and the thesis's torsional force (5.13)

TEST(Angle, AgreesWithAcosOnWellConditionedAngles) {
  Configs rng(12);
  for (int s = 0; s < 4 * kSamples; ++s) {
    const Vec<9> X = rng.angle_points();
    const Eigen::Vector3d a = X.segment<3>(3) - X.segment<3>(0);
    const Eigen::Vector3d b = X.segment<3>(6) - X.segment<3>(0);
    const double c = a.dot(b) / (a.norm() * b.norm());
    if (std::abs(c) > 0.9) continue;  // acos itself is ill-conditioned there
    EXPECT_NEAR(angle_of(X), std::acos(c), 1e-14);
  }
  // A right angle and 60° (equilateral triangle).
  const Eigen::Vector3d o(0, 0, 0), ex(2, 0, 0), ey(0, 3, 0);
  EXPECT_NEAR(angle_at(o, ex, ey), kPi / 2, 1e-15);
  EXPECT_NEAR(angle_at(o, ex, Eigen::Vector3d(1, std::sqrt(3.0), 0)), kPi / 3, 1e-15);
}

TEST(Angle, AccurateNearZeroAndPi) {
  // Arms (1, 0, 0) and (±1, eps, 0): theta = atan(eps) and pi - atan(eps), both exact in IEEE
  // arithmetic up to an ulp. acos of the normalised dot product returns exactly 0 for small eps
  // (the cosine rounds to 1), which is why angle_at uses atan2(|a×b|, a.b).
  const Eigen::Vector3d o(0, 0, 0), a(1, 0, 0);
  for (double eps : {1e-4, 1e-9, 1e-14}) {
    const Eigen::Vector3d near0(1, eps, 0), near_pi(-1, eps, 0);
    EXPECT_NEAR(angle_at(o, a, near0), std::atan(eps),
                4 * std::numeric_limits<double>::epsilon() * eps);
    EXPECT_NEAR(angle_at(o, a, near_pi), kPi - std::atan(eps),
                4 * std::numeric_limits<double>::epsilon());
  }
  const Eigen::Vector3d b(1, 1e-9, 0);
  EXPECT_EQ(std::acos(a.dot(b) / (a.norm() * b.norm())), 0.0);  // the failure atan2 avoids
}

TEST(Angle, ThesisTorsionForceMissesTheApexForce) {
  Configs rng(13);
  const double k = 40.0;
  for (int s = 0; s < kSamples; ++s) {
    const Vec<9> X = rng.angle_points();
    const double theta0 = angle_of(X) + (s % 2 ? 0.3 : -0.3);
    Vec<9> g;
    angle_spring(X.segment<3>(0), X.segment<3>(3), X.segment<3>(6), k, theta0, &g);
    const Vector6d f =
        thesis_torsion_force(X.segment<3>(0), X.segment<3>(3), X.segment<3>(6), k, theta0);
    // (5.13) is right about the arm ends: minus the energy gradient there.
    EXPECT_LE(max_abs(f + g.tail<6>()), 1e-12 * max_abs(g));
    // The thesis error we fix: (5.13) gives the apex nothing, so its forces on one angle do
    // not balance; the net force equals the apex gradient (minus the apex force we add), and
    // it is of the same size as the arm forces, not a rounding effect.
    const Eigen::Vector3d net = f.head<3>() + f.tail<3>();
    EXPECT_LE((net - g.head<3>()).norm(), 1e-12 * max_abs(g));
    EXPECT_GT(net.norm(), 0.1 * f.head<3>().norm());
  }
  // At the rest angle both vanish.
  const Vec<9> X = rng.angle_points();
  EXPECT_EQ(max_abs(thesis_torsion_force(X.segment<3>(0), X.segment<3>(3), X.segment<3>(6), k,
                                         angle_of(X))),
            0.0);
}

// ---------------------------------------------------------------------------------------------
// Radial springs: the barycentre reaction (5.4) omits

TEST(Radial, BarycentreReactionBalancesTheThesisForce) {
  Configs rng(14);
  const double k = 1.7;
  for (int s = 0; s < kSamples; ++s) {
    const Vec<12> X = rng.tet();
    const TetPoints x = Eigen::Map<const TetPoints>(X.data());
    const double S = radial_sum(X), S0 = 0.8 * S;
    const Vec<12> g = gradient(radial(k, S0), X);
    // (5.4): f_i = k (S - S0) (x_B - x_i)/|x_B - x_i|, computed here from its definition.
    const Eigen::Vector3d xb = 0.25 * x.rowwise().sum();
    Eigen::Vector3d thesis_net = Eigen::Vector3d::Zero(), our_net = Eigen::Vector3d::Zero();
    Eigen::Vector3d u_sum = Eigen::Vector3d::Zero();
    for (int i = 0; i < 4; ++i) {
      const Eigen::Vector3d thesis_f = k * (S - S0) * (xb - x.col(i)).normalized();
      thesis_net += thesis_f;
      our_net -= g.segment<3>(3 * i);
      u_sum += (x.col(i) - xb).normalized();
    }
    // Ours = thesis force + the barycentre's reaction k (S - S0) (1/4) sum_j u_j.
    const Eigen::Vector3d reaction = 0.25 * k * (S - S0) * u_sum;
    for (int i = 0; i < 4; ++i) {
      const Eigen::Vector3d thesis_f = k * (S - S0) * (xb - x.col(i)).normalized();
      EXPECT_LE((-g.segment<3>(3 * i) - (thesis_f + reaction)).norm(), 1e-13 * k * (S - S0));
    }
    // The thesis forces alone push the tet's centre of mass; ours are in equilibrium.
    EXPECT_GT(thesis_net.norm(), 1e-3 * k * (S - S0));
    EXPECT_LE(our_net.norm(), 1e-13 * k * (S - S0));
  }
}

// ---------------------------------------------------------------------------------------------
// Volume

TEST(Volume, UnitCornerTetAndOrientation) {
  TetPoints x;
  x << 0, 1, 0, 0,  //
      0, 0, 1, 0,   //
      0, 0, 0, 1;
  EXPECT_NEAR(tet_signed_volume(x), 1.0 / 6.0, 1e-16);
  TetPoints swapped = x;
  swapped.col(1).swap(swapped.col(2));
  EXPECT_NEAR(tet_signed_volume(swapped), -1.0 / 6.0, 1e-16);

  // dV/dx_i = (area vector of the opposite face, towards x_i)/3: for x0 the face x1x2x3 has
  // area sqrt(3)/2 and normal -(1,1,1)/sqrt(3); for x1 the face x0x2x3 has area 1/2, normal e1.
  const double k = 3.0, V0 = 0.1;
  Vector12d g;
  volume_penalty(x, k, V0, &g);
  const double f = k * (1.0 / 6.0 - V0);
  Vector12d expected;
  expected << -1.0 / 6, -1.0 / 6, -1.0 / 6, 1.0 / 6, 0, 0, 0, 1.0 / 6, 0, 0, 0, 1.0 / 6;
  EXPECT_LE(max_abs(g - f * expected), 1e-15);
}

TEST(Volume, GradientIsHomogeneousOfDegreeThree) {
  // V(lambda x) = lambda^3 V(x), so (Euler) sum_i x_i . dV/dx_i = 3 V, whatever the origin.
  Configs rng(15);
  for (int s = 0; s < kSamples; ++s) {
    const Vec<12> X = rng.tet();
    const double V = volume_of(X);
    const Vec<12> g = gradient(volume(1.0, V - 1.0), X);  // k (V - V0) = 1: g = dV/dx
    EXPECT_NEAR(X.dot(g), 3 * V, 1e-12 * X.norm() * g.norm());
  }
}

// ---------------------------------------------------------------------------------------------
// Probe contact

TEST(Probe, ZeroOutsideAndPushesOutwardsInside) {
  const Eigen::Vector3d c(1, -2, 3);
  const double r = 2.0, k = 5.0;
  Eigen::Vector3d g;
  Eigen::Matrix3d H;
  for (const Eigen::Vector3d& x : {Eigen::Vector3d(c + Eigen::Vector3d(2.5, 0, 0)),
                                   Eigen::Vector3d(c + Eigen::Vector3d(0, 0, -2.0))}) {
    g.setConstant(1.0);
    H.setConstant(1.0);
    EXPECT_EQ(probe_contact(x, c, r, k, &g, &H), 0.0);
    EXPECT_EQ(max_abs(g), 0.0);
    EXPECT_EQ(max_abs(H), 0.0);
  }
  Configs rng(16);
  for (int s = 0; s < kSamples; ++s) {
    const Eigen::Vector3d n = rng.direction();
    const double depth = rng.uniform(0.1, 1.5);
    const double e = probe_contact(c + (r - depth) * n, c, r, k, &g);
    EXPECT_NEAR(e, 0.5 * k * depth * depth, 1e-12 * e);
    // The force -g is k * depth along the outward normal.
    EXPECT_LE((-g - k * depth * n).norm(), 1e-12 * k * depth);
  }
}

// ---------------------------------------------------------------------------------------------
// Degenerate input: finite, documented values instead of NaN

TEST(Elements, DegenerateInputGivesFiniteZeroForce) {
  const Eigen::Vector3d p(1, 2, 3);
  Vector6d g6;
  Matrix6d H6;
  edge_spring(p, p, 2.0, 1.0, &g6, &H6);  // zero-length edge
  EXPECT_EQ(max_abs(g6), 0.0);
  EXPECT_TRUE(H6.allFinite());
  expect_psd(H6, "zero-length edge");

  Vector9d g9;
  Matrix9d H9;
  angle_spring(p, p + Eigen::Vector3d(1, 0, 0), p + Eigen::Vector3d(2, 0, 0), 3.0, 1.0, &g9, &H9);
  EXPECT_EQ(max_abs(g9), 0.0);  // collinear arms
  EXPECT_TRUE(H9.allFinite());
  angle_spring(p, p, p + Eigen::Vector3d(2, 0, 0), 3.0, 1.0, &g9, &H9);
  EXPECT_EQ(max_abs(g9), 0.0);  // zero-length arm
  EXPECT_TRUE(H9.allFinite());
  EXPECT_EQ(max_abs(thesis_torsion_force(p, p + Eigen::Vector3d(1, 0, 0),
                                         p + Eigen::Vector3d(-2, 0, 0), 3.0, 1.0)),
            0.0);

  // A flat tet with x3 at the barycentre of all four (x3 = centroid of x0 x1 x2).
  TetPoints x;
  x << 0, 3, 0, 1,  //
      0, 0, 3, 1,   //
      0, 0, 0, 0;
  Vector12d g12;
  Matrix12d H12;
  radial_springs(x, 1.0, 10.0, &g12, &H12);
  EXPECT_TRUE(g12.allFinite());
  EXPECT_TRUE(H12.allFinite());

  Eigen::Vector3d g3;
  Eigen::Matrix3d H3;
  EXPECT_EQ(probe_contact(p, p, 1.0, 4.0, &g3, &H3), 2.0);  // node at the probe centre
  EXPECT_EQ(max_abs(g3), 0.0);
  EXPECT_TRUE(H3.allFinite());
}

TEST(Elements, NonFiniteInputIsNotHidden) {
  // The guards above must not turn a NaN position into a silent zero force.
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const Eigen::Vector3d p(1, 2, 3), q(nan, 0, 0);
  Vector6d g6;
  edge_spring(p, q, 2.0, 1.0, &g6);
  EXPECT_FALSE(g6.allFinite());
  Vector9d g9;
  angle_spring(p, q, p + Eigen::Vector3d(0, 1, 0), 3.0, 1.0, &g9);
  EXPECT_FALSE(g9.allFinite());
  Eigen::Vector3d g3;
  probe_contact(q, p, 1.0, 4.0, &g3);
  EXPECT_FALSE(g3.allFinite());
  TetPoints x = TetPoints::Identity();
  x(0, 3) = nan;
  Vector12d g12;
  radial_springs(x, 1.0, 1.0, &g12);
  EXPECT_FALSE(g12.allFinite());
}

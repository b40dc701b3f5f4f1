// The blocked per-tet kernel (mss/src/tet_terms.hpp) against the reference elements
// radial_springs and volume_penalty (elements.hpp) one tet at a time, and against central
// differences of its own energy.
#include "tet_terms.hpp"

#include "spinesim/mss/elements.hpp"

#include <gtest/gtest.h>

#include <random>

namespace spinesim::mss {
namespace {

using detail::TetTermBlockInput;

struct Cloud {
  Eigen::VectorXd X, x;  // rest and deformed positions, 3n
  Eigen::MatrixX4i T;
  std::vector<TetTermBlockInput> in;
};

// n_tets tets over a shared node cloud (nodes shared between tets, as in a mesh, so the
// scatter-add is exercised), each positively oriented at rest, deformed by `amplitude`.
Cloud make_cloud(int n_tets, double amplitude, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  const int n_nodes = n_tets + 3;
  Cloud c;
  c.X.resize(3 * n_nodes);
  for (Eigen::Index i = 0; i < c.X.size(); ++i) c.X(i) = 3.0 * u(rng);
  c.x = c.X;
  for (Eigen::Index i = 0; i < c.x.size(); ++i) c.x(i) += amplitude * u(rng);
  c.T.resize(n_tets, 4);
  for (int t = 0; t < n_tets; ++t) {
    c.T.row(t) << t, t + 1, t + 2, t + 3;
    TetPoints p;
    for (int k = 0; k < 4; ++k) p.col(k) = c.X.segment<3>(3 * c.T(t, k));
    if (tet_signed_volume(p) < 0) std::swap(c.T(t, 2), c.T(t, 3)), p.col(2).swap(p.col(3));
    const Eigen::Vector3d xb = 0.25 * p.rowwise().sum();
    double S0 = 0.0;
    for (int k = 0; k < 4; ++k) S0 += (p.col(k) - xb).norm();
    c.in.push_back({t, 10.0 + 5.0 * u(rng), S0, 3.0 + u(rng), tet_signed_volume(p)});
  }
  return c;
}

TetPoints points(const Cloud& c, const Eigen::VectorXd& x, int t) {
  TetPoints p;
  for (int k = 0; k < 4; ++k) p.col(k) = x.segment<3>(3 * c.T(t, k));
  return p;
}

// Energy and gradient of the reference elements, summed over the tets.
double reference(const Cloud& c, bool radial, bool volume, Eigen::VectorXd& g) {
  g.setZero(c.x.size());
  double e = 0.0;
  Vector12d gt;
  for (const TetTermBlockInput& in : c.in) {
    const TetPoints p = points(c, c.x, in.t);
    if (radial) {
      e += radial_springs(p, in.k_radial, in.rest_sum, &gt);
      for (int k = 0; k < 4; ++k) g.segment<3>(3 * c.T(in.t, k)) += gt.segment<3>(3 * k);
    }
    if (volume) {
      e += volume_penalty(p, in.k_volume, in.rest_volume, &gt);
      for (int k = 0; k < 4; ++k) g.segment<3>(3 * c.T(in.t, k)) += gt.segment<3>(3 * k);
    }
  }
  return e;
}

template <bool R, bool V>
double blocked(const Cloud& c, const Eigen::VectorXd& x, Eigen::VectorXd& g) {
  g.setZero(x.size());
  return detail::tet_terms_all<R, V>(c.in, c.T, x.data(), g.data());
}

template <bool R, bool V>
void expect_matches_reference(int n_tets, double amplitude) {
  const Cloud c = make_cloud(n_tets, amplitude, 7u + unsigned(n_tets));
  Eigen::VectorXd g_ref, g;
  const double e_ref = reference(c, R, V, g_ref);
  const double e = blocked<R, V>(c, c.x, g);
  ASSERT_GT(e_ref, 0.0);
  EXPECT_NEAR(e, e_ref, 1e-12 * e_ref) << n_tets << " tets";
  EXPECT_LE((g - g_ref).norm(), 1e-12 * g_ref.norm()) << n_tets << " tets";
}

// Block sizes that fill whole blocks, end in a partial one, and are smaller than one.
TEST(TetTerms, EqualsReferenceElementsForEveryTermChoiceAndBlockRemainder) {
  for (int n : {1, 5, 8, 17, 64, 203}) {
    expect_matches_reference<true, true>(n, 0.3);
    expect_matches_reference<true, false>(n, 0.3);
    expect_matches_reference<false, true>(n, 0.3);
  }
}

TEST(TetTerms, GradientIsTheDerivativeOfTheEnergy) {
  const Cloud c = make_cloud(37, 0.4, 11);
  Eigen::VectorXd g, scratch;
  blocked<true, true>(c, c.x, g);
  const double h = 1e-6;
  double worst = 0.0;
  for (Eigen::Index i = 0; i < c.x.size(); ++i) {
    Eigen::VectorXd xp = c.x, xm = c.x;
    xp(i) += h, xm(i) -= h;
    const double fd =
        (blocked<true, true>(c, xp, scratch) - blocked<true, true>(c, xm, scratch)) / (2 * h);
    worst = std::max(worst, std::abs(fd - g(i)));
  }
  EXPECT_LT(worst, 1e-6 * g.cwiseAbs().maxCoeff());
}

TEST(TetTerms, RestIsForceFreeAndACollapsedTetHasNoRadialDirection) {
  Cloud c = make_cloud(9, 0.0, 13);
  Eigen::VectorXd g;
  EXPECT_NEAR((blocked<true, true>(c, c.x, g)), 0.0, 1e-20);
  EXPECT_LT(g.cwiseAbs().maxCoeff(), 1e-12);
  // Tet 0 collapsed onto one point: every radial length is zero. As radial_springs, no force
  // along a direction that does not exist; the volume penalty still pushes the faces apart.
  c = make_cloud(1, 0.0, 17);
  for (int k = 1; k < 4; ++k) c.x.segment<3>(3 * c.T(0, k)) = c.x.segment<3>(3 * c.T(0, 0));
  Eigen::VectorXd g_ref;
  const double e = blocked<true, true>(c, c.x, g);
  EXPECT_TRUE(g.allFinite());
  EXPECT_DOUBLE_EQ(e, reference(c, true, true, g_ref));
  EXPECT_EQ((g - g_ref).cwiseAbs().maxCoeff(), 0.0);
}

}  // namespace
}  // namespace spinesim::mss

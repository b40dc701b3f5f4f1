// Per-spring multipliers of the main springs (MssOptions::edge_multipliers, model.hpp):
// k_e = mu_e (s_a k_e,a + s_n k_e,n). Properties: the edge list is the mesh's unique edges; the
// energy is linear in each mu_e with slope that spring's energy; gradient and Hessian (total and
// per term) stay the derivatives with random multipliers; dE/d s_main keeps mu_e; bad
// multipliers are refused.
#include "spinesim/mss/model.hpp"

#include "spinesim/mesh/box_mesh.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <set>
#include <utility>

namespace spinesim::mss {
namespace {

/// Box 10 x 6 x 8 mm, 3x2x2 cells, the cells with x > 5 mm nucleus (two regions, so edges on
/// the interface have both parts).
mesh::TetMesh box_with_nucleus() {
  mesh::TetMesh m = spinesim::mesh::box_mesh(3, 2, 2, 10.0, 6.0, 8.0);
  for (Eigen::Index t = 0; t < m.num_tets(); ++t) {
    double cx = 0.0;
    for (int k = 0; k < 4; ++k) cx += 0.25 * m.V(m.T(t, k), 0);
    if (cx > 5.0) m.region(t) = 2;
  }
  return m;
}

mesh::RegionMaterials materials() {
  mesh::RegionMaterials m;
  m.name = "test";
  m.fallback = {4.2, 0.45, 1200.0};
  m.by_region[2] = {1.0, 0.49, 1000.0};
  return m;
}

/// Every term on, region scales off 1, and a random multiplier in [0.2, 5] per edge spring.
MssOptions options_with_random_multipliers(Eigen::Index num_edges, unsigned seed) {
  MssOptions o;
  o.volume_term = true;
  o.disc_volume_term = true;
  o.scales[int(Term::main)].by_region = {1.3, 0.6};
  o.scales[int(Term::torsion)].by_region = {0.8, 2.0};
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> log_mu(std::log(0.2), std::log(5.0));
  for (Eigen::Index e = 0; e < num_edges; ++e) o.edge_multipliers.push_back(std::exp(log_mu(rng)));
  return o;
}

Eigen::Index count_edges() { return MssModel(box_with_nucleus(), materials()).num_edge_springs(); }

Eigen::VectorXd perturbed(const MssModel& model, double amplitude_mm, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-amplitude_mm, amplitude_mm);
  Eigen::VectorXd x = model.rest_positions_mm();
  for (Eigen::Index i = 0; i < x.size(); ++i) x(i) += u(rng);
  return x;
}

double spring_energy(const EdgeSpringInfo& e, const Eigen::VectorXd& x, double k) {
  const double stretch = (x.segment<3>(3 * e.j) - x.segment<3>(3 * e.i)).norm() - e.rest_mm;
  return 0.5 * k * stretch * stretch;
}

TEST(EdgeMultipliers, EdgeSpringsAreTheUniqueMeshEdgesInOrder) {
  const mesh::TetMesh m = box_with_nucleus();
  MssOptions o;
  o.scales[int(Term::main)].by_region = {1.5, 0.5};
  const MssModel model(m, materials(), o);
  const std::vector<EdgeSpringInfo> edges = model.edge_springs();
  ASSERT_EQ(Eigen::Index(edges.size()), model.num_edge_springs());
  std::set<std::pair<int, int>> mesh_edges;
  for (Eigen::Index t = 0; t < m.num_tets(); ++t)
    for (int a = 0; a < 4; ++a)
      for (int b = a + 1; b < 4; ++b)
        mesh_edges.insert({std::min(m.T(t, a), m.T(t, b)), std::max(m.T(t, a), m.T(t, b))});
  ASSERT_EQ(edges.size(), mesh_edges.size());
  auto it = mesh_edges.begin();
  bool both_parts = false;
  for (const EdgeSpringInfo& e : edges) {
    EXPECT_EQ(std::make_pair(e.i, e.j), *it++);  // sorted by (i, j), each once
    EXPECT_NEAR(e.rest_mm, (m.V.row(e.j) - m.V.row(e.i)).norm(), 1e-12);
    EXPECT_EQ(e.multiplier, 1.0);
    EXPECT_NEAR(e.k_region, 1.5 * e.k_part[0] + 0.5 * e.k_part[1], 1e-12 * e.k_region);
    EXPECT_GT(e.k_part[0] + e.k_part[1], 0.0);
    both_parts = both_parts || (e.k_part[0] > 0 && e.k_part[1] > 0);
  }
  EXPECT_TRUE(both_parts) << "the fixture should have interface edges";
}

TEST(EdgeMultipliers, AllOnesIsTheDefault) {
  const mesh::TetMesh m = box_with_nucleus();
  MssOptions ones = options_with_random_multipliers(count_edges(), 1);
  std::fill(ones.edge_multipliers.begin(), ones.edge_multipliers.end(), 1.0);
  MssOptions none = ones;
  none.edge_multipliers.clear();
  const MssModel a(m, materials(), ones), b(m, materials(), none);
  const Eigen::VectorXd x = perturbed(a, 0.3, 2);
  EXPECT_EQ(a.energy(x), b.energy(x));
}

// E is linear in each mu_e, with slope the spring's energy at its region-scaled stiffness.
TEST(EdgeMultipliers, EnergyIsLinearInEachMultiplier) {
  const mesh::TetMesh m = box_with_nucleus();
  const MssOptions o = options_with_random_multipliers(count_edges(), 3);
  MssModel model(m, materials(), o);
  const Eigen::VectorXd x = perturbed(model, 0.3, 4);
  const double e0 = model.energy(x);
  const std::vector<EdgeSpringInfo> edges = model.edge_springs();
  for (std::size_t e = 0; e < edges.size(); e += 7) {
    EXPECT_EQ(edges[e].multiplier, o.edge_multipliers[e]);
    const double slope = spring_energy(edges[e], x, edges[e].k_region);
    ASSERT_GT(slope, 0.0);
    for (const double d : {0.5, 2.0}) {
      std::vector<double> mu = o.edge_multipliers;
      mu[e] += d;
      model.set_edge_multipliers(mu);
      EXPECT_NEAR(model.energy(x) - e0, d * slope, 1e-9 * e0) << "edge " << e;
    }
  }
  // set_edge_multipliers is the same as building with them.
  model.set_edge_multipliers(o.edge_multipliers);
  EXPECT_EQ(model.energy(x), e0);
  EXPECT_EQ(model.energy(x), MssModel(m, materials(), o).energy(x));
}

// dE/d s_main keeps the multipliers: the main term's energy is sum_r s_r term_energy(main, r)
// = sum_e mu_e k_region,e (l - L0)^2 / 2.
TEST(EdgeMultipliers, MainTermEnergyKeepsTheMultipliers) {
  const MssOptions o = options_with_random_multipliers(count_edges(), 5);
  const MssModel model(box_with_nucleus(), materials(), o);
  const Eigen::VectorXd x = perturbed(model, 0.3, 6);
  double springs = 0.0;
  for (const EdgeSpringInfo& e : model.edge_springs())
    springs += spring_energy(e, x, e.multiplier * e.k_region);
  const auto& s = o.scales[int(Term::main)].by_region;
  const double main =
      s[0] * model.term_energy(x, Term::main, 0) + s[1] * model.term_energy(x, Term::main, 1);
  EXPECT_NEAR(main, springs, 1e-12 * springs);
}

TEST(EdgeMultipliers, GradientAndHessianMatchFiniteDifferences) {
  const MssModel model(box_with_nucleus(), materials(),
                       options_with_random_multipliers(count_edges(), 7));
  const Eigen::VectorXd x = perturbed(model, 0.3, 8);
  Eigen::VectorXd g;
  model.gradient(x, g);
  Eigen::SparseMatrix<double> H;
  model.hessian(x, HessianMode::exact, H);
  Eigen::VectorXd u;
  const double kg = model.disc_volume_rank_one(x, u);
  const Eigen::MatrixXd Hd =
      Eigen::MatrixXd(H) + kg * u * u.transpose();  // the whole-disc term's rank-one part
  const double h = 1e-6;
  double worst_g = 0.0, worst_h = 0.0;
  for (Eigen::Index i = 0; i < x.size(); i += 3) {
    Eigen::VectorXd xp = x, xm = x, gp, gm;
    xp(i) += h, xm(i) -= h;
    worst_g = std::max(worst_g, std::abs((model.energy(xp) - model.energy(xm)) / (2 * h) - g(i)));
    model.gradient(xp, gp);
    model.gradient(xm, gm);
    worst_h = std::max(worst_h, ((gp - gm) / (2 * h) - Hd.col(i)).cwiseAbs().maxCoeff());
  }
  EXPECT_LT(worst_g, 1e-6 * g.cwiseAbs().maxCoeff());
  EXPECT_LT(worst_h, 1e-6 * Hd.cwiseAbs().maxCoeff());
}

// The calibration's dK/d s_main with multipliers: term_gradient / term_hessian of the main term
// are the derivatives of term_energy / term_gradient, and the scale-weighted sum of all term
// Hessians is still the Hessian.
TEST(EdgeMultipliers, MainTermDerivativesStayConsistent) {
  const MssOptions o = options_with_random_multipliers(count_edges(), 9);
  const MssModel model(box_with_nucleus(), materials(), o);
  const Eigen::VectorXd x = perturbed(model, 0.3, 10);
  const double h = 1e-6;
  Eigen::SparseMatrix<double> H, Hj;
  model.hessian(x, HessianMode::exact, H);
  Eigen::MatrixXd sum = Eigen::MatrixXd::Zero(H.rows(), H.cols());
  for (int term = 0; term < kNumTerms; ++term)
    for (int r = 0; r < 2; ++r) {
      model.term_hessian(x, Term(term), r, HessianMode::exact, Hj);
      sum += o.scales[std::size_t(term)].by_region[std::size_t(r)] * Eigen::MatrixXd(Hj);
    }
  EXPECT_LT((sum - Eigen::MatrixXd(H)).cwiseAbs().maxCoeff(), 1e-12 * sum.cwiseAbs().maxCoeff());
  for (int r = 0; r < 2; ++r) {
    Eigen::VectorXd g;
    model.term_gradient(x, Term::main, r, g);
    model.term_hessian(x, Term::main, r, HessianMode::exact, Hj);
    const Eigen::MatrixXd Hd(Hj);
    double worst_g = 0.0, worst_h = 0.0;
    for (Eigen::Index i = 1; i < x.size(); i += 4) {
      Eigen::VectorXd xp = x, xm = x, gp, gm;
      xp(i) += h, xm(i) -= h;
      worst_g = std::max(worst_g, std::abs((model.term_energy(xp, Term::main, r) -
                                            model.term_energy(xm, Term::main, r)) /
                                               (2 * h) -
                                           g(i)));
      model.term_gradient(xp, Term::main, r, gp);
      model.term_gradient(xm, Term::main, r, gm);
      worst_h = std::max(worst_h, ((gp - gm) / (2 * h) - Hd.col(i)).cwiseAbs().maxCoeff());
    }
    EXPECT_LT(worst_g, 1e-6 * g.cwiseAbs().maxCoeff()) << "region " << r;
    EXPECT_LT(worst_h, 1e-6 * Hd.cwiseAbs().maxCoeff()) << "region " << r;
  }
}

/// `make` throws std::invalid_argument with a one-line message containing `needle`.
template <class F>
void expect_refused(F make, const std::string& needle) {
  try {
    make();
    ADD_FAILURE() << "accepted; expected a refusal mentioning '" << needle << "'";
  } catch (const std::invalid_argument& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find(needle), std::string::npos) << what;
    EXPECT_EQ(what.find('\n'), std::string::npos) << what;
  }
}

TEST(EdgeMultipliers, WrongSizeOrNonPositiveValuesAreRefused) {
  const mesh::TetMesh m = box_with_nucleus();
  const Eigen::Index n = count_edges();
  const MssOptions good = options_with_random_multipliers(n, 11);
  for (const Eigen::Index size : {n - 1, n + 1, Eigen::Index(1)}) {
    MssOptions o = good;
    o.edge_multipliers.resize(std::size_t(size), 1.0);
    expect_refused([&] { MssModel(m, materials(), o); },
                   std::to_string(size) + " edge multipliers for " + std::to_string(n));
  }
  for (const double bad : {0.0, -1.0, std::numeric_limits<double>::quiet_NaN(),
                           std::numeric_limits<double>::infinity()}) {
    MssOptions o = good;
    o.edge_multipliers[std::size_t(n / 2)] = bad;
    expect_refused([&] { MssModel(m, materials(), o); }, "finite and > 0");
  }
  // set_edge_multipliers refuses the same and leaves the model as it was.
  MssModel model(m, materials(), good);
  const Eigen::VectorXd x = perturbed(model, 0.3, 12);
  const double before = model.energy(x);
  expect_refused([&] { model.set_edge_multipliers(std::vector<double>(std::size_t(n + 3), 1.0)); },
                 "edge multipliers");
  std::vector<double> negative = good.edge_multipliers;
  negative[0] = -2.0;
  expect_refused([&] { model.set_edge_multipliers(negative); }, "finite and > 0");
  EXPECT_EQ(model.energy(x), before);
  EXPECT_EQ(model.options().edge_multipliers, good.edge_multipliers);
}

}  // namespace
}  // namespace spinesim::mss

// The per-spring stage (per_spring.hpp): K(s, mu) in the linearised model against the MSS built
// with the same multipliers, the neighbour pairs of the smoothness term, the local adjoint
// gradient (and each of its parts) against central differences, a synthetic reference made
// with known random multipliers fitted better than by region scales alone, and the promise
// that the stage never ends above the region fit's J.
#include "spinesim/calibration/per_spring.hpp"

#include "calibration_fixtures.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <random>
#include <set>

namespace spinesim::calibration {
namespace {

using fixtures::all_terms;
using fixtures::two_materials;
using fixtures::two_region_disc;

const std::vector<std::string> kTrain = {"compression", "shear-ap", "flexion", "torsion"};

Eigen::VectorXd true_scales() {
  Eigen::VectorXd s(9);
  s << 1.7, 0.6, 0.45, 2.2, 1.3, 0.8, 3.0, 0.5, 0.35;
  return s;
}

/// ln mu_e uniform in [-a, a], reproducible.
Eigen::VectorXd random_log_multipliers(Eigen::Index n, double a, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-a, a);
  Eigen::VectorXd q(n);
  for (Eigen::Index e = 0; e < n; ++e) q(e) = u(rng);
  return q;
}

struct Problem {
  mesh::TetMesh mesh = two_region_disc();
  mss::MssModel model{mesh, two_materials(), all_terms()};
  Eigen::Vector3d center = mss::default_plate_center(mesh);
  LinearMss lin{model, available_knobs(model.options()), center};
  Eigen::Index num_edges() const { return model.num_edge_springs(); }
};

// solve(s, mu) refills K on the region pattern; the MSS built with the same multipliers and
// linearised the ordinary way (term Hessians) must give the same responses — also when the
// linearised model's own MSS already carries other multipliers.
TEST(PerSpringLinearModel, MultipliersMatchTheMssModelBuiltWithThem) {
  Problem p;
  const Eigen::VectorXd s = true_scales();
  const Eigen::VectorXd mu = random_log_multipliers(p.num_edges(), 1.0, 1).array().exp();
  mss::MssOptions with = all_terms();
  with.edge_multipliers.assign(mu.data(), mu.data() + mu.size());
  const mss::MssModel direct_model(p.mesh, two_materials(), with);
  LinearMss direct(direct_model, available_knobs(with), p.center);
  const LinearState expected = direct.solve(s);
  const LinearState got = p.lin.solve(s, mu);
  EXPECT_LT((got.k6 - expected.k6).norm(), 1e-10 * expected.k6.norm());
  EXPECT_LT((got.Z - expected.Z).norm(), 1e-10 * expected.Z.norm());

  // From a model with multipliers mu back to all ones: the plain model's K(s).
  const LinearState back = direct.solve(s, Eigen::VectorXd::Ones(p.num_edges()));
  const LinearState plain = p.lin.solve(s);
  EXPECT_LT((back.k6 - plain.k6).norm(), 1e-10 * plain.k6.norm());
  // All ones is the region model itself.
  EXPECT_LT((p.lin.solve(s, Eigen::VectorXd::Ones(p.num_edges())).k6 - plain.k6).norm(),
            1e-12 * plain.k6.norm());
}

TEST(PerSpringLinearModel, EdgeStiffnessAndExtensionsAreTheSprings) {
  Problem p;
  const Eigen::VectorXd s = true_scales();
  const Eigen::VectorXd k = p.lin.edge_stiffness(s);
  const std::vector<mss::EdgeSpringInfo> edges = p.model.edge_springs();
  ASSERT_EQ(k.size(), Eigen::Index(edges.size()));
  for (std::size_t e = 0; e < edges.size(); ++e)
    EXPECT_NEAR(k(Eigen::Index(e)), s(0) * edges[e].k_part[0] + s(1) * edges[e].k_part[1],
                1e-12 * k(Eigen::Index(e)));
  // Extensions of a response: n·(u_j - u_i) with u = R z.
  const LinearState st = p.lin.solve(s);
  const Eigen::VectorXd z = st.Z.col(1);
  const Eigen::VectorXd u = p.lin.displacement(z);
  const Eigen::MatrixXd ext = p.lin.edge_extensions(z);
  const Eigen::VectorXd& X = p.model.rest_positions_mm();
  for (std::size_t e = 0; e < edges.size(); e += 11) {
    const Eigen::Vector3d n =
        (X.segment<3>(3 * edges[e].j) - X.segment<3>(3 * edges[e].i)).normalized();
    EXPECT_NEAR(ext(Eigen::Index(e), 0),
                n.dot(u.segment<3>(3 * edges[e].j) - u.segment<3>(3 * edges[e].i)),
                1e-12 * u.cwiseAbs().maxCoeff());
  }
  EXPECT_THROW(p.lin.solve(s, Eigen::VectorXd::Ones(p.num_edges() - 1)), std::invalid_argument);
  EXPECT_THROW(p.lin.solve(s, Eigen::VectorXd::Zero(p.num_edges())), std::invalid_argument);
}

TEST(PerSpring, NeighbourPairsAreTheEdgesSharingATetrahedron) {
  Problem p;
  const auto pairs = neighbouring_edge_pairs(p.model);
  const std::vector<mss::EdgeSpringInfo> edges = p.model.edge_springs();
  std::map<std::pair<int, int>, int> index;
  for (std::size_t e = 0; e < edges.size(); ++e) index[{edges[e].i, edges[e].j}] = int(e);
  std::set<std::pair<int, int>> expected;
  for (Eigen::Index t = 0; t < p.mesh.num_tets(); ++t) {
    std::vector<int> tet_edges;
    for (int a = 0; a < 4; ++a)
      for (int b = a + 1; b < 4; ++b)
        tet_edges.push_back(index.at(
            {std::min(p.mesh.T(t, a), p.mesh.T(t, b)), std::max(p.mesh.T(t, a), p.mesh.T(t, b))}));
    for (int a = 0; a < 6; ++a)
      for (int b = a + 1; b < 6; ++b)
        expected.insert(
            {std::min(tet_edges[a], tet_edges[b]), std::max(tet_edges[a], tet_edges[b])});
  }
  const std::vector<std::pair<int, int>> sorted(expected.begin(), expected.end());
  EXPECT_EQ(sorted, pairs);  // sorted, unique, e < f
}

/// Central differences of J along a sample of edges against the adjoint gradient.
void expect_gradient_matches(PerSpringObjective& obj, const Eigen::VectorXd& q,
                             const std::string& what) {
  const PerSpringEvaluation ev = obj.evaluate(q, true);
  ASSERT_EQ(ev.gradient.size(), q.size());
  const double scale = ev.gradient.cwiseAbs().maxCoeff();
  ASSERT_GT(scale, 0.0) << what;
  const double h = 1e-5;
  for (Eigen::Index e = 3; e < q.size(); e += q.size() / 17) {
    Eigen::VectorXd qp = q, qm = q;
    qp(e) += h, qm(e) -= h;
    const double fd = (obj.evaluate(qp, false).value - obj.evaluate(qm, false).value) / (2 * h);
    EXPECT_NEAR(ev.gradient(e), fd, 1e-6 * scale) << what << ", edge " << e;
  }
}

TEST(PerSpring, GradientMatchesFiniteDifferences) {
  Problem p;
  const FemReference ref = fixtures::synthetic_reference(p.lin, p.mesh, true_scales(), p.center);
  const Eigen::VectorXd region_p =
      0.8 * true_scales().array().log();  // off the truth: every residual non-zero
  const Eigen::VectorXd q = random_log_multipliers(p.num_edges(), 0.4, 2);
  {
    Objective region(p.lin, ref, kTrain);
    PerSpringObjective obj(region, p.model, region_p, PerSpringWeights{1e-2, 1e-3});
    const PerSpringEvaluation ev = obj.evaluate(q, false);
    ASSERT_GT(ev.data.displacement, 0.0);
    ASSERT_GT(ev.data.reaction, 0.0);
    ASSERT_GT(ev.data.stiffness, 0.0);
    ASSERT_GT(ev.smoothness, 0.0);
    ASSERT_GT(ev.prior, 0.0);
    expect_gradient_matches(obj, q, "all parts");
  }
  // Each part of J on its own: displacement, reaction, 6x6 diagonal, smoothness, prior.
  const char* names[] = {"displacement", "reaction", "stiffness", "smoothness", "prior"};
  for (int part = 0; part < 5; ++part) {
    Weights w;
    w.reaction = part == 1 ? 1.0 : 0.0;
    w.stiffness = part == 2 ? 1.0 : 0.0;
    Objective region(p.lin, ref, kTrain, w);
    PerSpringWeights ws{part == 3 ? 1.0 : 0.0, part == 4 ? 1.0 : 0.0};
    PerSpringObjective obj(region, p.model, region_p, ws);
    if (part >= 3) {  // only the regulariser: remove the data terms by a reference with zero weight
      const PerSpringEvaluation all = obj.evaluate(q, true);
      Objective data_only(p.lin, ref, kTrain, w);
      PerSpringObjective data(data_only, p.model, region_p, PerSpringWeights{0.0, 0.0});
      const PerSpringEvaluation d = data.evaluate(q, true);
      const Eigen::VectorXd reg = all.gradient - d.gradient;  // the regulariser's gradient alone
      const double h = 1e-5;
      for (Eigen::Index e = 1; e < q.size(); e += q.size() / 13) {
        Eigen::VectorXd qp = q, qm = q;
        qp(e) += h, qm(e) -= h;
        const auto part_value = [&](const Eigen::VectorXd& x) {
          const PerSpringEvaluation v = obj.evaluate(x, false);
          return part == 3 ? v.smoothness : v.prior;
        };
        EXPECT_NEAR(reg(e), (part_value(qp) - part_value(qm)) / (2 * h),
                    1e-8 * reg.cwiseAbs().maxCoeff() + 1e-12)
            << names[part] << ", edge " << e;
      }
    } else {
      expect_gradient_matches(obj, q, names[part]);
    }
  }
}

TEST(PerSpring, StartIsTheRegionFit) {
  Problem p;
  Objective region(p.lin, fixtures::synthetic_reference(p.lin, p.mesh, true_scales(), p.center),
                   kTrain);
  const Eigen::VectorXd region_p = 0.7 * true_scales().array().log();
  const Evaluation at_region = region.evaluate(region_p, false);
  PerSpringObjective obj(region, p.model, region_p);
  const PerSpringEvaluation start = obj.evaluate(Eigen::VectorXd::Zero(p.num_edges()), false);
  EXPECT_NEAR(start.value,
              at_region.value - region.weights().regularisation * at_region.regularisation,
              1e-12 * start.value);
  EXPECT_EQ(start.smoothness, 0.0);
  EXPECT_EQ(start.prior, 0.0);
  ASSERT_EQ(start.data.cases.size(), at_region.cases.size());
  for (std::size_t c = 0; c < start.data.cases.size(); ++c)
    EXPECT_NEAR(start.data.cases[c].displacement_error, at_region.cases[c].displacement_error,
                1e-12);
}

TEST(PerSpring, RefusesBadInput) {
  Problem p;
  Objective region(p.lin, fixtures::synthetic_reference(p.lin, p.mesh, true_scales(), p.center),
                   kTrain);
  const Eigen::VectorXd region_p = Eigen::VectorXd::Zero(9);
  EXPECT_THROW(PerSpringObjective(region, p.model, region_p, PerSpringWeights{-1.0, 0.0}),
               std::invalid_argument);
  EXPECT_THROW(PerSpringObjective(region, p.model, Eigen::VectorXd::Zero(8)),
               std::invalid_argument);
  const mss::MssModel other(
      spinesim::mesh::box_mesh(4, 3, 4, 20.0, 8.0, 16.0, Eigen::Vector3d(-10.0, 0.0, -8.0)),
      two_materials(), all_terms());
  EXPECT_THROW(PerSpringObjective(region, other, region_p), std::invalid_argument);
  PerSpringObjective obj(region, p.model, region_p);
  EXPECT_THROW(obj.evaluate(Eigen::VectorXd::Zero(p.num_edges() + 1), false),
               std::invalid_argument);
  IpoptSettings above_one = per_spring_ipopt_defaults();
  above_one.lower_scale = 1.5;
  EXPECT_THROW(calibrate_per_spring(obj, above_one), std::invalid_argument);
}

// A reference made by the linearised MSS with known random multipliers: the region scales alone
// cannot reach it, the per-spring stage gets much closer, and never ends above its start.
TEST(PerSpring, FitsKnownMultipliersBetterThanRegionScales) {
  Problem p;
  const Eigen::VectorXd q_true = random_log_multipliers(p.num_edges(), 0.7, 3);
  const FemReference ref =
      fixtures::synthetic_reference(p.lin, p.mesh, true_scales(), p.center, q_true.array().exp());
  Objective region(p.lin, ref, kTrain);
  const CalibrationResult fit = calibrate(region, Eigen::VectorXd::Zero(9));
  ASSERT_TRUE(fit.success) << fit.status;
  const double region_data =
      fit.final.value - region.weights().regularisation * fit.final.regularisation;
  ASSERT_GT(region_data, 1e-4) << "the region scales should not reach a per-spring reference";

  PerSpringObjective obj(region, p.model, fit.log_scales, PerSpringWeights{1e-3, 1e-6});
  const PerSpringResult r = calibrate_per_spring(obj);
  EXPECT_TRUE(r.success) << r.status;
  EXPECT_FALSE(r.kept_start);
  EXPECT_NEAR(r.start.data.value, region_data, 1e-10 * region_data);
  EXPECT_LT(r.final.value, r.start.value);
  EXPECT_LT(r.final.data.value, 0.2 * region_data)
      << "per-spring " << r.final.data.value << ", region " << region_data;
  // Trained and held-out cases both improve: the multipliers are the reference's, not noise.
  for (std::size_t c = 0; c < r.final.data.cases.size(); ++c)
    EXPECT_LT(r.final.data.cases[c].displacement_error, r.start.data.cases[c].displacement_error)
        << r.final.data.cases[c].name;
  EXPECT_GT(r.iterations, 0);
  EXPECT_GT(r.evaluations, 0);
  EXPECT_LE(r.log_multipliers.maxCoeff(), std::log(10.0) + 1e-9);
  EXPECT_GE(r.log_multipliers.minCoeff(), std::log(0.1) - 1e-9);
}

TEST(PerSpring, NeverEndsAboveTheRegionFit) {
  Problem p;
  const FemReference ref =
      fixtures::synthetic_reference(p.lin, p.mesh, true_scales(), p.center,
                                    random_log_multipliers(p.num_edges(), 0.5, 4).array().exp());
  Objective region(p.lin, ref, kTrain);
  const CalibrationResult fit = calibrate(region, Eigen::VectorXd::Zero(9));
  ASSERT_TRUE(fit.success) << fit.status;
  // Heavy regularisers, a one-iteration limit, and the default run: J at the end <= J at the start.
  for (const PerSpringWeights w : {PerSpringWeights{1e-3, 1e-4}, PerSpringWeights{10.0, 10.0}}) {
    PerSpringObjective obj(region, p.model, fit.log_scales, w);
    for (const int iterations : {1, 3, 1000}) {
      IpoptSettings settings = per_spring_ipopt_defaults();
      settings.max_iterations = iterations;
      const PerSpringResult r = calibrate_per_spring(obj, settings);
      EXPECT_LE(r.final.value, r.start.value) << iterations << " iterations, w_s " << w.smoothness;
      EXPECT_EQ(r.log_multipliers.size(), p.num_edges());
      if (iterations == 1) {
        EXPECT_FALSE(r.success);
        EXPECT_EQ(r.status, "Maximum_Iterations_Exceeded");
      }
      if (r.kept_start) EXPECT_EQ(r.log_multipliers.cwiseAbs().maxCoeff(), 0.0);
    }
  }
}

}  // namespace
}  // namespace spinesim::calibration

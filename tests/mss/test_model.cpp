// MssModel: the assembled energy, gradient and Hessian of the thesis MSS disc (model.hpp).
// Properties: finite differences of the assembled gradient/Hessian, momentum balance, rigid
// invariance, the Hessian's rigid null space, and closed-form energies under a uniform
// dilation that check the constants (5.1), (5.2), (5.8) without looking inside.
#include "spinesim/common/constants.hpp"
#include "spinesim/mss/model.hpp"

#include "spinesim/mss/elements.hpp"

#include "spinesim/mesh/box_mesh.hpp"
#include "spinesim/mesh/tet_mesh.hpp"

#include <gtest/gtest.h>
#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>

#include <cmath>
#include <random>

namespace spinesim::mss {
namespace {

using spinesim::mesh::box_mesh;

mesh::RegionMaterials two_regions() {
  mesh::RegionMaterials m;
  m.name = "test";
  m.fallback = {4.2, 0.45, 1200.0};
  m.by_region[2] = {1.0, 0.49, 1000.0};
  return m;
}

/// Box 12 x 6 x 9 mm, 3x2x3 cells, the central column of cells labelled nucleus.
mesh::TetMesh two_region_box() {
  mesh::TetMesh m = box_mesh(3, 2, 3, 12.0, 6.0, 9.0);
  for (Eigen::Index t = 0; t < m.num_tets(); ++t) {
    Eigen::Vector3d c = Eigen::Vector3d::Zero();
    for (int k = 0; k < 4; ++k) c += 0.25 * m.V.row(m.T(t, k)).transpose();
    if (c.x() > 4.0 && c.x() < 8.0 && c.z() > 3.0 && c.z() < 6.0) m.region(t) = 2;
  }
  return m;
}

MssOptions all_terms() {
  MssOptions o;
  o.volume_term = true;
  o.disc_volume_term = true;
  return o;
}

Eigen::VectorXd perturbed(const MssModel& model, double amplitude_mm, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-amplitude_mm, amplitude_mm);
  Eigen::VectorXd x = model.rest_positions_mm();
  for (Eigen::Index i = 0; i < x.size(); ++i) x(i) += u(rng);
  return x;
}

Eigen::VectorXd rigidly_moved(const Eigen::VectorXd& x, const Eigen::Matrix3d& R,
                              const Eigen::Vector3d& t) {
  Eigen::VectorXd y(x.size());
  for (Eigen::Index i = 0; i < x.size() / 3; ++i) y.segment<3>(3 * i) = R * x.segment<3>(3 * i) + t;
  return y;
}

Eigen::Matrix3d some_rotation() {
  return Eigen::AngleAxisd(0.7, Eigen::Vector3d(1.0, -2.0, 0.5).normalized()).toRotationMatrix();
}

// volume_mm3 goes through the outer surface: it must equal the sum of signed tet volumes at any
// deformation, tets inverted by a large one included (the brute-force oracle: the tet loop).
TEST(MssModel, VolumeThroughTheSurfaceEqualsTheSumOfSignedTetVolumes) {
  const mesh::TetMesh m = two_region_box();
  const MssModel model(m, two_regions());
  for (const double amplitude : {0.0, 0.3, 3.0}) {
    Eigen::VectorXd x = rigidly_moved(perturbed(model, amplitude, 41), some_rotation(),
                                      Eigen::Vector3d(150.0, -300.0, 40.0));
    double tets = 0.0;
    int inverted = 0;
    for (Eigen::Index t = 0; t < m.num_tets(); ++t) {
      TetPoints p;
      for (int k = 0; k < 4; ++k) p.col(k) = x.segment<3>(3 * m.T(t, k));
      tets += tet_signed_volume(p);
      inverted += tet_signed_volume(p) < 0;
    }
    EXPECT_NEAR(model.volume_mm3(x), tets, 1e-11 * model.rest_volume_mm3()) << amplitude;
    if (amplitude == 3.0) EXPECT_GT(inverted, 0);  // the large one does invert some
  }
}

TEST(MssModel, MassesAddUpToDensityTimesVolume) {
  const mesh::TetMesh m = two_region_box();
  const MssModel model(m, two_regions());
  double expected = 0.0;
  for (Eigen::Index t = 0; t < m.num_tets(); ++t)
    expected += two_regions().at(m.region(t)).density_t_mm3() * mesh::tet_volume(m, t);
  EXPECT_NEAR(model.total_mass_t(), expected, 1e-12 * expected);
  EXPECT_GT(model.node_masses_t().minCoeff(), 0.0);
  EXPECT_NEAR(model.rest_volume_mm3(), 12.0 * 6.0 * 9.0, 1e-9);
  EXPECT_NEAR(model.volume_mm3(model.rest_positions_mm()), model.rest_volume_mm3(), 1e-9);
  EXPECT_EQ(model.inverted_tets(model.rest_positions_mm()), 0);
  // Mirroring every node inverts every tetrahedron.
  Eigen::VectorXd mirrored = model.rest_positions_mm();
  for (Eigen::Index i = 0; i < model.num_nodes(); ++i) mirrored(3 * i) *= -1.0;
  EXPECT_EQ(model.inverted_tets(mirrored), m.num_tets());
}

TEST(MssModel, RestIsEquilibriumWithZeroEnergy) {
  const MssModel model(two_region_box(), two_regions(), all_terms());
  Eigen::VectorXd g;
  EXPECT_NEAR(model.gradient(model.rest_positions_mm(), g), 0.0, 1e-20);
  EXPECT_LT(g.cwiseAbs().maxCoeff(), 1e-10);
}

// Uniform dilation x = (1 + eps) X changes every length by eps L0, keeps every angle and scales
// every volume by (1 + eps)^3, so each term's energy has a closed form in the material alone:
//   main   sum_e 1/2 k_e (eps L0)^2 = 1/2 eps^2 sum_e sum_{t∋e} E_t V_t = 3 eps^2 sum_t E_t V_t
//   radial sum_t 1/2 (E_t V_t / S0^2)(eps S0)^2 = 1/2 eps^2 sum_t E_t V_t
//   angle  0
//   volume sum_t 1/2 (K_t/V_t) (((1+eps)^3 - 1) V_t)^2
//   disc   1/2 (c_g K_mean/V) (((1+eps)^3 - 1) V)^2 = c_g times the same
TEST(MssModel, DilationEnergiesMatchVanGelderAndBulkModulus) {
  const mesh::TetMesh m = two_region_box();
  const mesh::RegionMaterials mat = two_regions();
  const MssModel model(m, mat, all_terms());
  const double eps = 0.01;
  const Eigen::VectorXd x = (1.0 + eps) * model.rest_positions_mm();
  double EV = 0.0, KV = 0.0;
  for (Eigen::Index t = 0; t < m.num_tets(); ++t) {
    const auto& mt = mat.at(m.region(t));
    EV += mt.youngs_modulus_mpa * mesh::tet_volume(m, t);
    KV += mt.youngs_modulus_mpa / (3.0 * (1.0 - 2.0 * mt.poisson_ratio)) * mesh::tet_volume(m, t);
  }
  auto both = [&](Term term) {
    return model.term_energy(x, term, 0) + model.term_energy(x, term, 1);
  };
  EXPECT_NEAR(both(Term::main), 3.0 * eps * eps * EV, 1e-9 * EV * eps * eps);
  EXPECT_NEAR(both(Term::radial), 0.5 * eps * eps * EV, 1e-9 * EV * eps * eps);
  EXPECT_NEAR(both(Term::torsion), 0.0, 1e-12 * EV * eps * eps);
  const double dv = std::pow(1.0 + eps, 3) - 1.0;
  EXPECT_NEAR(both(Term::volume), 0.5 * KV * dv * dv, 1e-9 * KV * dv * dv);
  const double cg = model.options().disc_volume_factor;
  EXPECT_NEAR(both(Term::disc_volume), 0.5 * cg * KV * dv * dv, 1e-9 * cg * KV * dv * dv);
  EXPECT_EQ(model.term_energy(x, Term::disc_volume, 1), 0.0);
  EXPECT_NEAR(model.energy(x),
              both(Term::main) + both(Term::radial) + both(Term::volume) + both(Term::disc_volume),
              1e-12 * EV);
}

// (5.6)-(5.8) on a box: endplates lx*lz, so D_u = D_l = 2 sqrt(lx lz / pi); L_m = 4V/(pi D^2) = ly;
// n_t = 3 x (number of distinct triangles) = 3 (4 T + F_boundary) / 2.
TEST(MssModel, EquivalentCylinderOfABox) {
  const int nx = 3, ny = 2, nz = 3;
  const double lx = 12.0, ly = 6.0, lz = 9.0;
  const mesh::TetMesh m = box_mesh(nx, ny, nz, lx, ly, lz);
  const MssModel model(m, two_regions());
  const EquivalentCylinder& c = model.cylinder();
  const double D = 2.0 * std::sqrt(lx * lz / kPi);
  EXPECT_NEAR(c.upper_diameter_mm, D, 1e-12 * D);
  EXPECT_NEAR(c.lower_diameter_mm, D, 1e-12 * D);
  EXPECT_NEAR(c.length_mm, ly, 1e-12 * ly);
  const Eigen::Index boundary_faces = 2 * 2 * (nx * ny + ny * nz + nx * nz);
  const Eigen::Index faces = (4 * m.num_tets() + boundary_faces) / 2;
  EXPECT_EQ(model.num_angle_springs(), 3 * faces);
  EXPECT_EQ(c.num_angle_springs, 3 * faces);
  EXPECT_NEAR(c.k_t_per_shear_modulus, kPi * std::pow(D, 4) / (32.0 * ly * 3.0 * faces), 1e-12);
  EXPECT_EQ(model.num_radial_tets(), m.num_tets());
  EXPECT_EQ(model.num_volume_terms(), 0);
}

TEST(MssModel, GradientMatchesFiniteDifferences) {
  const MssModel model(two_region_box(), two_regions(), all_terms());
  const Eigen::VectorXd x = perturbed(model, 0.4, 7);
  Eigen::VectorXd g;
  model.gradient(x, g);
  const double h = 1e-6;
  double worst = 0.0;
  for (Eigen::Index i = 0; i < x.size(); i += 5) {
    Eigen::VectorXd xp = x, xm = x;
    xp(i) += h, xm(i) -= h;
    const double fd = (model.energy(xp) - model.energy(xm)) / (2 * h);
    worst = std::max(worst, std::abs(fd - g(i)));
  }
  EXPECT_LT(worst, 1e-6 * g.cwiseAbs().maxCoeff());
}

TEST(MssModel, TermGradientsAreDerivativesOfTermEnergies) {
  const MssModel model(two_region_box(), two_regions(), all_terms());
  const Eigen::VectorXd x = perturbed(model, 0.4, 8);
  const double h = 1e-6;
  for (Term term : {Term::main, Term::radial, Term::torsion, Term::volume, Term::disc_volume})
    for (int r = 0; r < (term == Term::disc_volume ? 1 : 2); ++r) {
      Eigen::VectorXd g;
      model.term_gradient(x, term, r, g);
      ASSERT_GT(g.norm(), 0.0) << "term " << static_cast<int>(term) << " region " << r;
      double worst = 0.0;
      for (Eigen::Index i = 1; i < x.size(); i += 7) {
        Eigen::VectorXd xp = x, xm = x;
        xp(i) += h, xm(i) -= h;
        const double fd =
            (model.term_energy(xp, term, r) - model.term_energy(xm, term, r)) / (2 * h);
        worst = std::max(worst, std::abs(fd - g(i)));
      }
      EXPECT_LT(worst, 1e-6 * g.cwiseAbs().maxCoeff()) << "term " << static_cast<int>(term);
    }
}

// The calibration knobs: E is linear in the per-term, per-region scales.
TEST(MssModel, EnergyIsLinearInTheScales) {
  MssModel model(two_region_box(), two_regions(), all_terms());
  const Eigen::VectorXd x = perturbed(model, 0.3, 9);
  std::array<RegionScales, kNumTerms> s{};
  const double values[kNumTerms][2] = {{1.5, 0.7}, {2.0, 3.0}, {0.25, 4.0},
                                       {1.1, 0.9}, {2.5, 1.0}, {1.7, 0.6}};
  double expected = 0.0;
  for (int term = 0; term < kNumTerms; ++term)
    for (int r = 0; r < 2; ++r) {
      s[term].by_region[r] = values[term][r];
      expected += values[term][r] * model.term_energy(x, static_cast<Term>(term), r);
    }
  model.set_scales(s);
  EXPECT_NEAR(model.energy(x), expected, 1e-12 * std::abs(expected));
  s[0].by_region[1] = 0.0;
  EXPECT_THROW(model.set_scales(s), std::invalid_argument);
}

// dK/d scale for the calibration: term Hessians are the derivatives of the term gradients,
// and the full Hessian is their scale-weighted sum (the whole-disc rank-one part aside).
TEST(MssModel, TermHessiansSumToTheHessian) {
  MssModel model(two_region_box(), two_regions(), all_terms());
  const Eigen::VectorXd x = perturbed(model, 0.3, 10);
  std::array<RegionScales, kNumTerms> s{};
  const double values[kNumTerms][2] = {{1.5, 0.7}, {2.0, 3.0}, {0.25, 4.0},
                                       {1.1, 0.9}, {2.5, 1.0}, {1.7, 0.6}};
  for (int term = 0; term < kNumTerms; ++term)
    s[term].by_region = {values[term][0], values[term][1]};
  model.set_scales(s);
  Eigen::SparseMatrix<double> H, Hj;
  model.hessian(x, HessianMode::exact, H);
  Eigen::MatrixXd sum = Eigen::MatrixXd::Zero(H.rows(), H.cols());
  const double h = 1e-6;
  for (int term = 0; term < kNumTerms; ++term)
    for (int r = 0; r < 2; ++r) {
      model.term_hessian(x, static_cast<Term>(term), r, HessianMode::exact, Hj);
      sum += values[term][r] * Eigen::MatrixXd(Hj);
      // No fibres in the box, so no fibre springs (tested on the disc in test_fibre_springs.cpp).
      if ((term == static_cast<int>(Term::disc_volume) && r == 1) ||
          term == static_cast<int>(Term::fibre)) {
        EXPECT_EQ(Eigen::MatrixXd(Hj).cwiseAbs().maxCoeff(), 0.0);
        continue;
      }
      // One column in 5 against central differences of the term gradient (the whole-disc
      // term with its rank-one part, unscaled: k_g / scale u u^T).
      Eigen::MatrixXd Hd(Hj);
      if (term == static_cast<int>(Term::disc_volume)) {
        Eigen::VectorXd u;
        const double kg = model.disc_volume_rank_one(x, u);
        Hd += (kg / values[term][0]) * u * u.transpose();
      }
      double worst = 0.0;
      for (Eigen::Index j = 2; j < x.size(); j += 5) {
        Eigen::VectorXd xp = x, xm = x, gp, gm;
        xp(j) += h, xm(j) -= h;
        model.term_gradient(xp, static_cast<Term>(term), r, gp);
        model.term_gradient(xm, static_cast<Term>(term), r, gm);
        worst = std::max(worst, ((gp - gm) / (2 * h) - Hd.col(j)).cwiseAbs().maxCoeff());
      }
      EXPECT_LT(worst, 1e-6 * Hd.cwiseAbs().maxCoeff()) << "term " << term << " region " << r;
    }
  EXPECT_LT((sum - Eigen::MatrixXd(H)).cwiseAbs().maxCoeff(), 1e-12 * sum.cwiseAbs().maxCoeff());
}

TEST(MssModel, InternalForcesBalanceInAnyConfiguration) {
  const MssModel model(two_region_box(), two_regions(), all_terms());
  for (unsigned seed : {1u, 2u, 3u}) {
    const Eigen::VectorXd x = perturbed(model, 0.8, seed);
    Eigen::VectorXd g;
    model.gradient(x, g);
    Eigen::Vector3d force = Eigen::Vector3d::Zero(), moment = Eigen::Vector3d::Zero();
    for (Eigen::Index i = 0; i < model.num_nodes(); ++i) {
      force += g.segment<3>(3 * i);
      moment += x.segment<3>(3 * i).cross(g.segment<3>(3 * i));
    }
    const double scale = g.cwiseAbs().maxCoeff();
    EXPECT_LT(force.norm(), 1e-11 * scale);
    EXPECT_LT(moment.norm(), 1e-11 * scale * 15.0);  // lever arms up to ~15 mm
  }
}

TEST(MssModel, EnergyIsInvariantUnderRigidMotion) {
  const MssModel model(two_region_box(), two_regions(), all_terms());
  const Eigen::Matrix3d R = some_rotation();
  const Eigen::Vector3d t(3.0, -1.0, 20.0);
  EXPECT_NEAR(model.energy(rigidly_moved(model.rest_positions_mm(), R, t)), 0.0, 1e-16);
  const Eigen::VectorXd x = perturbed(model, 0.5, 4);
  const double e = model.energy(x);
  EXPECT_NEAR(model.energy(rigidly_moved(x, R, t)), e, 1e-11 * e);
}

// The whole-disc volume term's dense rank-one part comes separately: H + k_g u u^T.
TEST(MssModel, HessianMatchesFiniteDifferencesOfTheGradient) {
  const MssModel model(two_region_box(), two_regions(), all_terms());
  const Eigen::VectorXd x = perturbed(model, 0.4, 5);
  Eigen::SparseMatrix<double> H;
  model.hessian(x, HessianMode::exact, H);
  Eigen::VectorXd u;
  const double kg = model.disc_volume_rank_one(x, u);
  ASSERT_GT(kg, 0.0);
  const Eigen::MatrixXd Hd = Eigen::MatrixXd(H) + kg * u * u.transpose();
  const double h = 1e-6;
  double worst = 0.0;
  for (Eigen::Index j = 0; j < x.size(); j += 3) {
    Eigen::VectorXd xp = x, xm = x, gp, gm;
    xp(j) += h, xm(j) -= h;
    model.gradient(xp, gp);
    model.gradient(xm, gm);
    worst = std::max(worst, ((gp - gm) / (2 * h) - Hd.col(j)).cwiseAbs().maxCoeff());
  }
  EXPECT_LT(worst, 1e-6 * Hd.cwiseAbs().maxCoeff());
  EXPECT_LT((Hd - Hd.transpose()).cwiseAbs().maxCoeff(), 1e-12 * Hd.cwiseAbs().maxCoeff());
}

TEST(MssModel, ProjectedHessianIsPositiveSemiDefinite) {
  const MssModel model(two_region_box(), two_regions(), all_terms());
  const Eigen::VectorXd x = perturbed(model, 0.8, 6);
  Eigen::SparseMatrix<double> H;
  model.hessian(x, HessianMode::projected, H);
  const Eigen::MatrixXd Hd = Eigen::MatrixXd(H);
  EXPECT_LT((Hd - Hd.transpose()).cwiseAbs().maxCoeff(), 1e-12 * Hd.cwiseAbs().maxCoeff());
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(Hd);
  EXPECT_GT(eig.eigenvalues().minCoeff(), -1e-9 * eig.eigenvalues().maxCoeff());
  // The exact one at a strongly perturbed state is indefinite: the projection did something.
  model.hessian(x, HessianMode::exact, H);
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> exact{Eigen::MatrixXd(H)};
  EXPECT_LT(exact.eigenvalues().minCoeff(), -1e-6 * exact.eigenvalues().maxCoeff());
}

// At rest the stiffness has exactly the six rigid modes in its null space, and is positive
// definite on the rest (no zero-energy modes: edges, angles and radial springs hold every tet).
TEST(MssModel, RestHessianNullSpaceIsTheRigidModes) {
  const MssModel model(box_mesh(2, 2, 2, 6.0, 6.0, 6.0), two_regions());
  Eigen::SparseMatrix<double> H;
  model.hessian(model.rest_positions_mm(), HessianMode::exact, H);
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig{Eigen::MatrixXd(H)};
  const Eigen::VectorXd& ev = eig.eigenvalues();
  const double top = ev.maxCoeff();
  for (int i = 0; i < 6; ++i) EXPECT_LT(std::abs(ev(i)), 1e-10 * top);
  EXPECT_GT(ev(6), 1e-6 * top);
  const Eigen::VectorXd& X = model.rest_positions_mm();
  for (int axis = 0; axis < 3; ++axis) {
    Eigen::VectorXd shift = Eigen::VectorXd::Zero(X.size()), spin(X.size());
    for (Eigen::Index i = 0; i < model.num_nodes(); ++i) {
      shift(3 * i + axis) = 1.0;
      spin.segment<3>(3 * i) = Eigen::Vector3d::Unit(axis).cross(X.segment<3>(3 * i));
    }
    EXPECT_LT((H * shift).norm(), 1e-10 * top);
    EXPECT_LT((H * spin).norm(), 1e-9 * top);
  }
}

TEST(MssModel, HessianRefillsTheSamePattern) {
  const MssModel model(two_region_box(), two_regions());
  Eigen::SparseMatrix<double> H;
  model.hessian(perturbed(model, 0.3, 1), HessianMode::exact, H);
  const double* values = H.valuePtr();
  const Eigen::VectorXd x2 = perturbed(model, 0.3, 2);
  model.hessian(x2, HessianMode::exact, H);
  EXPECT_EQ(values, H.valuePtr());  // refilled in place, no reallocation
  Eigen::SparseMatrix<double> fresh;
  model.hessian(x2, HessianMode::exact, fresh);
  EXPECT_EQ((Eigen::MatrixXd(H) - Eigen::MatrixXd(fresh)).cwiseAbs().maxCoeff(), 0.0);
}

TEST(MssModel, TermsCanBeSwitchedOff) {
  MssOptions o;
  o.radial_springs = false;
  o.torsion_springs = false;
  const MssModel model(two_region_box(), two_regions(), o);
  EXPECT_EQ(model.num_radial_tets(), 0);
  EXPECT_EQ(model.num_angle_springs(), 0);
  const Eigen::VectorXd x = perturbed(model, 0.3, 3);
  EXPECT_EQ(model.term_energy(x, Term::torsion, 0), 0.0);
  EXPECT_NEAR(model.energy(x),
              model.term_energy(x, Term::main, 0) + model.term_energy(x, Term::main, 1),
              1e-12 * model.energy(x));
}

// Default K_d (5.11): 2 zeta omega_1 m_mean, omega_1 = (pi / L_m) sqrt(E/rho) of the cylinder.
TEST(MssModel, DefaultDampingIsTheFirstAxialModeRate) {
  mesh::RegionMaterials mat;
  mat.fallback = {3.22, 0.4557, 1038.0};
  const MssModel model(box_mesh(2, 2, 2, 10.0, 5.0, 10.0), mat);
  const double omega1 = kPi / 5.0 * std::sqrt(3.22 / (1038.0e-12));
  EXPECT_NEAR(model.damping_n_s_per_mm(), 2.0 * omega1 * model.node_masses_t().mean(),
              1e-12 * model.damping_n_s_per_mm());
  MssOptions o;
  o.damping_n_s_per_mm = 0.25;
  EXPECT_EQ(MssModel(box_mesh(1, 1, 1, 1, 1, 1), mat, o).damping_n_s_per_mm(), 0.25);
}

TEST(MssModel, BadInputIsRefused) {
  mesh::TetMesh m = box_mesh(1, 1, 1, 1.0, 1.0, 1.0);
  mesh::RegionMaterials bad;
  bad.fallback = {-1.0, 0.3, 1000.0};
  EXPECT_THROW(MssModel(m, bad), std::invalid_argument);
  bad.fallback = {1.0, 0.3, 0.0};
  EXPECT_THROW(MssModel(m, bad), std::invalid_argument);
  MssOptions o;
  o.radial_factor = 0.0;
  EXPECT_THROW(MssModel(m, two_regions(), o), std::invalid_argument);
  o = MssOptions();
  o.damping_n_s_per_mm = std::nan("");
  EXPECT_THROW(MssModel(m, two_regions(), o), std::invalid_argument);
  // A vertex no tetrahedron uses has no mass.
  mesh::TetMesh orphan = m;
  orphan.V.conservativeResize(m.V.rows() + 1, 3);
  orphan.V.row(m.V.rows()) << 5.0, 5.0, 5.0;
  orphan.surface.conservativeResize(m.V.rows() + 1);
  orphan.surface(m.V.rows()) = 0;
  EXPECT_THROW(MssModel(orphan, two_regions()), std::invalid_argument);
  const MssModel ok(m, two_regions());
  EXPECT_THROW(ok.energy(Eigen::VectorXd::Zero(5)), std::invalid_argument);
}

}  // namespace
}  // namespace spinesim::mss

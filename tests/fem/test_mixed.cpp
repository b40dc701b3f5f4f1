// Taylor–Hood P2–P1 (mixed.hpp): patch test, and convergence on Lamé's pressurised thick sphere
// at nu = 0.4999, against the displacement-only P2 element that locks there.
#include "spinesim/fem/assembly.hpp"
#include "spinesim/fem/dirichlet.hpp"
#include "spinesim/fem/fe_space.hpp"
#include "spinesim/fem/mixed.hpp"
#include "spinesim/fem/quadrature.hpp"
#include "spinesim/mesh/box_mesh.hpp"

#include <gtest/gtest.h>
#include <Eigen/Geometry>

#include <cmath>
#include <cstdio>
#include <functional>
#include <utility>
#include <vector>

using namespace spinesim;
using namespace spinesim::fem;

namespace {

using Field = std::function<Eigen::Vector3d(const Eigen::Vector3d&)>;

bool on_cube_boundary(const Eigen::Vector3d& x) {
  return (x.array().abs() < 1e-12).any() || ((x.array() - 1).abs() < 1e-12).any();
}

struct MixedSolution {
  Eigen::VectorXd u, p;  // 3N displacements, #P mean stresses
  FeSpace space;
  PressureSpace pressure;
};

/// Solves the mixed problem on `m` with u = exact on the cube's boundary and no body force.
MixedSolution solve_mixed(const mesh::TetMesh& m, const mesh::RegionMaterials& mat,
                          const Field& exact, const ElementFibres* fibres = nullptr) {
  MixedSolution s;
  s.space = make_fe_space(m, 2);
  s.pressure = make_pressure_space(m.T, m.region);
  const Eigen::SparseMatrix<double> K = assemble_mixed(s.space, s.pressure, m.region, mat, fibres);
  std::vector<Eigen::Index> fixed;
  std::vector<double> values;
  for (Eigen::Index i = 0; i < s.space.num_nodes(); ++i) {
    const Eigen::Vector3d x = s.space.X.row(i).transpose();
    if (!on_cube_boundary(x)) continue;
    const Eigen::Vector3d ue = exact(x);
    for (int d = 0; d < 3; ++d) fixed.push_back(3 * i + d), values.push_back(ue(d));
  }
  const Eigen::VectorXd x =
      solve_dirichlet(K, Eigen::VectorXd::Zero(K.rows()), fixed,
                      Eigen::Map<const Eigen::VectorXd>(values.data(), Eigen::Index(values.size())),
                      Factorization::ldlt);
  const Eigen::Index nu = 3 * s.space.num_nodes();
  s.u = x.head(nu);
  s.p = x.tail(K.rows() - nu);
  return s;
}

TEST(MixedPatch, LinearFieldAndConstantPressureAreExactOnADistortedMesh) {
  mesh::TetMesh m = mesh::unit_cube_mesh(4);
  mesh::perturb_interior(m, 0.25, 0.15);
  mesh::validate(m);
  for (double nu : {0.3, 0.4999, 0.4999999}) {
    mesh::RegionMaterials mat;
    mat.fallback = {3.0, nu, 1000.0};
    Eigen::Matrix3d G;
    G << 0.01, 0.02, -0.03, 0.005, -0.01, 0.015, 0.02, 0.01, 0.03;
    const Eigen::Vector3d b(0.1, -0.2, 0.05);
    const Field exact = [&](const Eigen::Vector3d& x) -> Eigen::Vector3d { return G * x + b; };
    const MixedSolution s = solve_mixed(m, mat, exact);
    double u_err = 0;
    for (Eigen::Index i = 0; i < s.space.num_nodes(); ++i)
      u_err = std::max(
          u_err,
          (s.u.segment<3>(3 * i) - exact(s.space.X.row(i).transpose())).lpNorm<Eigen::Infinity>());
    const double p_exact = bulk_modulus_mpa(mat.fallback) * G.trace();
    const double p_err = (s.p.array() - p_exact).abs().maxCoeff();
    // Round-off grows with the system's conditioning, kappa/mu = 5e6 at nu = 0.4999999.
    const double tol = nu < 0.49999 ? 1e-11 : 1e-9;
    EXPECT_LT(u_err, tol) << "nu " << nu;
    EXPECT_LT(p_err, 1e-9 * std::max(1.0, std::abs(p_exact))) << "nu " << nu;
  }
}

// Lamé: a thick sphere a < r < b under internal pressure P has u = (A r + B / r^2) e_r with
//   A = P a^3 (1 - 2 nu) / (E (b^3 - a^3)),  B = P a^3 b^3 (1 + nu) / (2 E (b^3 - a^3)),
// and a constant mean stress sigma_m = P a^3 / (b^3 - a^3), whatever nu (Timoshenko & Goodier,
// Theory of Elasticity, 3rd ed., sec. 141). The unit cube sits inside the shell (centre x0
// below the corner): the exact field is imposed on its boundary.
struct LameSphere {
  double E = 1.0, nu = 0.4999, P = 0.2, a = 0.5, b = 3.0;
  Eigen::Vector3d x0{-0.5, -0.5, -0.5};

  Eigen::Vector3d u(const Eigen::Vector3d& x) const {
    const double k = P * a * a * a / (b * b * b - a * a * a);
    const double A = k * (1 - 2 * nu) / E, B = k * b * b * b * (1 + nu) / (2 * E);
    const Eigen::Vector3d r = x - x0;
    return A * r + B * r / std::pow(r.norm(), 3);
  }
  double mean_stress() const { return P * a * a * a / (b * b * b - a * a * a); }
};

struct Errors {
  double u = 0, p = 0;
};

Errors mixed_errors(int n, const LameSphere& lame) {
  const mesh::TetMesh m = mesh::unit_cube_mesh(n);
  mesh::RegionMaterials mat;
  mat.fallback = {lame.E, lame.nu, 1000.0};
  const Field exact = [&](const Eigen::Vector3d& x) { return lame.u(x); };
  const MixedSolution s = solve_mixed(m, mat, exact);
  Errors e;
  e.u = l2_error(s.space, s.u, exact, 6);
  e.p = pressure_l2_error(s.space, s.pressure, s.p,
                          [&](const Eigen::Vector3d&) { return lame.mean_stress(); });
  return e;
}

double order(double e_coarse, double e_fine) { return std::log2(e_coarse / e_fine); }

/// Prints the errors on 2³, 4³, 8³ meshes and their orders.
void print_orders(const char* label, const Errors& e2, const Errors& e4, const Errors& e8) {
  std::printf(
      "%s: u L2 %.3e %.3e %.3e (orders %.2f %.2f); p L2 %.3e %.3e %.3e (orders %.2f %.2f)\n", label,
      e2.u, e4.u, e8.u, order(e2.u, e4.u), order(e4.u, e8.u), e2.p, e4.p, e8.p, order(e2.p, e4.p),
      order(e4.p, e8.p));
}

TEST(MixedConvergence, LameSphereAtNuPoint4999IsThirdOrderInU) {
  LameSphere lame;
  const Errors e2 = mixed_errors(2, lame), e4 = mixed_errors(4, lame), e8 = mixed_errors(8, lame);
  print_orders("Lame sphere, Taylor-Hood, nu = 0.4999", e2, e4, e8);
  EXPECT_GT(order(e4.u, e8.u), 2.8);
  // The exact mean stress is constant (in the P1 space): its error follows u's, at least order 2.
  EXPECT_GT(order(e4.p, e8.p), 1.8);
}

TEST(MixedConvergence, ErrorDoesNotGrowAsNuApproachesOneHalf) {
  // Locking-free: the same mesh gives the same accuracy at nu = 0.3, 0.4999 and 0.4999999.
  LameSphere lame;
  lame.nu = 0.3;
  const Errors compressible = mixed_errors(4, lame);
  for (double nu : {0.4999, 0.4999999}) {
    lame.nu = nu;
    const Errors e = mixed_errors(4, lame);
    std::printf("n = 4, nu = %.7f: u L2 %.3e (nu = 0.3: %.3e)\n", nu, e.u, compressible.u);
    EXPECT_LT(e.u, 3.0 * compressible.u) << "nu " << nu;
  }
}

// A manufactured nearly incompressible field with a varying pressure: u = sum_j c_j sin(k_j.x +
// phi_j), divergence-free modes (c_j . k_j = 0) of order one plus dilatational modes
// (c_j || k_j) scaled by 1/kappa, so that p = kappa div u stays finite as nu -> 0.5. With
// -div sigma = -mu lap u - (lambda + mu) grad div u, the body force is
//   f = sum_j [mu |k_j|^2 c_j + (lambda + mu) (c_j . k_j) k_j] sin(k_j.x + phi_j).
struct NearlyIncompressible {
  struct Mode {
    Eigen::Vector3d c, k;
    double phase;
  };
  std::vector<Mode> modes;
  double lambda = 0, mu = 0, kappa = 0;

  explicit NearlyIncompressible(const mesh::IsotropicMaterial& m)
      : lambda(m.lame_lambda_mpa()), mu(m.shear_modulus_mpa()), kappa(bulk_modulus_mpa(m)) {
    const Eigen::Vector3d k1(2.0, 1.0, 0.5), k2(-1.0, 1.5, 1.0), k3(0.5, -0.7, 2.2);
    modes.push_back({0.01 * k1.cross(Eigen::Vector3d(0, 0, 1)).normalized(), k1, 0.3});
    modes.push_back({0.01 * k2.cross(Eigen::Vector3d(1, 0, 0)).normalized(), k2, -0.4});
    modes.push_back({(0.02 * mu / kappa) * k3.normalized(), k3, 1.1});  // p = O(0.02 mu)
  }
  Eigen::Vector3d u(const Eigen::Vector3d& x) const {
    Eigen::Vector3d v = Eigen::Vector3d::Zero();
    for (const Mode& m : modes) v += m.c * std::sin(m.k.dot(x) + m.phase);
    return v;
  }
  Eigen::Vector3d body_force(const Eigen::Vector3d& x) const {
    Eigen::Vector3d f = Eigen::Vector3d::Zero();
    for (const Mode& m : modes)
      f += (mu * m.k.squaredNorm() * m.c + (lambda + mu) * m.c.dot(m.k) * m.k) *
           std::sin(m.k.dot(x) + m.phase);
    return f;
  }
  double mean_stress(const Eigen::Vector3d& x) const {
    double div = 0;
    for (const Mode& m : modes) div += m.c.dot(m.k) * std::cos(m.k.dot(x) + m.phase);
    return kappa * div;
  }
};

std::vector<std::pair<Eigen::Index, double>> cube_boundary_values(const FeSpace& space,
                                                                  const Field& exact) {
  std::vector<std::pair<Eigen::Index, double>> fixed;
  for (Eigen::Index i = 0; i < space.num_nodes(); ++i) {
    const Eigen::Vector3d x = space.X.row(i).transpose();
    if (!on_cube_boundary(x)) continue;
    const Eigen::Vector3d ue = exact(x);
    for (int d = 0; d < 3; ++d) fixed.emplace_back(3 * i + d, ue(d));
  }
  return fixed;
}

/// u and p L² errors of the manufactured field on an n^3 cube, mixed or displacement-only P2
/// (whose mean stress is kappa div u_h).
Errors manufactured_errors(int n, double nu, bool mixed) {
  const mesh::TetMesh m = mesh::unit_cube_mesh(n);
  mesh::RegionMaterials mat;
  mat.fallback = {1.0, nu, 1000.0};
  const NearlyIncompressible ms(mat.fallback);
  const FeSpace space = make_fe_space(m, 2);
  const PressureSpace pressure = make_pressure_space(m.T, m.region);
  const Eigen::SparseMatrix<double> K = mixed ? assemble_mixed(space, pressure, m.region, mat)
                                              : assemble_stiffness(space, m.region, mat);
  Eigen::VectorXd f = Eigen::VectorXd::Zero(K.rows());
  f.head(3 * space.num_nodes()) = assemble_body_force(
      space, [&](const Eigen::Vector3d& x) { return ms.body_force(x); }, 5);
  const Field exact = [&](const Eigen::Vector3d& x) { return ms.u(x); };
  std::vector<Eigen::Index> dofs;
  std::vector<double> values;
  for (const auto& [dof, v] : cube_boundary_values(space, exact))
    dofs.push_back(dof), values.push_back(v);
  const Eigen::VectorXd x = solve_dirichlet(
      K, f, dofs, Eigen::Map<const Eigen::VectorXd>(values.data(), Eigen::Index(values.size())),
      mixed ? Factorization::ldlt : Factorization::llt);
  const Eigen::VectorXd u = x.head(3 * space.num_nodes());
  Errors e;
  e.u = l2_error(space, u, exact, 6);
  const auto p_exact = [&](const Eigen::Vector3d& y) { return ms.mean_stress(y); };
  if (mixed) {
    // With u prescribed on the whole boundary the constant pressure mode is fixed only through
    // kappa times the boundary flux of the interpolated data (kappa = 1.7e6 at nu = 0.4999999),
    // so, as for Stokes flow, the pressure is compared up to its mean.
    const Eigen::VectorXd ph = x.tail(pressure.size());
    double mean_diff = 0, volume = 0;
    for (Eigen::Index t = 0; t < space.elements.rows(); ++t) {
      TetVertices X;
      for (int a = 0; a < 4; ++a) X.row(a) = space.X.row(space.elements(t, a));
      double vol = 0;
      barycentric_gradients(X, vol);
      const TetQuadrature q = tet_rule_collapsed(4);
      for (Eigen::Index k = 0; k < q.weights.size(); ++k) {
        const Eigen::Vector4d L = q.barycentric.row(k).transpose();
        double v = -p_exact(X.transpose() * L);
        for (int a = 0; a < 4; ++a) v += L(a) * ph(pressure.elements(t, a));
        mean_diff += q.weights(k) * vol * v;
      }
      volume += vol;
    }
    mean_diff /= volume;
    e.p = pressure_l2_error(space, pressure, ph.array() - mean_diff, p_exact);
    return e;
  }
  // Displacement form: p_h = kappa div u_h, integrated with the collapsed rule.
  const TetQuadrature q = tet_rule_collapsed(6);
  double sum = 0;
  for (Eigen::Index t = 0; t < space.elements.rows(); ++t) {
    TetVertices X;
    for (int a = 0; a < 4; ++a) X.row(a) = space.X.row(space.elements(t, a));
    double vol = 0;
    const Eigen::Matrix<double, 4, 3> gL = barycentric_gradients(X, vol);
    for (Eigen::Index k = 0; k < q.weights.size(); ++k) {
      const Eigen::Vector4d L = q.barycentric.row(k).transpose();
      const Eigen::MatrixX3d G = shape_gradients(2, gL, L);
      double div = 0;
      for (int a = 0; a < 10; ++a) div += G.row(a).dot(u.segment<3>(3 * space.elements(t, a)));
      sum += q.weights(k) * vol * std::pow(ms.kappa * div - p_exact(X.transpose() * L), 2);
    }
  }
  e.p = std::sqrt(sum);
  return e;
}

TEST(MixedConvergence, VaryingPressureAtNuPoint4999IsThirdOrderInUSecondInP) {
  const Errors e2 = manufactured_errors(2, 0.4999, true), e4 = manufactured_errors(4, 0.4999, true),
               e8 = manufactured_errors(8, 0.4999, true);
  print_orders("manufactured, Taylor-Hood, nu = 0.4999", e2, e4, e8);
  EXPECT_GT(order(e4.u, e8.u), 2.7);
  EXPECT_GT(order(e4.p, e8.p), 1.8);
}

TEST(MixedConvergence, DisplacementOnlyP2LocksWhereTaylorHoodDoesNot) {
  // Locking: on a fixed mesh the displacement-only error grows as nu -> 0.5; the mixed one
  // does not.
  const int n = 4;
  const Errors d3 = manufactured_errors(n, 0.3, false),
               d5 = manufactured_errors(n, 0.4999999, false);
  const Errors m3 = manufactured_errors(n, 0.3, true), m5 = manufactured_errors(n, 0.4999999, true);
  std::printf(
      "n = 4, u L2 error at nu = 0.3 / 0.4999999: displacement P2 %.3e / %.3e, "
      "Taylor-Hood %.3e / %.3e; p L2: displacement P2 %.3e / %.3e, Taylor-Hood %.3e / "
      "%.3e\n",
      d3.u, d5.u, m3.u, m5.u, d3.p, d5.p, m3.p, m5.p);
  EXPECT_LT(m5.u, 1.5 * m3.u);
  EXPECT_LT(m5.p, 1.5 * m3.p);
  EXPECT_GT(d5.u, 2.0 * d3.u);
  EXPECT_GT(d5.p, 100.0 * d3.p);
}

}  // namespace

// Per-tet stress, strain and energy fields of a linear solution; the definitions are in
// stress_fields.hpp.
#include "spinesim/fem/stress_fields.hpp"

#include "spinesim/fem/elasticity.hpp"
#include "spinesim/fem/fe_space.hpp"
#include "spinesim/fem/mixed.hpp"
#include "spinesim/fem/quadrature.hpp"

#include <Eigen/Eigenvalues>

#include <cmath>
#include <stdexcept>
#include <string>

namespace spinesim::fem {
namespace {

using Vector6 = Eigen::Matrix<double, 6, 1>;

/// A symmetric tensor's components in ParaView's order (xx, yy, zz, xy, yz, xz).
Vector6 paraview_components(const Eigen::Matrix3d& t) {
  Vector6 v;
  v << t(0, 0), t(1, 1), t(2, 2), t(0, 1), t(1, 2), t(0, 2);
  return v;
}

/// sym grad u at barycentric point L of a tet with nodal displacements ue (npe×3).
Eigen::Matrix3d strain_at(int order, const Eigen::Matrix<double, 4, 3>& grad_L,
                          const Eigen::MatrixX3d& ue, const Eigen::Vector4d& L) {
  const Eigen::MatrixX3d G = shape_gradients(order, grad_L, L);
  const Eigen::Matrix3d grad_u = ue.transpose() * G;  // (i, j) = d u_i / d x_j
  return 0.5 * (grad_u + grad_u.transpose());
}

Eigen::Matrix3d deviator(const Eigen::Matrix3d& t) {
  return t - t.trace() / 3.0 * Eigen::Matrix3d::Identity();
}

/// The tet's two fibre families: direction and stiffness k (0 when the tet has none).
struct Families {
  Eigen::Vector3d a[2];
  double k = 0;
};

Families families_of(const ElementFibres& fibres, Eigen::Index t) {
  Families f;
  if (fibres.empty() || !(fibres.stiffness_mpa(t) > 0)) return f;
  f.a[0] = fibres.direction_1.row(t).transpose();
  f.a[1] = fibres.direction_2.row(t).transpose();
  f.k = fibres.stiffness_mpa(t);
  return f;
}

/// The fibres' stress and energy density at strain eps.
double add_fibres(const Families& f, const Eigen::Matrix3d& eps, Eigen::Matrix3d& stress) {
  double energy = 0;
  if (f.k == 0) return energy;
  for (const Eigen::Vector3d& a : f.a) {
    const double e = a.dot(eps * a);
    stress += f.k * e * a * a.transpose();
    energy += 0.5 * f.k * e * e;
  }
  return energy;
}

void check_sizes(const mesh::TetMesh& mesh, const FeSpace& space, const ElementFibres& fibres,
                 const Eigen::MatrixX3d& u, const Eigen::MatrixX4d* p) {
  const std::string who = "element_fields: ";
  if (u.rows() != space.num_nodes())
    throw std::invalid_argument(who + "displacements for " + std::to_string(u.rows()) +
                                " nodes, the P" + std::to_string(space.order) + " mesh has " +
                                std::to_string(space.num_nodes()));
  if (!fibres.empty() && fibres.stiffness_mpa.size() != mesh.num_tets())
    throw std::invalid_argument(who + "the fibre field does not match the mesh");
  if (p && p->rows() != mesh.num_tets())
    throw std::invalid_argument(who + "mean stresses for " + std::to_string(p->rows()) +
                                " tets, the mesh has " + std::to_string(mesh.num_tets()));
}

}  // namespace

void principal(const Eigen::Matrix3d& eps, Eigen::Vector3d& values, Eigen::Matrix3d& directions) {
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> es(eps);
  for (int k = 0; k < 3; ++k) {
    values(k) = es.eigenvalues()(2 - k);
    Eigen::Vector3d d = es.eigenvectors().col(2 - k);
    Eigen::Index big = 0;
    d.cwiseAbs().maxCoeff(&big);
    directions.col(k) = d(big) < 0 ? Eigen::Vector3d(-d) : d;
  }
}

double von_mises(const Eigen::Matrix<double, 6, 1>& s) {
  const double a = s(0) - s(1), b = s(1) - s(2), c = s(2) - s(0);
  return std::sqrt(0.5 * (a * a + b * b + c * c) + 3.0 * (s(3) * s(3) + s(4) * s(4) + s(5) * s(5)));
}

ElementFields element_fields(const mesh::TetMesh& mesh, const mesh::RegionMaterials& materials,
                             const ElementFibres& fibres, int order,
                             const Eigen::MatrixX3d& node_displacement_mm,
                             const Eigen::MatrixX4d* mean_stress_mpa) {
  const FeSpace space = make_fe_space(mesh, order);
  check_sizes(mesh, space, fibres, node_displacement_mm, mean_stress_mpa);
  const Eigen::Index nt = mesh.num_tets();
  ElementFields f;
  f.strain.resize(nt, 6);
  f.stress_mpa.resize(nt, 6);
  f.von_mises_mpa.resize(nt);
  f.pressure_mpa.resize(nt);
  f.principal_strain.resize(nt, 3);
  f.principal_strain_directions.resize(nt, 9);
  f.fibre_stretch.setZero(nt, 2);
  f.fibre_stress_mpa.setZero(nt, 2);
  f.strain_energy_density_mpa.resize(nt);
  const TetQuadrature rule = tet_rule_degree2();
  const Eigen::Vector4d centroid = Eigen::Vector4d::Constant(0.25);
  const int npe = space.nodes_per_element();
  TetVertices X;
  Eigen::MatrixX3d ue(npe, 3);
  for (Eigen::Index t = 0; t < nt; ++t) {
    for (int a = 0; a < 4; ++a) X.row(a) = mesh.V.row(mesh.T(t, a));
    for (int a = 0; a < npe; ++a) ue.row(a) = node_displacement_mm.row(space.elements(t, a));
    double volume = 0;
    const Eigen::Matrix<double, 4, 3> grad_L = barycentric_gradients(X, volume);
    const mesh::IsotropicMaterial& m = materials.at(mesh.region(t));
    const double lambda = m.lame_lambda_mpa(), mu = m.shear_modulus_mpa();
    const Families fam = families_of(fibres, t);
    // The stress and energy density at a point with strain eps and mean stress p (mixed).
    const auto stress_and_energy = [&](const Eigen::Matrix3d& eps, double p, double& energy) {
      Eigen::Matrix3d s;
      if (mean_stress_mpa) {
        const double kappa = bulk_modulus_mpa(m);
        s = 2 * mu * deviator(eps) + p * Eigen::Matrix3d::Identity();
        energy = mu * deviator(eps).squaredNorm() + (std::isfinite(kappa) ? p * p / (2 * kappa) : 0);
      } else {
        s = lambda * eps.trace() * Eigen::Matrix3d::Identity() + 2 * mu * eps;
        energy = 0.5 * (eps.array() * s.array()).sum();
      }
      energy += add_fibres(fam, eps, s);
      return s;
    };
    const auto p_at = [&](const Eigen::Vector4d& L) {
      return mean_stress_mpa ? L.dot(mean_stress_mpa->row(t).transpose()) : 0.0;
    };
    // 1. Strain and stress at the centroid: the tet's mean.
    const Eigen::Matrix3d eps = strain_at(order, grad_L, ue, centroid);
    double unused = 0;
    const Eigen::Matrix3d sigma = stress_and_energy(eps, p_at(centroid), unused);
    f.strain.row(t) = paraview_components(eps).transpose();
    f.stress_mpa.row(t) = paraview_components(sigma).transpose();
    f.von_mises_mpa(t) = von_mises(paraview_components(sigma));
    f.pressure_mpa(t) = -sigma.trace() / 3.0;
    Eigen::Vector3d values;
    Eigen::Matrix3d directions;
    principal(eps, values, directions);
    f.principal_strain.row(t) = values.transpose();
    for (int k = 0; k < 3; ++k) f.principal_strain_directions.block<1, 3>(t, 3 * k) = directions.col(k).transpose();
    for (int k = 0; fam.k > 0 && k < 2; ++k) {
      const double e = fam.a[k].dot(eps * fam.a[k]);
      f.fibre_stretch(t, k) = 1.0 + e;
      f.fibre_stress_mpa(t, k) = fam.k * e;
    }
    // 2. The energy density's mean, by the degree-2 rule (exact: it is quadratic).
    double w = 0;
    for (Eigen::Index q = 0; q < rule.weights.size(); ++q) {
      const Eigen::Vector4d L = rule.barycentric.row(q).transpose();
      double energy = 0;
      stress_and_energy(strain_at(order, grad_L, ue, L), p_at(L), energy);
      w += rule.weights(q) * energy;
    }
    f.strain_energy_density_mpa(t) = w;
  }
  return f;
}

}  // namespace spinesim::fem

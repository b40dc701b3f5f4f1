// Per-tet fields of a nonlinear disc state; the definitions are in nonlinear_fields.hpp.
#include "spinesim/fem/nonlinear_fields.hpp"

#include "spinesim/fem/elasticity.hpp"
#include "spinesim/fem/quadrature.hpp"
#include "spinesim/fem/stress_fields.hpp"

#include <Eigen/Eigenvalues>
#include <Eigen/LU>

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace spinesim::fem {
namespace {

/// (xx, yy, zz, xy, yz, xz): the order of the linear fields (stress_fields.hpp).
Vector6d paraview_order(const Eigen::Matrix3d& T) {
  Vector6d v;
  v << T(0, 0), T(1, 1), T(2, 2), T(0, 1), T(1, 2), T(0, 2);
  return v;
}

/// The P1 nodal volume ratios of the nodal-average form at each tet's four vertices (#T×4):
/// J = v_n / V_n on the node's share of the tets of the same bulk modulus (the body keeps one
/// nodal volume per node and distinct D1, so a nucleus–annulus border node has two).
Eigen::MatrixX4d nodal_volume_ratios(const FeSpace& space,
                                     const std::vector<FibreHyperelastic>& materials,
                                     const Eigen::VectorXd& u) {
  std::vector<double> d1s;
  std::vector<int> group(materials.size());
  for (std::size_t t = 0; t < materials.size(); ++t) {
    const auto it = std::find(d1s.begin(), d1s.end(), materials[t].d1_per_mpa);
    group[t] = int(it - d1s.begin());
    if (it == d1s.end()) d1s.push_back(materials[t].d1_per_mpa);
  }
  const Eigen::Index groups = Eigen::Index(d1s.size());
  Eigen::VectorXd V = Eigen::VectorXd::Zero(space.num_nodes() * groups), v = V;
  const auto slot = [&](Eigen::Index t, int a) {
    return space.elements(t, a) * groups + group[std::size_t(t)];
  };
  for (Eigen::Index t = 0; t < space.elements.rows(); ++t) {
    Eigen::Matrix3d D0, D;
    for (int k = 0; k < 3; ++k) {
      const Eigen::Index a = space.elements(t, k + 1), o = space.elements(t, 0);
      D0.col(k) = (space.X.row(a) - space.X.row(o)).transpose();
      D.col(k) = D0.col(k) + u.segment<3>(3 * a) - u.segment<3>(3 * o);
    }
    for (int a = 0; a < 4; ++a) {
      V(slot(t, a)) += D0.determinant() / 24.0;
      v(slot(t, a)) += D.determinant() / 24.0;
    }
  }
  Eigen::MatrixX4d J(space.elements.rows(), 4);
  for (Eigen::Index t = 0; t < space.elements.rows(); ++t)
    for (int a = 0; a < 4; ++a) J(t, a) = v(slot(t, a)) / V(slot(t, a));
  return J;
}

struct ElementSums {
  Eigen::Matrix3d isochoric_virial = Eigen::Matrix3d::Zero();  ///< ∫ F S̄ Fᵀ dV₀
  Eigen::Matrix3d C = Eigen::Matrix3d::Zero();                 ///< ∫ C dV₀
  double pointwise_pressure_virial = 0;                        ///< ∫ U'(J) J dV₀
  double pointwise_energy = 0, isochoric_energy = 0;           ///< ∫ U dV₀, ∫ W̄ dV₀
  double V0 = 0, v = 0;
  Eigen::Vector2d stretch = Eigen::Vector2d::Zero();           ///< ∫ |F a_f| dV₀
  Eigen::Matrix<double, 3, 2> fibre_now = Eigen::Matrix<double, 3, 2>::Zero();  ///< ∫ F a_f dV₀
};

ElementSums integrate(const FeSpace& space, Eigen::Index t, const Eigen::VectorXd& u,
                      const FibreHyperelastic& m) {
  const int npe = space.nodes_per_element();
  TetVertices X;
  for (int a = 0; a < 4; ++a) X.row(a) = space.X.row(space.elements(t, a));
  double V0 = 0;
  const Eigen::Matrix<double, 4, 3> gL = barycentric_gradients(X, V0);
  const TetQuadrature& q = element_rule(space.order);
  ElementSums s;
  for (Eigen::Index k = 0; k < q.weights.size(); ++k) {
    const Eigen::MatrixX3d G = shape_gradients(space.order, gL, q.barycentric.row(k).transpose());
    Eigen::Matrix3d F = Eigen::Matrix3d::Identity();
    for (int a = 0; a < npe; ++a)
      F += u.segment<3>(3 * space.elements(t, a)) * G.row(a);
    const double J = F.determinant(), dV = q.weights(k) * V0;
    if (!(J > 0)) throw std::invalid_argument("nonlinear fields: an inverted element");
    const Eigen::Matrix3d C = F.transpose() * F;
    const MaterialPointState iso = isochoric_point(C, m, false);
    const VolumetricEnergy U = volumetric_energy(J, m);
    s.isochoric_virial += dV * F * iso.S * F.transpose();
    s.C += dV * C;
    s.pointwise_pressure_virial += dV * U.first * J;
    s.pointwise_energy += dV * U.value;
    s.isochoric_energy += dV * iso.energy;
    s.V0 += dV;
    s.v += dV * J;
    for (std::size_t f = 0; f < std::min<std::size_t>(2, m.fibres.size()); ++f) {
      const Eigen::Vector3d Fa = F * m.fibres[f].direction;
      s.stretch(Eigen::Index(f)) += dV * Fa.norm();
      s.fibre_now.col(Eigen::Index(f)) += dV * Fa;
    }
  }
  return s;
}

}  // namespace

NonlinearElementFields nonlinear_element_fields(const HyperelasticBody& body,
                                                const Eigen::VectorXd& u) {
  const FeSpace& space = body.space();
  if (u.size() != 3 * space.num_nodes())
    throw std::invalid_argument("nonlinear fields: wrong displacement size");
  const Eigen::Index nt = space.elements.rows();
  const bool nodal = body.form() == VolumetricForm::nodal_average;
  const Eigen::MatrixX4d Jn =
      nodal ? nodal_volume_ratios(space, body.materials(), u) : Eigen::MatrixX4d();
  NonlinearElementFields f;
  f.cauchy_stress_mpa.resize(nt, 6);
  f.green_lagrange_strain.resize(nt, 6);
  f.von_mises_mpa.resize(nt);
  f.pressure_mpa.resize(nt);
  f.principal_stretch.resize(nt, 3);
  f.principal_stretch_directions.resize(nt, 9);
  f.fibre_stretch = Eigen::MatrixX2d::Zero(nt, 2);
  f.fibre_stress_mpa = Eigen::MatrixX2d::Zero(nt, 2);
  f.volume_ratio.resize(nt);
  f.strain_energy_density_mpa.resize(nt);
  for (Eigen::Index t = 0; t < nt; ++t) {
    const FibreHyperelastic& m = body.materials()[std::size_t(t)];
    const ElementSums s = integrate(space, t, u, m);
    // The volumetric part as the form takes it: ∫ U'·J dV₀ and ∫ U dV₀ over the tet.
    double pressure_virial = s.pointwise_pressure_virial, volumetric_energy_sum = s.pointwise_energy;
    if (body.form() == VolumetricForm::mean_dilatation) {
      const VolumetricEnergy U = volumetric_energy(s.v / s.V0, m);
      pressure_virial = U.first * s.v;
      volumetric_energy_sum = U.value * s.V0;
    } else if (nodal) {
      double first = 0, value = 0;
      for (int a = 0; a < 4; ++a) {
        const VolumetricEnergy U = volumetric_energy(Jn(t, a), m);
        first += 0.25 * U.first;
        value += 0.25 * U.value;
      }
      pressure_virial = first * s.v;
      volumetric_energy_sum = value * s.V0;
    }
    const Eigen::Matrix3d sigma =
        (s.isochoric_virial + pressure_virial * Eigen::Matrix3d::Identity()) / s.v;
    const Vector6d sv = paraview_order(sigma);
    f.cauchy_stress_mpa.row(t) = sv.transpose();
    f.von_mises_mpa(t) = von_mises(sv);  // the linear fields' order, which this is
    f.pressure_mpa(t) = -sigma.trace() / 3;
    const Eigen::Matrix3d C = s.C / s.V0;
    f.green_lagrange_strain.row(t) =
        paraview_order(0.5 * (C - Eigen::Matrix3d::Identity())).transpose();
    Eigen::Vector3d ev;
    Eigen::Matrix3d axes;
    principal(C, ev, axes);
    f.principal_stretch.row(t) = ev.cwiseSqrt().transpose();
    for (int k = 0; k < 3; ++k)
      f.principal_stretch_directions.block<1, 3>(t, 3 * k) = axes.col(k).transpose();
    for (Eigen::Index k = 0; k < Eigen::Index(std::min<std::size_t>(2, m.fibres.size())); ++k) {
      f.fibre_stretch(t, k) = s.stretch(k) / s.V0;
      const Eigen::Vector3d a = s.fibre_now.col(k).normalized();
      f.fibre_stress_mpa(t, k) = a.dot(sigma * a);
    }
    f.volume_ratio(t) = s.v / s.V0;
    f.strain_energy_density_mpa(t) = (s.isochoric_energy + volumetric_energy_sum) / s.V0;
  }
  return f;
}

}  // namespace spinesim::fem

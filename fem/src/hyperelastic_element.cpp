#include "spinesim/fem/hyperelastic_element.hpp"

#include "spinesim/fem/quadrature.hpp"

#include <Eigen/LU>

#include <cmath>
#include <limits>
#include <stdexcept>
#include <vector>

namespace spinesim::fem {

namespace {

/// B_a (6×3) of one node at deformation gradient F, gradient g = ∇N_a.
Eigen::Matrix<double, 6, 3> strain_displacement(const Eigen::Matrix3d& F,
                                                const Eigen::Vector3d& g) {
  Eigen::Matrix<double, 6, 3> B;
  for (int i = 0; i < 3; ++i) {
    B(0, i) = F(i, 0) * g(0);
    B(1, i) = F(i, 1) * g(1);
    B(2, i) = F(i, 2) * g(2);
    B(3, i) = F(i, 1) * g(2) + F(i, 2) * g(1);
    B(4, i) = F(i, 0) * g(2) + F(i, 2) * g(0);
    B(5, i) = F(i, 0) * g(1) + F(i, 1) * g(0);
  }
  return B;
}

}  // namespace

namespace {

/// Adds one point's ∫ Bᵀ S and ∫ Bᵀ ℂ B + (∇N_a · S ∇N_b) I (weight dV) to the element.
void add_point(const Eigen::Matrix3d& F, const Eigen::MatrixX3d& G, const MaterialPointState& p,
               double dV, bool with_tangent, HyperelasticElement& out) {
  const auto npe = int(G.rows());
  std::vector<Eigen::Matrix<double, 6, 3>> B(static_cast<std::size_t>(npe));
  const Vector6d S = to_voigt(p.S);
  for (int a = 0; a < npe; ++a) {
    B[std::size_t(a)] = strain_displacement(F, G.row(a).transpose());
    out.force.segment<3>(3 * a) += dV * B[std::size_t(a)].transpose() * S;
  }
  if (!with_tangent) return;
  for (int a = 0; a < npe; ++a) {
    const Eigen::Matrix<double, 3, 6> BaC = B[std::size_t(a)].transpose() * p.tangent;
    const Eigen::RowVector3d gSa = G.row(a) * p.S;
    for (int b = 0; b <= a; ++b) {
      Eigen::Matrix3d k = BaC * B[std::size_t(b)];
      k.diagonal().array() += gSa.dot(G.row(b));
      out.tangent.block<3, 3>(3 * a, 3 * b) += dV * k;
      if (b != a) out.tangent.block<3, 3>(3 * b, 3 * a) += dV * k.transpose();
    }
  }
}

}  // namespace

namespace {

/// The element; `pressure`: none (pointwise U), U'(J̄) of the element (mean dilatation, with
/// V₀ U(J̄) and its U'' term added), or a given value held fixed (no volumetric energy).
enum class Pressure { pointwise, mean, given };

HyperelasticElement element(int order, const TetVertices& X, const Eigen::MatrixX3d& u,
                            const FibreHyperelastic& m, bool with_tangent, Pressure pressure,
                            double given_mpa) {
  if (order != 1 && order != 2) throw std::invalid_argument("element order must be 1 or 2");
  const int npe = order == 1 ? 4 : 10;
  if (u.rows() != npe) throw std::invalid_argument("element displacements: wrong node count");
  double volume = 0;
  const Eigen::Matrix<double, 4, 3> gL = barycentric_gradients(X, volume);
  const TetQuadrature& rule = element_rule(order);
  const auto nq = rule.weights.size();

  HyperelasticElement out;
  out.force = Eigen::VectorXd::Zero(3 * npe);
  out.volume_gradient = Eigen::VectorXd::Zero(3 * npe);
  if (with_tangent) out.tangent = Eigen::MatrixXd::Zero(3 * npe, 3 * npe);
  std::vector<Eigen::MatrixX3d> G(static_cast<std::size_t>(nq));
  std::vector<Eigen::Matrix3d> F(static_cast<std::size_t>(nq));
  // The current volume v = ∫ J dV₀ and ∂v/∂u (∂J/∂u_a = J F⁻ᵀ ∇N_a).
  for (Eigen::Index q = 0; q < nq; ++q) {
    const std::size_t k = std::size_t(q);
    G[k] = shape_gradients(order, gL, rule.barycentric.row(q).transpose());
    F[k] = Eigen::Matrix3d::Identity() + u.transpose() * G[k];
    const double J = F[k].determinant(), dV = rule.weights(q) * volume;
    if (!(J > 0)) {
      ++out.inverted_points;
      continue;
    }
    out.volume_mm3 += dV * J;
    const Eigen::Matrix3d FiT = F[k].inverse().transpose();
    for (int a = 0; a < npe; ++a)
      out.volume_gradient.segment<3>(3 * a) += dV * J * FiT * G[k].row(a).transpose();
  }
  if (out.inverted_points > 0) {
    out.energy = std::numeric_limits<double>::quiet_NaN();
    return out;
  }
  const VolumetricEnergy U = volumetric_energy(out.volume_mm3 / volume, m);
  const double p_fixed = pressure == Pressure::mean ? U.first : given_mpa;
  for (Eigen::Index q = 0; q < nq; ++q) {
    const std::size_t k = std::size_t(q);
    const Eigen::Matrix3d C = F[k].transpose() * F[k];
    MaterialPointState p = pressure == Pressure::pointwise
                               ? fibre_hyperelastic_point(C, m, with_tangent)
                               : isochoric_point(C, m, with_tangent);
    if (pressure != Pressure::pointwise && std::isfinite(p.energy)) {
      const MaterialPointState v = pressure_point(C, p_fixed, with_tangent);
      p.S += v.S, p.tangent += v.tangent;
    }
    out.energy += rule.weights(q) * volume * p.energy;
    add_point(F[k], G[k], p, rule.weights(q) * volume, with_tangent, out);
  }
  if (pressure == Pressure::mean) {
    // V₀ U(J̄), J̄ = v/V₀: its gradient is in the forces above; its second derivative
    // V₀ U'' ∂J̄ ∂J̄ᵀ = U''/V₀ ∂v ∂vᵀ.
    out.energy += volume * U.value;
    if (with_tangent)
      out.tangent += U.second / volume * out.volume_gradient * out.volume_gradient.transpose();
  }
  return out;
}

}  // namespace

HyperelasticElement hyperelastic_element(int order, const TetVertices& X, const Eigen::MatrixX3d& u,
                                         const FibreHyperelastic& m, bool with_tangent,
                                         VolumetricForm form) {
  if (form == VolumetricForm::nodal_average)
    throw std::invalid_argument(
        "the nodal-average volume is a property of a body (hyperelastic_body.hpp), not of one "
        "element");
  return element(order, X, u, m, with_tangent,
                 form == VolumetricForm::pointwise ? Pressure::pointwise : Pressure::mean, 0.0);
}

HyperelasticElement hyperelastic_element_at_pressure(int order, const TetVertices& X,
                                                     const Eigen::MatrixX3d& u,
                                                     const FibreHyperelastic& m,
                                                     double pressure_mpa, bool with_tangent) {
  if (!std::isfinite(pressure_mpa)) throw std::invalid_argument("element pressure: not finite");
  return element(order, X, u, m, with_tangent, Pressure::given, pressure_mpa);
}

}  // namespace spinesim::fem

#include "spinesim/fem/mixed.hpp"

#include "spinesim/fem/quadrature.hpp"

#include <algorithm>
#include <cmath>
#include <utility>
#include <vector>

namespace spinesim::fem {

PressureSpace make_pressure_space(const Eigen::MatrixX4i& T, const Eigen::VectorXi& region) {
  std::vector<std::pair<int, int>> keys;  // (vertex, region)
  keys.reserve(std::size_t(4 * T.rows()));
  for (Eigen::Index t = 0; t < T.rows(); ++t)
    for (int a = 0; a < 4; ++a) keys.emplace_back(T(t, a), region(t));
  std::sort(keys.begin(), keys.end());
  keys.erase(std::unique(keys.begin(), keys.end()), keys.end());
  PressureSpace ps;
  ps.vertex.resize(Eigen::Index(keys.size()));
  ps.region.resize(Eigen::Index(keys.size()));
  for (std::size_t i = 0; i < keys.size(); ++i) {
    ps.vertex(Eigen::Index(i)) = keys[i].first;
    ps.region(Eigen::Index(i)) = keys[i].second;
  }
  ps.elements.resize(T.rows(), 4);
  for (Eigen::Index t = 0; t < T.rows(); ++t)
    for (int a = 0; a < 4; ++a)
      ps.elements(t, a) =
          int(std::lower_bound(keys.begin(), keys.end(), std::make_pair(T(t, a), region(t))) -
              keys.begin());
  return ps;
}

double bulk_modulus_mpa(const mesh::IsotropicMaterial& m) {
  return m.youngs_modulus_mpa / (3.0 * (1.0 - 2.0 * m.poisson_ratio));
}

void element_mixed(const TetVertices& X, double mu, double kappa, MixedElement& e) {
  element_stiffness_p2(X, -2.0 * mu / 3.0, mu, e.A);
  // B: the integrand L_i dN_b/dx_d is quadratic; the 4-point degree-2 rule is exact.
  static const double qa = 0.5854101966249685, qb = 0.1381966011250105;
  double vol = 0;
  const Eigen::Matrix<double, 4, 3> gL = barycentric_gradients(X, vol);
  e.B.setZero();
  for (int q = 0; q < 4; ++q) {
    Eigen::Vector4d L = Eigen::Vector4d::Constant(qb);
    L(q) = qa;
    const Eigen::MatrixX3d G = shape_gradients(2, gL, L);
    for (int i = 0; i < 4; ++i)
      for (int b = 0; b < 10; ++b) e.B.block<1, 3>(i, 3 * b) += (0.25 * vol * L(i)) * G.row(b);
  }
  // C = \int L_i L_j dV / kappa = V (1 + delta_ij) / (20 kappa).
  e.C.setConstant(vol / (20.0 * kappa));
  e.C.diagonal().array() *= 2.0;
}

Eigen::SparseMatrix<double> assemble_mixed(const FeSpace& p2, const PressureSpace& pressure,
                                           const Eigen::VectorXi& region,
                                           const mesh::RegionMaterials& materials,
                                           const ElementFibres* fibres) {
  const Eigen::Index nu = 3 * p2.num_nodes(), n = nu + pressure.size();
  std::vector<Eigen::Triplet<double>> trip;
  trip.reserve(std::size_t(p2.elements.rows()) * (900 + 2 * 120 + 16));
  MixedElement e;
  TetVertices X;
  for (Eigen::Index t = 0; t < p2.elements.rows(); ++t) {
    const mesh::IsotropicMaterial& m = materials.at(region(t));
    for (int a = 0; a < 4; ++a) X.row(a) = p2.X.row(p2.elements(t, a));
    element_mixed(X, m.shear_modulus_mpa(), bulk_modulus_mpa(m), e);
    if (fibres != nullptr) add_element_fibres(*fibres, t, X, e.A);
    for (int a = 0; a < 10; ++a)
      for (int da = 0; da < 3; ++da) {
        const Eigen::Index r = 3 * p2.elements(t, a) + da;
        for (int b = 0; b < 10; ++b)
          for (int db = 0; db < 3; ++db)
            trip.emplace_back(r, 3 * p2.elements(t, b) + db, e.A(3 * a + da, 3 * b + db));
        for (int i = 0; i < 4; ++i) {
          const Eigen::Index pi = nu + pressure.elements(t, i);
          trip.emplace_back(pi, r, e.B(i, 3 * a + da));
          trip.emplace_back(r, pi, e.B(i, 3 * a + da));
        }
      }
    for (int i = 0; i < 4; ++i)
      for (int j = 0; j < 4; ++j)
        trip.emplace_back(nu + pressure.elements(t, i), nu + pressure.elements(t, j), -e.C(i, j));
  }
  Eigen::SparseMatrix<double> K(n, n);
  K.setFromTriplets(trip.begin(), trip.end());
  return K;
}

double pressure_l2_error(const FeSpace& p2, const PressureSpace& pressure,
                         const Eigen::VectorXd& p_h,
                         const std::function<double(const Eigen::Vector3d&)>& p_exact, int n) {
  const TetQuadrature q = tet_rule_collapsed(n);
  double sum = 0;
  TetVertices X;
  for (Eigen::Index t = 0; t < p2.elements.rows(); ++t) {
    for (int a = 0; a < 4; ++a) X.row(a) = p2.X.row(p2.elements(t, a));
    double vol = 0;
    barycentric_gradients(X, vol);
    for (Eigen::Index k = 0; k < q.weights.size(); ++k) {
      const Eigen::Vector4d L = q.barycentric.row(k).transpose();
      double ph = 0;
      for (int a = 0; a < 4; ++a) ph += L(a) * p_h(pressure.elements(t, a));
      const double d = ph - p_exact(X.transpose() * L);
      sum += q.weights(k) * vol * d * d;
    }
  }
  return std::sqrt(sum);
}

}  // namespace spinesim::fem

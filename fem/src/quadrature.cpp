#include "spinesim/fem/quadrature.hpp"
#include "spinesim/common/constants.hpp"

#include <cmath>
#include <stdexcept>
#include <vector>

namespace spinesim::fem {

namespace {

// Gauss–Legendre nodes and weights on [0, 1], by Newton iteration on P_n (Golub–Welsch-free).
void gauss_legendre_01(int n, std::vector<double>& x, std::vector<double>& w) {
  x.assign(std::size_t(n), 0.0);
  w.assign(std::size_t(n), 0.0);
  for (int i = 0; i < n; ++i) {
    double z = std::cos(kPi * (i + 0.75) / (n + 0.5));
    double dp = 1.0;
    for (int iter = 0; iter < 100; ++iter) {
      double p0 = 1.0, p1 = z;  // Legendre recurrence: P_k
      for (int k = 2; k <= n; ++k) {
        const double pk = ((2.0 * k - 1.0) * z * p1 - (k - 1.0) * p0) / k;
        p0 = p1;
        p1 = pk;
      }
      dp = n * (z * p1 - p0) / (z * z - 1.0);
      const double dz = p1 / dp;
      z -= dz;
      if (std::abs(dz) < 1e-16) break;
    }
    x[std::size_t(i)] = 0.5 * (1.0 - z);
    w[std::size_t(i)] = 1.0 / ((1.0 - z * z) * dp * dp);  // = 2/((1-z^2)P'^2) on [-1,1], halved
  }
}

}  // namespace

TetQuadrature tet_rule_degree2() {
  const double a = 0.5854101966249685, b = 0.1381966011250105;  // (5 +- 3 sqrt 5)/20
  TetQuadrature q;
  q.barycentric.resize(4, 4);
  q.barycentric.setConstant(b);
  for (int i = 0; i < 4; ++i) q.barycentric(i, i) = a;
  q.weights = Eigen::VectorXd::Constant(4, 0.25);
  return q;
}

TetQuadrature tet_rule_collapsed(int n) {
  if (n < 1 || n > 10) throw std::invalid_argument("collapsed tet rule: n must be in 1..10");
  std::vector<double> x, w;
  gauss_legendre_01(n, x, w);
  TetQuadrature q;
  q.barycentric.resize(n * n * n, 4);
  q.weights.resize(n * n * n);
  int k = 0;
  // Duffy map of the unit cube (u,v,s) onto the unit tet: x = u, y = v(1-u), z = s(1-u)(1-v),
  // Jacobian (1-u)^2 (1-v); the reference tet has volume 1/6, hence the factor 6.
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j)
      for (int l = 0; l < n; ++l, ++k) {
        const double u = x[std::size_t(i)], v = x[std::size_t(j)], s = x[std::size_t(l)];
        const double px = u, py = v * (1 - u), pz = s * (1 - u) * (1 - v);
        q.barycentric.row(k) << 1 - px - py - pz, px, py, pz;
        q.weights(k) = 6.0 * w[std::size_t(i)] * w[std::size_t(j)] * w[std::size_t(l)] * (1 - u) *
                       (1 - u) * (1 - v);
      }
  return q;
}

const TetQuadrature& element_rule(int order) {
  static const TetQuadrature p1 = [] {
    TetQuadrature q;
    q.barycentric = Eigen::RowVector4d::Constant(0.25);
    q.weights = Eigen::VectorXd::Ones(1);
    return q;
  }();
  static const TetQuadrature p2 = tet_rule_degree2();
  return order == 1 ? p1 : p2;
}

}  // namespace spinesim::fem

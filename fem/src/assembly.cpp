#include "spinesim/fem/assembly.hpp"

#include "spinesim/fem/quadrature.hpp"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <cstdint>
#include <utility>

namespace spinesim::fem {

namespace {

// Interleaves the low 21 bits of x, y, z (Morton / Z-order key).
std::uint64_t morton_key(std::uint32_t x, std::uint32_t y, std::uint32_t z) {
  const auto spread = [](std::uint64_t v) {
    v &= 0x1fffff;
    v = (v | v << 32) & 0x1f00000000ffffULL;
    v = (v | v << 16) & 0x1f0000ff0000ffULL;
    v = (v | v << 8) & 0x100f00f00f00f00fULL;
    v = (v | v << 4) & 0x10c30c30c30c30c3ULL;
    v = (v | v << 2) & 0x1249249249249249ULL;
    return v;
  };
  return spread(x) | spread(y) << 1 | spread(z) << 2;
}

}  // namespace

FreeBlockPattern build_free_block_pattern(const FeSpace& space, const std::vector<NodeRole>& roles,
                                          FreeNodeOrder order) {
  assert(roles.size() == std::size_t(space.num_nodes()));
  FreeBlockPattern p;
  p.free_index.assign(roles.size(), -1);
  // Free nodes are numbered along a Z-order curve through space, so that matrix neighbours are
  // memory neighbours (P2 edge nodes otherwise sit far from their vertices in node order).
  std::vector<std::pair<std::uint64_t, int>> keyed;
  keyed.reserve(roles.size());
  const Eigen::RowVector3d lo = space.X.colwise().minCoeff();
  const double extent = std::max(1e-300, (space.X.colwise().maxCoeff() - lo).maxCoeff());
  const double scale = double((1u << 21) - 1) / extent;
  for (std::size_t i = 0; i < roles.size(); ++i)
    if (roles[i] == NodeRole::free) {
      const Eigen::RowVector3d c = (space.X.row(Eigen::Index(i)) - lo) * scale;
      keyed.emplace_back(
          morton_key(std::uint32_t(c.x()), std::uint32_t(c.y()), std::uint32_t(c.z())), int(i));
    }
  if (order == FreeNodeOrder::spatial) std::sort(keyed.begin(), keyed.end());
  int nf = 0;
  for (const auto& [key, node] : keyed) p.free_index[std::size_t(node)] = nf++;
  p.num_free_nodes = nf;

  const Eigen::Index nt = space.elements.rows();
  const int npe = space.nodes_per_element();
  // Higher free neighbours of every free node.
  std::vector<std::vector<int>> higher(static_cast<std::size_t>(nf));
  int idx[10];
  for (Eigen::Index t = 0; t < nt; ++t) {
    for (int a = 0; a < npe; ++a) idx[a] = p.free_index[std::size_t(space.elements(t, a))];
    for (int a = 0; a < npe; ++a)
      for (int b = 0; b < npe; ++b)
        if (idx[b] >= 0 && idx[a] > idx[b]) higher[std::size_t(idx[b])].push_back(idx[a]);
  }
  Eigen::Index nnz = 0;
  for (auto& list : higher) {
    std::sort(list.begin(), list.end());
    list.erase(std::unique(list.begin(), list.end()), list.end());
    nnz += 6 + 9 * Eigen::Index(list.size());  // 3+2+1 diagonal-block entries, 3×3 per neighbour
  }

  // Column 3B+d holds rows 3B+d..3B+2 (diagonal block), then 3A..3A+2 for each higher A.
  const Eigen::Index n = 3 * Eigen::Index(nf);
  p.lower.resize(n, n);
  p.lower.resizeNonZeros(nnz);
  int* outer = p.lower.outerIndexPtr();
  int* inner = p.lower.innerIndexPtr();
  int pos = 0;
  for (int B = 0; B < nf; ++B)
    for (int d = 0; d < 3; ++d) {
      outer[3 * B + d] = pos;
      for (int r = d; r < 3; ++r) inner[pos++] = 3 * B + r;
      for (int A : higher[std::size_t(B)])
        for (int r = 0; r < 3; ++r) inner[pos++] = 3 * A + r;
    }
  outer[n] = pos;
  std::fill_n(p.lower.valuePtr(), nnz, 0.0);

  p.slot.assign(std::size_t(nt) * std::size_t(npe * npe), -1);
  for (Eigen::Index t = 0; t < nt; ++t) {
    for (int a = 0; a < npe; ++a) idx[a] = p.free_index[std::size_t(space.elements(t, a))];
    int* s = &p.slot[std::size_t(t) * std::size_t(npe * npe)];
    for (int a = 0; a < npe; ++a)
      for (int b = 0; b < npe; ++b)
        if (idx[b] >= 0 && idx[a] > idx[b]) {
          const auto& list = higher[std::size_t(idx[b])];
          s[a * npe + b] = int(std::lower_bound(list.begin(), list.end(), idx[a]) - list.begin());
        }
  }
  return p;
}

namespace {

template <int NPE>
void assemble_constrained_impl(const FeSpace& space, const Eigen::VectorXi& region,
                               const mesh::RegionMaterials& materials,
                               const std::vector<NodeRole>& roles, const Eigen::Vector3d& c,
                               FreeBlockPattern& p, PlateCoupling& out,
                               const ElementFibres* fibres) {
  using ElementMatrix = Eigen::Matrix<double, 3 * NPE, 3 * NPE>;
  const Eigen::Index nt = space.elements.rows();
  const int* outer = p.lower.outerIndexPtr();
  double* val = p.lower.valuePtr();
  std::fill_n(val, p.lower.nonZeros(), 0.0);
  out.K_fp.setZero(3 * p.num_free_nodes, 6);
  out.K_pp.setZero();

  ElementMatrix Ke;
  TetVertices X;
  int node[NPE], A[NPE];
  Eigen::Matrix<double, 3, 6> R[NPE];
  int cached_region = 0;
  double lambda = 0, mu = 0;
  bool have_material = false;
  for (Eigen::Index t = 0; t < nt; ++t) {
    if (!have_material || region(t) != cached_region) {
      const mesh::IsotropicMaterial& m = materials.at(region(t));
      lambda = m.lame_lambda_mpa();
      mu = m.shear_modulus_mpa();
      cached_region = region(t);
      have_material = true;
    }
    bool has_plate = false;
    for (int a = 0; a < NPE; ++a) {
      node[a] = space.elements(t, a);
      A[a] = p.free_index[std::size_t(node[a])];
      if (roles[std::size_t(node[a])] == NodeRole::plate) {
        R[a] = plate_map(space.X.row(node[a]).transpose() - c);
        has_plate = true;
      }
    }
    for (int a = 0; a < 4; ++a) X.row(a) = space.X.row(node[a]);
    if constexpr (NPE == 4)
      element_stiffness_p1(X, lambda, mu, Ke);
    else
      element_stiffness_p2(X, lambda, mu, Ke);
    if (fibres != nullptr) add_element_fibres(*fibres, t, X, Ke);

    const int* s = &p.slot[std::size_t(t) * NPE * NPE];
    for (int a = 0; a < NPE; ++a) {
      if (A[a] >= 0) {
        for (int b = 0; b < NPE; ++b) {
          if (A[b] >= 0) {
            if (A[a] == A[b]) {  // diagonal block, lower part
              for (int d = 0; d < 3; ++d) {
                double* col = val + outer[3 * A[b] + d] - d;
                for (int r = d; r < 3; ++r) col[r] += Ke(3 * a + r, 3 * b + d);
              }
            } else if (A[a] > A[b]) {
              const int k = s[a * NPE + b];
              for (int d = 0; d < 3; ++d) {
                double* col = val + outer[3 * A[b] + d] + (3 - d) + 3 * k;
                for (int r = 0; r < 3; ++r) col[r] += Ke(3 * a + r, 3 * b + d);
              }
            }
          } else if (has_plate && roles[std::size_t(node[b])] == NodeRole::plate) {
            out.K_fp.template block<3, 6>(3 * A[a], 0).noalias() +=
                Ke.template block<3, 3>(3 * a, 3 * b) * R[b];
          }
        }
      } else if (roles[std::size_t(node[a])] == NodeRole::plate) {
        for (int b = 0; b < NPE; ++b)
          if (roles[std::size_t(node[b])] == NodeRole::plate)
            out.K_pp.noalias() += R[a].transpose() * Ke.template block<3, 3>(3 * a, 3 * b) * R[b];
      }
    }
  }
}

}  // namespace

PlateCoupling assemble_constrained(const FeSpace& space, const Eigen::VectorXi& region,
                                   const mesh::RegionMaterials& materials,
                                   const std::vector<NodeRole>& roles,
                                   const Eigen::Vector3d& plate_center_mm,
                                   FreeBlockPattern& pattern, const ElementFibres* fibres) {
  PlateCoupling out;
  if (space.order == 1)
    assemble_constrained_impl<4>(space, region, materials, roles, plate_center_mm, pattern, out,
                                 fibres);
  else
    assemble_constrained_impl<10>(space, region, materials, roles, plate_center_mm, pattern, out,
                                  fibres);
  return out;
}

Eigen::SparseMatrix<double> assemble_stiffness(const FeSpace& space, const Eigen::VectorXi& region,
                                               const mesh::RegionMaterials& materials,
                                               const ElementFibres* fibres) {
  const std::vector<NodeRole> roles(std::size_t(space.num_nodes()), NodeRole::free);
  FreeBlockPattern p = build_free_block_pattern(space, roles, FreeNodeOrder::node);
  assemble_constrained(space, region, materials, roles, Eigen::Vector3d::Zero(), p, fibres);
  Eigen::SparseMatrix<double> full = p.lower.selfadjointView<Eigen::Lower>();
  return full;
}

namespace {

/// Calls fn(t, N, x, w) at every point of the collapsed Gauss rule of order n on every element
/// t: N = the element's shape-function values there, x = the point (mm), w = weight × volume.
template <class Fn>
void for_each_quadrature_point(const FeSpace& space, int n, Fn&& fn) {
  const TetQuadrature q = tet_rule_collapsed(n);
  for (Eigen::Index t = 0; t < space.elements.rows(); ++t) {
    TetVertices X;
    for (int a = 0; a < 4; ++a) X.row(a) = space.X.row(space.elements(t, a));
    double vol = 0;
    barycentric_gradients(X, vol);
    for (Eigen::Index k = 0; k < q.weights.size(); ++k) {
      const Eigen::Vector4d L = q.barycentric.row(k).transpose();
      const Eigen::Vector3d x = X.transpose() * L;
      fn(t, shape_values(space.order, L), x, q.weights(k) * vol);
    }
  }
}

}  // namespace

Eigen::VectorXd assemble_body_force(const FeSpace& space, const VectorField& body_force, int n) {
  Eigen::VectorXd f = Eigen::VectorXd::Zero(3 * space.num_nodes());
  const int npe = space.nodes_per_element();
  for_each_quadrature_point(
      space, n, [&](Eigen::Index t, const Eigen::VectorXd& N, const Eigen::Vector3d& x, double w) {
        const Eigen::Vector3d b = body_force(x) * w;
        for (int a = 0; a < npe; ++a) f.segment<3>(3 * space.elements(t, a)) += N(a) * b;
      });
  return f;
}

double l2_error(const FeSpace& space, const Eigen::VectorXd& u_h, const VectorField& u_exact,
                int n) {
  const int npe = space.nodes_per_element();
  double sum = 0;
  for_each_quadrature_point(
      space, n, [&](Eigen::Index t, const Eigen::VectorXd& N, const Eigen::Vector3d& x, double w) {
        Eigen::Vector3d uh = Eigen::Vector3d::Zero();
        for (int a = 0; a < npe; ++a) uh += N(a) * u_h.segment<3>(3 * space.elements(t, a));
        sum += w * (uh - u_exact(x)).squaredNorm();
      });
  return std::sqrt(sum);
}

}  // namespace spinesim::fem

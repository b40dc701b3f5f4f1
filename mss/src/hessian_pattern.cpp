#include "hessian_pattern.hpp"

#include <algorithm>
#include <stdexcept>

namespace spinesim::mss {

HessianPattern::HessianPattern(const Eigen::MatrixX4i& T, Eigen::Index n) {
  std::vector<std::vector<int>> adj(static_cast<std::size_t>(n));
  for (Eigen::Index i = 0; i < n; ++i) adj[i].push_back(static_cast<int>(i));
  for (Eigen::Index t = 0; t < T.rows(); ++t)
    for (int a = 0; a < 4; ++a)
      for (int b = 0; b < 4; ++b)
        if (a != b) adj[T(t, a)].push_back(T(t, b));
  first_.assign(static_cast<std::size_t>(n) + 1, 0);
  for (Eigen::Index i = 0; i < n; ++i) {
    auto& l = adj[i];
    std::sort(l.begin(), l.end());
    l.erase(std::unique(l.begin(), l.end()), l.end());
    first_[i + 1] = first_[i] + static_cast<int>(l.size());
  }
  neighbours_.reserve(first_.back());
  for (const auto& l : adj) neighbours_.insert(neighbours_.end(), l.begin(), l.end());

  // Column 3q+c holds rows 3p+r of every neighbour p of q, in order.
  const Eigen::Index N = 3 * n;
  pattern_.resize(N, N);
  stride_.resize(static_cast<std::size_t>(n));
  Eigen::VectorXi per_column(N);
  for (Eigen::Index q = 0; q < n; ++q) {
    stride_[q] = 3 * (first_[q + 1] - first_[q]);
    for (int c = 0; c < 3; ++c) per_column(3 * q + c) = stride_[q];
  }
  pattern_.reserve(per_column);
  for (Eigen::Index q = 0; q < n; ++q)
    for (int c = 0; c < 3; ++c)
      for (int k = first_[q]; k < first_[q + 1]; ++k)
        for (int r = 0; r < 3; ++r) pattern_.insert(3 * neighbours_[k] + r, 3 * q + c) = 0.0;
  pattern_.makeCompressed();
}

int HessianPattern::block(int p, int q) const {
  const auto begin = neighbours_.begin() + first_[q], end = neighbours_.begin() + first_[q + 1];
  const auto it = std::lower_bound(begin, end, p);
  if (it == end || *it != p) throw std::logic_error("HessianPattern: nodes share no tetrahedron");
  return pattern_.outerIndexPtr()[3 * q] + 3 * static_cast<int>(it - begin);
}

void HessianPattern::reset(Eigen::SparseMatrix<double>& H) const {
  const bool same =
      H.rows() == pattern_.rows() && H.cols() == pattern_.cols() && H.isCompressed() &&
      H.nonZeros() == pattern_.nonZeros() &&
      std::equal(H.outerIndexPtr(), H.outerIndexPtr() + H.cols() + 1, pattern_.outerIndexPtr()) &&
      std::equal(H.innerIndexPtr(), H.innerIndexPtr() + H.nonZeros(), pattern_.innerIndexPtr());
  if (!same) H = pattern_;
  std::fill(H.valuePtr(), H.valuePtr() + H.nonZeros(), 0.0);
}

}  // namespace spinesim::mss

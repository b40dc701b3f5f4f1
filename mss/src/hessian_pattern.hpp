// Fixed sparsity pattern of a 3-DOF-per-node Hessian: a dense 3x3 block for every node pair
// that shares a tetrahedron (and the diagonal). Built once; element blocks are scattered into
// precomputed value slots, so refilling the matrix does no searching and no allocation.
// Both triangles are stored (column-major, sorted row indices).
#pragma once

#include <Eigen/Core>
#include <Eigen/SparseCore>

#include <vector>

namespace spinesim::mss {

class HessianPattern {
 public:
  HessianPattern() = default;
  /// Pattern of the node graph of the tetrahedra T (#T×4) on n nodes.
  HessianPattern(const Eigen::MatrixX4i& T, Eigen::Index n);

  /// Index into valuePtr() of the entry (3p, 3q) — the top-left of block (p, q). The entries
  /// (3p + r, 3q + c) are at block(p, q) + c * column_stride(q) + r.
  int block(int p, int q) const;
  int column_stride(int q) const { return stride_[q]; }

  /// Gives H this pattern (copied if H's differs) and zero values.
  void reset(Eigen::SparseMatrix<double>& H) const;

  /// val[block (p, q)] += h, where `slot` = block(p, q).
  template <typename Block>
  void add_block(double* val, int slot, int q, const Block& h) const {
    const int s = stride_[q];
    for (int c = 0; c < 3; ++c)
      for (int r = 0; r < 3; ++r) val[slot + c * s + r] += h(r, c);
  }

  const Eigen::SparseMatrix<double>& matrix() const { return pattern_; }

 private:
  Eigen::SparseMatrix<double> pattern_;
  std::vector<int> stride_;      ///< nonzeros per column of node q (3 x its neighbour count)
  std::vector<int> first_;       ///< CSR offsets of the sorted neighbour lists
  std::vector<int> neighbours_;  ///< sorted neighbours of each node, itself included
};

}  // namespace spinesim::mss

#include "spinesim/haptics/aabb_tree.hpp"

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace spinesim::haptics {

Eigen::Vector3d closest_point_on_triangle(const Eigen::Vector3d& p, const Eigen::Vector3d& a,
                                          const Eigen::Vector3d& b, const Eigen::Vector3d& c) {
  // Voronoi regions of the vertices, edges and face, in that order.
  const Eigen::Vector3d ab = b - a, ac = c - a, ap = p - a;
  const double d1 = ab.dot(ap), d2 = ac.dot(ap);
  if (d1 <= 0 && d2 <= 0) return a;
  const Eigen::Vector3d bp = p - b;
  const double d3 = ab.dot(bp), d4 = ac.dot(bp);
  if (d3 >= 0 && d4 <= d3) return b;
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) return a + d1 / (d1 - d3) * ab;
  const Eigen::Vector3d cp = p - c;
  const double d5 = ab.dot(cp), d6 = ac.dot(cp);
  if (d6 >= 0 && d5 <= d6) return c;
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) return a + d2 / (d2 - d6) * ac;
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0)
    return b + (d4 - d3) / ((d4 - d3) + (d5 - d6)) * (c - b);
  const double denom = 1.0 / (va + vb + vc);
  return a + ab * (vb * denom) + ac * (vc * denom);
}

double winding_number(const AabbTree& tree, const Eigen::Vector3d& p) {
  const auto& V = tree.vertices();
  const auto& F = tree.triangles();
  double sum = 0;
  for (Eigen::Index t = 0; t < F.rows(); ++t) {
    const Eigen::Vector3d a = V.row(F(t, 0)).transpose() - p, b = V.row(F(t, 1)).transpose() - p,
                          c = V.row(F(t, 2)).transpose() - p;
    const double la = a.norm(), lb = b.norm(), lc = c.norm();
    sum += 2 * std::atan2(a.dot(b.cross(c)),
                          la * lb * lc + a.dot(b) * lc + a.dot(c) * lb + b.dot(c) * la);
  }
  return sum / (4 * M_PI);
}

AabbTree::AabbTree(const Eigen::MatrixX3d& V, const Eigen::MatrixX3i& F) : V_(V), F_(F) {
  if (F.rows() == 0) throw std::invalid_argument("AABB tree: the surface has no triangles");
  if (F.minCoeff() < 0 || F.maxCoeff() >= V.rows())
    throw std::invalid_argument("AABB tree: a triangle index is out of range");
  N_.resize(F.rows(), 3);
  for (Eigen::Index t = 0; t < F.rows(); ++t) {
    const Eigen::Vector3d a = V.row(F(t, 0)), b = V.row(F(t, 1)), c = V.row(F(t, 2));
    const Eigen::Vector3d n = (b - a).cross(c - a);
    N_.row(t) = n.norm() > 0 ? Eigen::Vector3d(n.normalized()) : Eigen::Vector3d::Zero();
  }
  std::vector<int> order(std::size_t(F.rows()));
  for (std::size_t i = 0; i < order.size(); ++i) order[i] = int(i);
  nodes_.reserve(2 * order.size());
  build(order, 0, int(order.size()), 1);
}

int AabbTree::build(std::vector<int>& order, int begin, int end, int depth) {
  depth_ = std::max(depth_, depth);
  const int index = int(nodes_.size());
  nodes_.emplace_back();
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(1e300), hi = -lo;
  for (int i = begin; i < end; ++i)
    for (int k = 0; k < 3; ++k) {
      const Eigen::Vector3d v = V_.row(F_(order[std::size_t(i)], k));
      lo = lo.cwiseMin(v);
      hi = hi.cwiseMax(v);
    }
  nodes_[std::size_t(index)].lo = lo;
  nodes_[std::size_t(index)].hi = hi;
  if (end - begin == 1) {
    nodes_[std::size_t(index)].triangle = order[std::size_t(begin)];
    return index;
  }
  // The plane orthogonal to the longest axis through the box's middle; a triangle is positive
  // when the midpoint of its projection onto the axis lies beyond it.
  int axis = 0;
  (hi - lo).maxCoeff(&axis);
  const double delta = 0.5 * (lo[axis] + hi[axis]);
  auto midpoint = [&](int t) {
    double a = V_(F_(t, 0), axis), b = a;
    for (int k = 1; k < 3; ++k) {
      a = std::min(a, V_(F_(t, k), axis));
      b = std::max(b, V_(F_(t, k), axis));
    }
    return 0.5 * (a + b);
  };
  auto first = order.begin() + begin, last = order.begin() + end;
  int mid = int(std::partition(first, last, [&](int t) { return !(midpoint(t) > delta); }) -
                order.begin());
  // All on one side (triangles stacked at one spot) or a deep tree: split the sorted list in
  // half so that the depth stays logarithmic and the recursion ends.
  if (mid == begin || mid == end || depth > kMaxDepth - 24) {
    mid = begin + (end - begin) / 2;
    std::nth_element(first, order.begin() + mid, last,
                     [&](int s, int t) { return midpoint(s) < midpoint(t); });
  }
  const int left = build(order, begin, mid, depth + 1);
  const int right = build(order, mid, end, depth + 1);
  nodes_[std::size_t(index)].left = left;
  nodes_[std::size_t(index)].right = right;
  return index;
}

bool AabbTree::triangle_meets_ball(int t, const Eigen::Vector3d& c, double r2) const {
  const Eigen::Vector3d q =
      closest_point_on_triangle(c, V_.row(F_(t, 0)), V_.row(F_(t, 1)), V_.row(F_(t, 2)));
  return (q - c).squaredNorm() <= r2;
}

int AabbTree::sphere_query(const Eigen::Vector3d& center, double radius, int* out,
                           int capacity) const {
  if (nodes_.empty()) return 0;
  const double r2 = radius * radius;
  int stack[kMaxDepth + 1];
  int top = 0, found = 0;
  stack[top++] = 0;
  while (top > 0) {
    const Node& n = nodes_[std::size_t(stack[--top])];
    if (box_distance_squared(center, n.lo, n.hi) > r2) continue;
    if (n.triangle >= 0) {
      if (triangle_meets_ball(n.triangle, center, r2)) {
        if (found < capacity) out[found] = n.triangle;
        ++found;
      }
      continue;
    }
    stack[top++] = n.right;
    stack[top++] = n.left;
  }
  return found;
}

double AabbTree::entry(const Eigen::Vector3d& p0, const Eigen::Vector3d& m, double radius,
                       const Eigen::Vector3d& lo, const Eigen::Vector3d& hi) {
  // Slabs of the grown box (Kay & Kajiya 1986): the segment is inside all three on [t_in, t_out].
  double t_in = 0, t_out = 1;
  for (int k = 0; k < 3; ++k) {
    const double a = lo[k] - radius, b = hi[k] + radius;
    if (m[k] == 0) {
      if (p0[k] < a || p0[k] > b) return 2;
      continue;
    }
    double ta = (a - p0[k]) / m[k], tb = (b - p0[k]) / m[k];
    if (ta > tb) std::swap(ta, tb);
    t_in = std::max(t_in, ta);
    t_out = std::min(t_out, tb);
    if (t_in > t_out) return 2;
  }
  return t_in;
}

std::vector<int> AabbTree::sphere_query_brute_force(const Eigen::Vector3d& center,
                                                    double radius) const {
  std::vector<int> out;
  for (int t = 0; t < int(F_.rows()); ++t)
    if (triangle_meets_ball(t, center, radius * radius)) out.push_back(t);
  return out;
}

double AabbTree::closest_point(const Eigen::Vector3d& p, double max_distance, int* triangle,
                               Eigen::Vector3d* closest, bool front_only) const {
  double best2 = max_distance * max_distance;
  int best = -1;
  Eigen::Vector3d best_point = p;
  if (nodes_.empty()) {
    if (triangle) *triangle = -1;
    return max_distance;
  }
  int stack[kMaxDepth + 1];
  int top = 0;
  stack[top++] = 0;
  while (top > 0) {
    const Node& n = nodes_[std::size_t(stack[--top])];
    if (box_distance_squared(p, n.lo, n.hi) >= best2) continue;
    if (n.triangle >= 0) {
      if (front_only && N_.row(n.triangle).dot(p - V_.row(F_(n.triangle, 0)).transpose()) < 0)
        continue;
      const Eigen::Vector3d q = closest_point_on_triangle(
          p, V_.row(F_(n.triangle, 0)), V_.row(F_(n.triangle, 1)), V_.row(F_(n.triangle, 2)));
      const double d2 = (q - p).squaredNorm();
      if (d2 < best2) {
        best2 = d2;
        best = n.triangle;
        best_point = q;
      }
      continue;
    }
    // Nearer child last, so it is searched first and prunes the other.
    const Node& l = nodes_[std::size_t(n.left)];
    const Node& r = nodes_[std::size_t(n.right)];
    const bool left_first =
        box_distance_squared(p, l.lo, l.hi) <= box_distance_squared(p, r.lo, r.hi);
    stack[top++] = left_first ? n.right : n.left;
    stack[top++] = left_first ? n.left : n.right;
  }
  if (triangle) *triangle = best;
  if (closest) *closest = best_point;
  return best < 0 ? max_distance : std::sqrt(best2);
}

}  // namespace spinesim::haptics

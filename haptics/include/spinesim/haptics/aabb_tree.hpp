// The collision tree of the rigid stage (thesis 4.4.1): one axis-aligned bounding-box tree per
// rigid body, built top-down by recursive subdivision — the box of the primitives is split at
// the median (the middle) of its longest axis, a primitive goes to the positive side when the
// midpoint of its projection onto that axis is beyond the plane — until each leaf holds one
// triangle (n leaves, n − 1 inner nodes). Queries use Arvo's (1990) sphere–box test and, at the
// leaves, the exact sphere–triangle test, and run in the body's own frame, so a body can move
// without a rebuild. A query allocates nothing: it writes into a caller's fixed buffer.
#pragma once

#include <Eigen/Core>

#include <algorithm>
#include <cstdint>
#include <vector>

namespace spinesim::haptics {

/// Squared distance from p to the box [lo, hi] (Arvo 1990): 0 inside.
inline double box_distance_squared(const Eigen::Vector3d& p, const Eigen::Vector3d& lo,
                                   const Eigen::Vector3d& hi) {
  double d2 = 0;
  for (int k = 0; k < 3; ++k) {
    if (p[k] < lo[k]) {
      const double e = lo[k] - p[k];
      d2 += e * e;
    } else if (p[k] > hi[k]) {
      const double e = p[k] - hi[k];
      d2 += e * e;
    }
  }
  return d2;
}

/// Closest point to p on the triangle (a, b, c) (Ericson 2005, 5.1.5).
Eigen::Vector3d closest_point_on_triangle(const Eigen::Vector3d& p, const Eigen::Vector3d& a,
                                          const Eigen::Vector3d& b, const Eigen::Vector3d& c);

class AabbTree;
/// Generalised winding number of the tree's closed surface about p (Jacobson et al. 2013): the
/// sum of the triangles' solid angles (Van Oosterom & Strackee 1983) over 4π; 1 inside, 0
/// outside. O(triangles): for set-up and tests, not for a tick.
double winding_number(const AabbTree& tree, const Eigen::Vector3d& p);

class AabbTree {
 public:
  AabbTree() = default;
  /// Builds the tree of the triangles F over the vertices V (mm). Throws std::invalid_argument
  /// for an empty mesh or an index out of range.
  AabbTree(const Eigen::MatrixX3d& V, const Eigen::MatrixX3i& F);

  /// Triangles whose closed set is within `radius` of `center` (the ball meets the triangle),
  /// written to out[0 … capacity); returns how many there are (may exceed capacity: then only
  /// the first `capacity` were written). No allocation.
  int sphere_query(const Eigen::Vector3d& center, double radius, int* out, int capacity) const;

  /// The same set by testing every triangle (the brute-force oracle).
  std::vector<int> sphere_query_brute_force(const Eigen::Vector3d& center, double radius) const;

  /// The earliest contact of a sphere of `radius` moving from p0 to p0 + m, within a budget of
  /// work. `sweep(t)` gives the earliest t in [0, 1] at which the sphere touches triangle t (> 1:
  /// never); it is asked only for triangles whose box, grown by `radius`, the segment enters
  /// before the earliest contact found so far (nearer child first). Each node visited and each
  /// triangle swept spends one unit of `budget`; when it runs out the search stops and
  /// `t_free` says how far the move is proven free (the smallest entry of what was left
  /// unsearched). No allocation: the work of one call is at most the budget, whatever the move.
  struct Sweep {
    double t = 2;          ///< earliest contact found (> 1: none)
    int triangle = -1;     ///< its triangle
    double t_free = 1;     ///< no contact before this (= min(t, 1) when complete)
    bool complete = true;  ///< false: the budget ran out first
  };
  template <class TriangleSweep>
  Sweep sweep(const Eigen::Vector3d& p0, const Eigen::Vector3d& m, double radius, int& budget,
              TriangleSweep&& sweep_triangle) const;
  /// When the segment p0 + t m (t in [0, 1]) enters the box [lo, hi] grown by `radius` (0 if it
  /// starts inside; > 1 if never): a lower bound on the sphere's first contact with anything in
  /// the box.
  static double entry(const Eigen::Vector3d& p0, const Eigen::Vector3d& m, double radius,
                      const Eigen::Vector3d& lo, const Eigen::Vector3d& hi);
  /// The root box's entry (entry() on bounds_min/bounds_max); > 1 for an empty tree.
  double root_entry(const Eigen::Vector3d& p0, const Eigen::Vector3d& m, double radius) const {
    return nodes_.empty() ? 2 : entry(p0, m, radius, nodes_[0].lo, nodes_[0].hi);
  }

  /// Smallest distance from p to the surface, over the triangles within `max_distance` (returns
  /// max_distance when none is closer); `triangle` gets the closest one (−1 if none) and
  /// `closest` the closest point. With `front_only`, triangles that p lies behind (on the side
  /// their normal points away from) are ignored: the surface is one-sided, as a proxy that
  /// starts inside a solid must be able to leave it. No allocation.
  double closest_point(const Eigen::Vector3d& p, double max_distance, int* triangle,
                       Eigen::Vector3d* closest, bool front_only = false) const;
  /// Unit outward normal of triangle t (from its vertex order).
  Eigen::Vector3d normal(int t) const { return N_.row(t); }

  int triangle_count() const { return int(F_.rows()); }
  int node_count() const { return int(nodes_.size()); }
  int depth() const { return depth_; }
  const Eigen::MatrixX3d& vertices() const { return V_; }
  const Eigen::MatrixX3i& triangles() const { return F_; }
  Eigen::Vector3d bounds_min() const {
    return nodes_.empty() ? Eigen::Vector3d::Zero() : nodes_[0].lo;
  }
  Eigen::Vector3d bounds_max() const {
    return nodes_.empty() ? Eigen::Vector3d::Zero() : nodes_[0].hi;
  }

  /// Deepest possible stack of a query (the tree's depth is checked against it when built).
  static constexpr int kMaxDepth = 64;

 private:
  struct Node {
    Eigen::Vector3d lo, hi;
    std::int32_t left = -1, right = -1;  ///< children; both −1 for a leaf
    std::int32_t triangle = -1;          ///< the leaf's triangle
  };
  int build(std::vector<int>& order, int begin, int end, int depth);
  bool triangle_meets_ball(int t, const Eigen::Vector3d& c, double r2) const;

  Eigen::MatrixX3d V_;
  Eigen::MatrixX3i F_;
  Eigen::MatrixX3d N_;  ///< unit face normals
  std::vector<Node> nodes_;
  int depth_ = 0;
};

template <class TriangleSweep>
AabbTree::Sweep AabbTree::sweep(const Eigen::Vector3d& p0, const Eigen::Vector3d& m, double radius,
                                int& budget, TriangleSweep&& sweep_triangle) const {
  Sweep out;
  if (nodes_.empty()) return out;
  // Depth-first, nearer child on top; each entry remembers its box's entry time, so what is
  // left on the stack when the budget runs out bounds the unsearched part from below.
  struct Entry {
    int node;
    double t;
  };
  Entry stack[kMaxDepth + 2];
  int top = 0;
  const double t0 = entry(p0, m, radius, nodes_[0].lo, nodes_[0].hi);
  if (t0 <= 1) stack[top++] = {0, t0};
  while (top > 0) {
    const Entry e = stack[--top];
    if (e.t >= out.t) continue;
    if (budget <= 0) {
      out.complete = false;
      double t_free = e.t;
      for (int k = 0; k < top; ++k) t_free = std::min(t_free, stack[k].t);
      out.t_free = std::min(t_free, std::min(out.t, 1.0));
      return out;
    }
    --budget;
    const Node& n = nodes_[std::size_t(e.node)];
    if (n.triangle >= 0) {
      const double t = sweep_triangle(n.triangle);
      if (t < out.t) {
        out.t = t;
        out.triangle = n.triangle;
      }
      continue;
    }
    const Node& l = nodes_[std::size_t(n.left)];
    const Node& r = nodes_[std::size_t(n.right)];
    const double tl = entry(p0, m, radius, l.lo, l.hi), tr = entry(p0, m, radius, r.lo, r.hi);
    const bool left_first = tl <= tr;
    const Entry first{left_first ? n.left : n.right, left_first ? tl : tr};
    const Entry second{left_first ? n.right : n.left, left_first ? tr : tl};
    if (second.t <= 1 && second.t < out.t) stack[top++] = second;
    if (first.t <= 1 && first.t < out.t) stack[top++] = first;
  }
  out.t_free = std::min(out.t, 1.0);
  return out;
}

}  // namespace spinesim::haptics

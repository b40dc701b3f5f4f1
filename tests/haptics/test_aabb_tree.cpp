// The thesis's AABB tree against two oracles: a brute-force search over every triangle and
// CGAL 5.5's AABB_tree (all_intersected_primitives with a Sphere_3), on random probes.
#include "haptics_fixtures.hpp"
#include "spinesim/haptics/aabb_tree.hpp"

#include <gtest/gtest.h>

#include <CGAL/AABB_traits.h>
#include <CGAL/AABB_tree.h>
#include <CGAL/AABB_triangle_primitive.h>
#include <CGAL/Simple_cartesian.h>

#include <algorithm>
#include <random>
#include <vector>

namespace sh = spinesim::haptics;

namespace {

using K = CGAL::Simple_cartesian<double>;
using Triangle = K::Triangle_3;
using Iterator = std::vector<Triangle>::const_iterator;
using Primitive = CGAL::AABB_triangle_primitive<K, Iterator>;
using CgalTree = CGAL::AABB_tree<CGAL::AABB_traits<K, Primitive>>;

}  // namespace

TEST(AabbTree, ClosestPointOnTriangleMatchesDenseSampling) {
  std::mt19937 rng(3);
  std::normal_distribution<double> g(0, 1);
  for (int trial = 0; trial < 200; ++trial) {
    const Eigen::Vector3d a(g(rng), g(rng), g(rng)), b(g(rng), g(rng), g(rng)),
        c(g(rng), g(rng), g(rng)), p(2 * g(rng), 2 * g(rng), 2 * g(rng));
    const Eigen::Vector3d q = sh::closest_point_on_triangle(p, a, b, c);
    double best = 1e300;
    const int n = 200;
    for (int i = 0; i <= n; ++i)
      for (int j = 0; i + j <= n; ++j)
        best = std::min(best, (a + (b - a) * i / n + (c - a) * j / n - p).norm());
    EXPECT_LE((q - p).norm(), best + 1e-12);
    EXPECT_GE((q - p).norm(), best - 0.02 * (b - a).norm() - 0.02 * (c - a).norm());
  }
}

TEST(AabbTree, BuildsTheThesisTree) {
  const auto& v = sh::testing::vertebra("L3");
  const sh::AabbTree tree(v.surface.V, v.surface.F);
  const int n = int(v.surface.F.rows());
  EXPECT_EQ(tree.node_count(), 2 * n - 1);  // n leaves, n − 1 inner nodes
  EXPECT_LE(tree.depth(), sh::AabbTree::kMaxDepth);
  EXPECT_LT(tree.depth(), 40);
}

TEST(AabbTree, SphereQueryEqualsBruteForceAndCgalOnRandomProbes) {
  const auto& v = sh::testing::vertebra("L3");
  const sh::AabbTree tree(v.surface.V, v.surface.F);
  std::vector<Triangle> triangles;
  for (Eigen::Index t = 0; t < v.surface.F.rows(); ++t) {
    auto P = [&](int k) {
      const Eigen::Vector3d x = v.surface.V.row(v.surface.F(t, k));
      return K::Point_3(x.x(), x.y(), x.z());
    };
    triangles.emplace_back(P(0), P(1), P(2));
  }
  CgalTree cgal(triangles.begin(), triangles.end());
  const Eigen::Vector3d lo = tree.bounds_min(), hi = tree.bounds_max();
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(0, 1), radius(2, 10);
  std::vector<int> buffer(20000);
  int probes_with_contact = 0;
  for (int probe = 0; probe < 10000; ++probe) {
    const Eigen::Vector3d c = lo + (hi - lo).cwiseProduct(Eigen::Vector3d(u(rng), u(rng), u(rng)));
    const double r = radius(rng);
    const int n = tree.sphere_query(c, r, buffer.data(), int(buffer.size()));
    ASSERT_LE(n, int(buffer.size()));
    std::vector<int> ours(buffer.begin(), buffer.begin() + n);
    std::sort(ours.begin(), ours.end());
    const std::vector<int> brute = tree.sphere_query_brute_force(c, r);
    ASSERT_EQ(ours, brute) << "probe " << probe;
    std::vector<Iterator> hits;
    cgal.all_intersected_primitives(K::Sphere_3(K::Point_3(c.x(), c.y(), c.z()), r * r),
                                    std::back_inserter(hits));
    std::vector<int> theirs;
    for (const auto& it : hits) theirs.push_back(int(it - triangles.cbegin()));
    std::sort(theirs.begin(), theirs.end());
    // CGAL's Sphere_3 is the surface, not the ball: it misses triangles wholly inside the
    // ball. Compare on the triangles that reach the ball's surface.
    std::vector<int> crossing;
    for (int t : ours) {
      double far = 0;
      for (int k = 0; k < 3; ++k)
        far = std::max(far, (v.surface.V.row(v.surface.F(t, k)).transpose() - c).norm());
      if (far >= r) crossing.push_back(t);
    }
    ASSERT_EQ(theirs, crossing) << "probe " << probe;
    probes_with_contact += n > 0;
  }
  EXPECT_GT(probes_with_contact, 1000);  // the test saw contacts, not only empty space
}

TEST(AabbTree, QueryReportsOverflowWithoutWritingPastTheBuffer) {
  const auto& v = sh::testing::vertebra("L3");
  const sh::AabbTree tree(v.surface.V, v.surface.F);
  std::vector<int> buffer(8, -7);
  const Eigen::Vector3d c = 0.5 * (tree.bounds_min() + tree.bounds_max());
  const int n = tree.sphere_query(c, 1000.0, buffer.data(), 4);
  EXPECT_EQ(n, tree.triangle_count());
  for (int k = 4; k < 8; ++k) EXPECT_EQ(buffer[std::size_t(k)], -7);
}

TEST(AabbTree, ClosestPointEqualsBruteForce) {
  const auto& v = sh::testing::vertebra("T8");
  const sh::AabbTree tree(v.surface.V, v.surface.F);
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(0, 1);
  const Eigen::Vector3d lo = tree.bounds_min(), hi = tree.bounds_max();
  for (int probe = 0; probe < 500; ++probe) {
    const Eigen::Vector3d p = lo + (hi - lo).cwiseProduct(Eigen::Vector3d(u(rng), u(rng), u(rng)));
    int tri = -1;
    Eigen::Vector3d q;
    const double d = tree.closest_point(p, 1e9, &tri, &q);
    double best = 1e300;
    for (int t = 0; t < tree.triangle_count(); ++t)
      best = std::min(best, (sh::closest_point_on_triangle(p, v.surface.V.row(v.surface.F(t, 0)),
                                                           v.surface.V.row(v.surface.F(t, 1)),
                                                           v.surface.V.row(v.surface.F(t, 2))) -
                             p)
                                .norm());
    EXPECT_NEAR(d, best, 1e-12);
    EXPECT_NEAR((q - p).norm(), d, 1e-12);
  }
}

namespace {

// A sphere moving from p0 by m: the earliest t in [0, 1] at which it comes within r of the
// triangle, by bisection on the distance along the move after a dense scan (the brute-force
// oracle of AabbTree::sweep: any triangle sweep function works, this one is two-sided).
double sweep_by_scan(const sh::AabbTree& tree, int t, const Eigen::Vector3d& p0,
                     const Eigen::Vector3d& m, double r) {
  const auto& F = tree.triangles();
  const auto& V = tree.vertices();
  auto distance = [&](double s) {
    const Eigen::Vector3d p = p0 + s * m;
    return (sh::closest_point_on_triangle(p, V.row(F(t, 0)), V.row(F(t, 1)), V.row(F(t, 2))) - p)
        .norm();
  };
  if (distance(0) <= r) return 0;
  const int n = 64;
  for (int k = 1; k <= n; ++k) {
    if (distance(double(k) / n) > r) continue;
    double a = double(k - 1) / n, b = double(k) / n;
    for (int i = 0; i < 50; ++i) (distance(0.5 * (a + b)) > r ? a : b) = 0.5 * (a + b);
    return b;
  }
  return 2;
}

}  // namespace

// The swept search equals testing every triangle, and a search that runs out of budget never
// claims the move free past a contact; its work is at most the budget, for moves of any length.
TEST(AabbTree, BudgetedSweepEqualsBruteForceAndNeverClaimsAContactFree) {
  const auto& v = sh::testing::vertebra("L3");
  const sh::AabbTree tree(v.surface.V, v.surface.F);
  const Eigen::Vector3d lo = tree.bounds_min(), hi = tree.bounds_max();
  const Eigen::Vector3d centre = 0.5 * (lo + hi), size = hi - lo;
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(-1, 1), length(0.5, 400);
  std::vector<double> scan(std::size_t(tree.triangle_count()));
  int complete_hits = 0, partial = 0;
  for (int trial = 0; trial < 300; ++trial) {
    const Eigen::Vector3d p0 =
        centre + 0.8 * size.cwiseProduct(Eigen::Vector3d(u(rng), u(rng), u(rng)));
    const Eigen::Vector3d m = length(rng) * Eigen::Vector3d(u(rng), u(rng), u(rng)).normalized();
    const double r = 4;
    // The oracle: every triangle, the closed-form sweep replaced by a scan.
    double truth = 2;
    for (int t = 0; t < tree.triangle_count(); ++t) {
      scan[std::size_t(t)] = sweep_by_scan(tree, t, p0, m, r);
      truth = std::min(truth, scan[std::size_t(t)]);
    }
    auto sweep = [&](int t) { return scan[std::size_t(t)]; };
    int budget = 1 << 30;
    const sh::AabbTree::Sweep full = tree.sweep(p0, m, r, budget, sweep);
    ASSERT_TRUE(full.complete);
    EXPECT_EQ(full.t, truth) << "trial " << trial;
    EXPECT_EQ(full.t_free, std::min(truth, 1.0));
    if (truth <= 1) {
      ++complete_hits;
      EXPECT_EQ(scan[std::size_t(full.triangle)], truth);
    }
    for (const int limit : {1, 16, 100, 400}) {
      int left = limit;
      const sh::AabbTree::Sweep part = tree.sweep(p0, m, r, left, sweep);
      EXPECT_GE(left, 0);
      EXPECT_LE(part.t_free, std::min(truth, 1.0)) << "trial " << trial << ", budget " << limit;
      if (part.complete) {
        EXPECT_EQ(part.t, truth);
      } else {
        ++partial;
        EXPECT_EQ(left, 0);
      }
    }
  }
  EXPECT_GT(complete_hits, 30);
  EXPECT_GT(partial, 100);
}

// The entry time of a segment into a grown box, against a dense scan of the point's distance.
TEST(AabbTree, EntryIsWhenTheSegmentFirstComesWithinTheGrowthOfTheBox) {
  std::mt19937 rng(8);
  std::uniform_real_distribution<double> u(-10, 10);
  const Eigen::Vector3d lo(-2, -1, -3), hi(1, 2, 0.5);
  for (int trial = 0; trial < 2000; ++trial) {
    const Eigen::Vector3d p0(u(rng), u(rng), u(rng)), m(2 * u(rng), 2 * u(rng), 2 * u(rng));
    const double r = 0.1 * std::abs(u(rng));
    const double t = sh::AabbTree::entry(p0, m, r, lo, hi);
    // Inside the grown box (a superset of the points within r of the box) at t, outside before.
    auto inside = [&](double s) {
      const Eigen::Vector3d p = p0 + s * m;
      return ((p.array() >= lo.array() - r) && (p.array() <= hi.array() + r)).all();
    };
    if (t <= 1) {
      EXPECT_TRUE(inside(std::min(1.0, t + 1e-9))) << trial;
      for (int k = 0; k < 200; ++k) {
        const double s = t * k / 200.0;
        if (s < t - 1e-9) EXPECT_FALSE(inside(s)) << trial;
      }
    } else {
      for (int k = 0; k <= 400; ++k) EXPECT_FALSE(inside(k / 400.0)) << trial;
    }
  }
}

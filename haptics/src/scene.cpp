#include "spinesim/haptics/scene.hpp"

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace spinesim::haptics {

SurfaceSamples sample_surface(const mesh::TriSurface& s, double spacing_mm) {
  if (!(spacing_mm > 0) || !std::isfinite(spacing_mm))
    throw std::invalid_argument("surface sample spacing must be > 0 mm");
  SurfaceSamples out;
  out.spacing_mm = spacing_mm;
  out.first.resize(std::size_t(s.F.rows()) + 1, 0);
  std::vector<int> n(std::size_t(s.F.rows()));
  long long total = 0;
  for (Eigen::Index t = 0; t < s.F.rows(); ++t) {
    const Eigen::Vector3d a = s.V.row(s.F(t, 0)), b = s.V.row(s.F(t, 1)), c = s.V.row(s.F(t, 2));
    const double longest = std::max({(b - a).norm(), (c - b).norm(), (a - c).norm()});
    n[std::size_t(t)] = std::max(1, int(std::ceil(longest / spacing_mm)));
    out.first[std::size_t(t)] = int(total);
    total += (long long)n[std::size_t(t)] * n[std::size_t(t)];
    if (total > 50000000)
      throw std::invalid_argument("surface samples: spacing " + std::to_string(spacing_mm) +
                                  " mm gives more than 50 million points; use a larger one");
  }
  out.first.back() = int(total);
  out.points.resize(total, 3);
  out.area_mm2.resize(total);
  for (Eigen::Index t = 0; t < s.F.rows(); ++t) {
    const Eigen::Vector3d a = s.V.row(s.F(t, 0)), b = s.V.row(s.F(t, 1)), c = s.V.row(s.F(t, 2));
    const int m = n[std::size_t(t)];
    const double sub_area = 0.5 * (b - a).cross(c - a).norm() / (m * m);
    const Eigen::Vector3d u = (b - a) / m, v = (c - a) / m;
    int k = out.first[std::size_t(t)];
    // Sub-triangles of the grid: "up" ones (i, j), (i+1, j), (i, j+1) and "down" ones
    // (i+1, j), (i+1, j+1), (i, j+1); centroids at a + u (i + 1/3 or 2/3) + v (j + …).
    for (int i = 0; i < m; ++i)
      for (int j = 0; i + j < m; ++j) {
        out.points.row(k) = a + u * (i + 1.0 / 3) + v * (j + 1.0 / 3);
        out.area_mm2(k++) = sub_area;
        if (i + j + 1 < m) {
          out.points.row(k) = a + u * (i + 2.0 / 3) + v * (j + 2.0 / 3);
          out.area_mm2(k++) = sub_area;
        }
      }
  }
  return out;
}

void Scene::add_body(const std::string& name, const mesh::TriSurface& surface) {
  if (int(bodies_.size()) >= kMaxBodies)
    throw std::invalid_argument("scene: more than " + std::to_string(kMaxBodies) + " bodies");
  // Bodies are found by name (index()): a second body of the same name would be found as the
  // first, and poses meant for one would move the other.
  if (index(name) >= 0) throw std::invalid_argument("scene: a second body named " + name);
  RigidBody b;
  b.name = name;
  b.tree = AabbTree(surface.V, surface.F);
  bodies_.push_back(std::move(b));
}

void Scene::sample_surfaces(double spacing_mm) {
  for (auto& b : bodies_) {
    mesh::TriSurface s{b.tree.vertices(), b.tree.triangles()};
    b.samples = sample_surface(s, spacing_mm);
  }
}

int Scene::index(const std::string& name) const {
  for (std::size_t i = 0; i < bodies_.size(); ++i)
    if (bodies_[i].name == name) return int(i);
  return -1;
}

int Scene::triangle_count() const {
  int n = 0;
  for (const auto& b : bodies_) n += b.tree.triangle_count();
  return n;
}

NearestSurface nearest_surface(const Scene& scene, const ScenePoses& poses,
                               const Eigen::Vector3d& p, double max_distance, bool front_only) {
  NearestSurface best;
  best.distance_mm = max_distance;
  for (int i = 0; i < scene.size(); ++i) {
    const Eigen::Vector3d q = to_body(poses, i, p);
    const AabbTree& tree = scene.body(i).tree;
    if (box_distance_squared(q, tree.bounds_min(), tree.bounds_max()) >=
        best.distance_mm * best.distance_mm)
      continue;
    int tri = -1;
    Eigen::Vector3d c;
    const double d = tree.closest_point(q, best.distance_mm, &tri, &c, front_only);
    if (tri >= 0 && d < best.distance_mm) {
      best.distance_mm = d;
      best.body = i;
      best.triangle = tri;
      best.point_mm = poses.pose[std::size_t(i)].apply(c);
    }
  }
  return best;
}

mesh::TriSurface square_plane(double size_mm, double cell_mm) {
  const int n = std::max(1, int(std::ceil(size_mm / cell_mm)));
  mesh::TriSurface s;
  s.V.resize((n + 1) * (n + 1), 3);
  s.F.resize(2 * n * n, 3);
  for (int i = 0; i <= n; ++i)
    for (int j = 0; j <= n; ++j)
      s.V.row(i * (n + 1) + j) << -size_mm / 2 + size_mm * i / n, -size_mm / 2 + size_mm * j / n, 0;
  int f = 0;
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) {
      const int a = i * (n + 1) + j, b = a + n + 1, c = b + 1, d = a + 1;
      s.F.row(f++) << a, b, c;  // normal +z: (b − a) × (c − a) = x̂ × (x̂ + ŷ) = +ẑ
      s.F.row(f++) << a, c, d;
    }
  return s;
}

}  // namespace spinesim::haptics

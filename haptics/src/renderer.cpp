#include "spinesim/haptics/renderer.hpp"
#include "spinesim/common/constants.hpp"

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace spinesim::haptics {

// ---------------------------------------------------------------------------------------------
// Sphere proxy

SphereProxyRenderer::SphereProxyRenderer(const ProxyParameters& p) : p_(p) {
  if (!(p.radius_mm > 0) || !std::isfinite(p.radius_mm))
    throw std::invalid_argument("probe radius must be > 0 mm");
  if (!(p.stiffness_n_per_mm > 0) || !(p.damping_n_s_per_mm >= 0) || !(p.skin_mm > 0))
    throw std::invalid_argument("proxy: stiffness must be > 0, damping >= 0, skin > 0");
  if (p.max_work < 64) throw std::invalid_argument("proxy: the work bound must be >= 64");
}

void SphereProxyRenderer::reset(const Eigen::Vector3d& device_mm) {
  proxy_ = device_mm;
  anchor_ = -1;
}

Eigen::Vector3d SphereProxyRenderer::proxy_world(const ScenePoses& poses) const {
  return anchor_ < 0 ? proxy_ : poses.pose[std::size_t(anchor_)].apply(proxy_);
}

namespace {

// Projects the goal onto the region the active constraint planes (through `at`, normals n[i])
// allow: the closest point to `goal` on their intersection (one plane: a plane; two: their
// line; three: the point `at`). Only planes the goal lies behind are kept active (Ruspini's
// rule: a constraint the user pulls away from is released).
Eigen::Vector3d constrain_goal(const Eigen::Vector3d& at, const Eigen::Vector3d& goal,
                               const Eigen::Vector3d* n, int count) {
  Eigen::Vector3d g = goal;
  if (count == 1) return g - std::min(0.0, n[0].dot(g - at)) * n[0];
  if (count == 2) {
    // Try each plane alone; if the result still violates the other, use the line.
    for (int k = 0; k < 2; ++k) {
      const Eigen::Vector3d h = goal - std::min(0.0, n[k].dot(goal - at)) * n[k];
      if (n[1 - k].dot(h - at) >= -1e-12) return h;
    }
    Eigen::Vector3d line = n[0].cross(n[1]);
    if (line.norm() < 1e-9) return at;
    line.normalize();
    return at + line.dot(goal - at) * line;
  }
  return at;
}

// Earliest t in [0, 1] at which a sphere of radius r moving from p0 by m touches the triangle
// (a, b, c) with unit normal n, coming from the triangle's front side and approaching it; 2 if
// never. The candidates are the face (a plane at distance r), the three edges (cylinders) and
// the three vertices (spheres), each a quadratic in t (Ericson 2005, 5.5.7).
double sweep_triangle(const Eigen::Vector3d& p0, const Eigen::Vector3d& m, double r,
                      const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c,
                      const Eigen::Vector3d& n) {
  const double h0 = n.dot(p0 - a);
  if (h0 < 0) return 2;  // one-sided: the motion starts behind the triangle
  double best = 2;
  // Face: the centre reaches height r above the plane with its foot inside the triangle.
  const double nm = n.dot(m);
  if (nm < 0) {
    const double t = std::max(0.0, (h0 - r) / -nm);
    if (t <= 1) {
      const Eigen::Vector3d foot = p0 + t * m - (h0 + t * nm) * n;
      const Eigen::Vector3d bary_b = (b - a).cross(foot - a), bary_c = (foot - a).cross(c - a),
                            bary_a = (c - b).cross(foot - b);
      if (bary_b.dot(n) >= 0 && bary_c.dot(n) >= 0 && bary_a.dot(n) >= 0) best = t;
    }
  }
  // Smallest root t >= 0 of |w + t v|² = r² (restricted to directions that approach), or 2.
  auto quadratic = [r](const Eigen::Vector3d& w, const Eigen::Vector3d& v) {
    const double A = v.squaredNorm(), B = w.dot(v), C = w.squaredNorm() - r * r;
    if (B >= 0) return 2.0;  // moving away (or along)
    if (C <= 0) return 0.0;  // already touching and approaching
    const double disc = B * B - A * C;
    if (disc < 0 || A <= 0) return 2.0;
    return (-B - std::sqrt(disc)) / A;
  };
  const Eigen::Vector3d verts[3] = {a, b, c};
  for (int k = 0; k < 3; ++k) {
    const Eigen::Vector3d& e0 = verts[k];
    const Eigen::Vector3d& e1 = verts[(k + 1) % 3];
    const double len = (e1 - e0).norm();
    if (len > 0) {
      const Eigen::Vector3d u = (e1 - e0) / len;
      const Eigen::Vector3d w = p0 - e0;
      const double t = quadratic(w - w.dot(u) * u, m - m.dot(u) * u);
      if (t < best) {
        const double s = (w + t * m).dot(u);
        if (s >= 0 && s <= len) best = t;
      }
    }
    const double t = quadratic(p0 - e0, m);
    if (t < best) best = t;
  }
  return best;
}

}  // namespace

RenderOutput SphereProxyRenderer::render(const ProbeState& probe, const Scene& scene,
                                         const ScenePoses& poses, double) {
  RenderOutput out;
  const double r = p_.radius_mm, skin = p_.skin_mm;
  Eigen::Vector3d proxy = proxy_world(poses);
  const Eigen::Vector3d device = probe.position_mm;
  Eigen::Vector3d goal = device;
  Eigen::Vector3d normals[3];
  int active = 0, touched = -1;
  int budget = p_.max_work;

  for (int iteration = 0; iteration < 4; ++iteration) {
    const Eigen::Vector3d move = goal - proxy;
    const double length = move.norm();
    if (length < 1e-12) break;
    // Earliest contact along the move over every body, each searched along the swept sphere
    // (its tree pruned by the earliest contact so far) within what is left of the tick's
    // budget; the sphere stops `skin` short of it. When the budget runs out, the proxy moves
    // only as far as the search has proven free and the rest waits for the next tick.
    double t_hit = 2, t_free = 1;
    int hit_body = -1, hit_triangle = -1;
    for (int bi = 0; bi < scene.size(); ++bi) {
      const AabbTree& tree = scene.body(bi).tree;
      const auto& pose = poses.pose[std::size_t(bi)];
      const Eigen::Vector3d p0 = pose.R.transpose() * (proxy - pose.t);
      const Eigen::Vector3d m = pose.R.transpose() * move;
      if (tree.root_entry(p0, m, r + 2 * skin) >= std::min(t_hit, t_free)) continue;
      const auto& F = tree.triangles();
      const auto& V = tree.vertices();
      const AabbTree::Sweep sweep = tree.sweep(p0, m, r + 2 * skin, budget, [&](int t) {
        ++out.candidates;
        return sweep_triangle(p0, m, r + skin, V.row(F(t, 0)), V.row(F(t, 1)), V.row(F(t, 2)),
                              tree.normal(t));
      });
      if (sweep.t < t_hit) {
        t_hit = sweep.t;
        hit_body = bi;
        hit_triangle = sweep.triangle;
      }
      if (!sweep.complete) {
        out.truncated = true;
        t_free = std::min(t_free, sweep.t_free);
      }
    }
    if (out.truncated && t_free < std::min(t_hit, 1.0)) {
      // Proven free only up to t_free: go there (short of it by the skin) and stop this tick.
      proxy += std::max(0.0, t_free - skin / length) * move;
      break;
    }
    if (t_hit > 1) {
      proxy = goal;
      break;
    }
    proxy += std::max(0.0, t_hit - 0.1 * skin / length) * move;
    touched = hit_body;
    // Contact normal: from the closest point of the hit triangle to the proxy.
    const AabbTree& tree = scene.body(hit_body).tree;
    const auto& pose = poses.pose[std::size_t(hit_body)];
    const Eigen::Vector3d q = pose.R.transpose() * (proxy - pose.t);
    const auto& F = tree.triangles();
    const auto& V = tree.vertices();
    Eigen::Vector3d n =
        q - closest_point_on_triangle(q, V.row(F(hit_triangle, 0)), V.row(F(hit_triangle, 1)),
                                      V.row(F(hit_triangle, 2)));
    n = n.norm() > 1e-9 ? Eigen::Vector3d(n.normalized()) : tree.normal(hit_triangle);
    n = pose.R * n;
    if (active < 3) normals[active++] = n;
    goal = constrain_goal(proxy, device, normals, active);
    if (active == 3) break;
  }

  out.work = p_.max_work - budget;
  const Eigen::Vector3d spring = proxy - device;
  out.contact = touched >= 0 || spring.norm() > 10 * skin;
  out.body = touched;
  out.proxy_mm = proxy;
  if (out.contact) {
    out.force_n = p_.stiffness_n_per_mm * spring;
    out.penetration_mm = spring.norm();
    out.force_n -= p_.damping_n_s_per_mm * probe.velocity_mm_s;
  }
  // The proxy rides the body it touches (kept in that body's frame); in free space, the world.
  if (touched >= 0) anchor_ = touched;
  if (!out.contact) anchor_ = -1;
  if (anchor_ >= 0) {
    const auto& pose = poses.pose[std::size_t(anchor_)];
    proxy_ = pose.R.transpose() * (proxy - pose.t);
  } else {
    proxy_ = proxy;
  }
  return out;
}

// ---------------------------------------------------------------------------------------------
// Gao & Gibson probe-normal method

GaoGibsonRenderer::GaoGibsonRenderer(const GaoGibsonParameters& p) : p_(p) {
  if (!(p.radius_mm > 0) || !std::isfinite(p.radius_mm))
    throw std::invalid_argument("probe radius must be > 0 mm");
  if (!(p.stiffness > 0) || !(p.damping >= 0) || p.max_triangles < 1)
    throw std::invalid_argument("gao-gibson: stiffness must be > 0 and damping >= 0");
  candidates_.resize(std::size_t(p.max_triangles));
}

RenderOutput GaoGibsonRenderer::render(const ProbeState& probe, const Scene& scene,
                                       const ScenePoses& poses, double) {
  RenderOutput out;
  out.proxy_mm = probe.position_mm;
  const double r = p_.radius_mm;
  double magnitude = 0, deepest = 0, deepest_body_depth = 0;
  Eigen::Vector3d direction = Eigen::Vector3d::Zero();
  int inside = 0;
  for (int b = 0; b < scene.size(); ++b) {
    const RigidBody& body = scene.body(b);
    const Eigen::Vector3d c = to_body(poses, b, probe.position_mm);
    if (box_distance_squared(c, body.tree.bounds_min(), body.tree.bounds_max()) > r * r) continue;
    const auto& R = poses.pose[std::size_t(b)].R;
    const Eigen::Vector3d v = R.transpose() * probe.velocity_mm_s;
    const int found = body.tree.sphere_query(c, r, candidates_.data(), int(candidates_.size()));
    out.candidates += found;
    out.work += std::min(found, int(candidates_.size()));
    if (found > int(candidates_.size())) out.truncated = true;
    const int n = std::min(found, int(candidates_.size()));
    if (n > 0 && body.samples.first.empty())
      throw std::logic_error("gao-gibson: the scene's surfaces were not sampled");
    Eigen::Vector3d body_direction = Eigen::Vector3d::Zero();
    double body_deepest = 0;
    for (int k = 0; k < n; ++k) {
      const int t = candidates_[std::size_t(k)];
      for (int i = body.samples.first[std::size_t(t)]; i < body.samples.first[std::size_t(t) + 1];
           ++i) {
        const Eigen::Vector3d d = body.samples.points.row(i).transpose() - c;
        const double dist = d.norm();
        const double s = r - dist;  // depth along the probe's normal (radial for a sphere)
        if (s <= 0 || dist < 1e-12) continue;
        const Eigen::Vector3d normal = d / dist;  // the probe surface's outward normal there
        const double s_dot = normal.dot(v);       // the depth grows as the probe moves towards it
        magnitude += (p_.stiffness * s + p_.damping * s_dot) * body.samples.area_mm2(i);
        body_direction += normal * s;
        body_deepest = std::max(body_deepest, s);
        ++inside;
      }
    }
    direction += R * body_direction;
    if (body_deepest > deepest_body_depth) {
      deepest_body_depth = body_deepest;
      out.body = b;
    }
    deepest = std::max(deepest, body_deepest);
  }
  if (inside == 0) return out;
  if (p_.law == GaoGibsonLaw::eq_4_10) magnitude /= kPi * r * r;
  magnitude = std::max(magnitude, 0.0);  // a surface pushes, it never pulls
  // Eq 4.11: the depth-weighted mean of the probe normals points from the probe into the
  // surface; the reaction on the probe is opposite.
  out.contact = true;
  out.penetration_mm = deepest;
  if (direction.norm() > 1e-12) out.force_n = -magnitude * direction.normalized();
  return out;
}

}  // namespace spinesim::haptics

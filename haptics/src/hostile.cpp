#include "spinesim/haptics/hostile.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace spinesim::haptics {

namespace {

constexpr double kPi = 3.14159265358979323846;

struct Box {
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(1e300), hi = Eigen::Vector3d::Constant(-1e300);
  void add(const Eigen::Vector3d& x) {
    lo = lo.cwiseMin(x);
    hi = hi.cwiseMax(x);
  }
  Eigen::Vector3d centre() const { return 0.5 * (lo + hi); }
  Eigen::Vector3d size() const { return hi - lo; }
};

// Where the trajectories go: the scene's box, its longest and shortest axes, and for each body
// its box and the centre of its vertices (world frame).
struct Layout {
  Box scene;
  std::vector<Box> bodies;
  std::vector<Eigen::Vector3d> centres;   ///< a point deep inside each body
  std::vector<Eigen::Vector3d> extremes;  ///< each body's vertex furthest towards −across
  Eigen::Vector3d along = Eigen::Vector3d::UnitX(), across = Eigen::Vector3d::UnitZ();
  double length = 0, depth = 0;
};

// A point deep inside a body (reference frame): of the points 2–16 mm behind the centres of
// about 64 of its triangles, the inside one furthest from the surface. (A vertebra's vertex
// mean lies in its spinal canal, outside the bone.) The vertex mean if none is inside.
Eigen::Vector3d deep_inside(const AabbTree& tree) {
  const auto& V = tree.vertices();
  const auto& F = tree.triangles();
  Eigen::Vector3d best = V.colwise().mean().transpose();
  double deepest = 0;
  const int step = std::max(1, tree.triangle_count() / 64);
  for (int t = 0; t < tree.triangle_count(); t += step) {
    const Eigen::Vector3d c = (V.row(F(t, 0)) + V.row(F(t, 1)) + V.row(F(t, 2))).transpose() / 3.0;
    for (const double d : {2.0, 4.0, 8.0, 16.0}) {
      const Eigen::Vector3d p = c - d * tree.normal(t);
      const double distance = tree.closest_point(p, 1e3, nullptr, nullptr);
      if (distance > deepest && winding_number(tree, p) > 0.5) {
        deepest = distance;
        best = p;
      }
    }
  }
  return best;
}

Layout layout_of(const Scene& scene, const ScenePoses& poses) {
  if (scene.size() == 0) throw std::invalid_argument("hostile trajectories: the scene is empty");
  Layout l;
  for (int b = 0; b < scene.size(); ++b) {
    const auto& V = scene.body(b).tree.vertices();
    const spine::Pose& pose = poses.pose[std::size_t(b)];
    Box box;
    for (Eigen::Index i = 0; i < V.rows(); ++i) {
      const Eigen::Vector3d x = pose.apply(V.row(i).transpose());
      box.add(x);
      l.scene.add(x);
    }
    l.bodies.push_back(box);
    l.centres.push_back(pose.apply(deep_inside(scene.body(b).tree)));
  }
  int a = 0, c = 0;
  l.scene.size().maxCoeff(&a);
  l.scene.size().minCoeff(&c);
  if (a == c) c = (a + 1) % 3;
  l.along = Eigen::Vector3d::Unit(a);
  l.across = Eigen::Vector3d::Unit(c);
  l.length = l.scene.size()[a];
  l.depth = l.scene.size()[c];
  for (int b = 0; b < scene.size(); ++b) {
    const auto& V = scene.body(b).tree.vertices();
    const spine::Pose& pose = poses.pose[std::size_t(b)];
    Eigen::Vector3d best = pose.apply(V.row(0).transpose());
    for (Eigen::Index i = 1; i < V.rows(); ++i) {
      const Eigen::Vector3d x = pose.apply(V.row(i).transpose());
      if (x[c] < best[c]) best = x;
    }
    l.extremes.push_back(best);
  }
  return l;
}

struct Builder {
  Trajectory t;
  void at(double time, const Eigen::Vector3d& x, unsigned button = 0) {
    t.t_s.push_back(time);
    t.position_mm.push_back(x);
    t.buttons.push_back(button);
  }
  double end() const { return t.t_s.empty() ? 0 : t.t_s.back(); }
  // Holds `x` for `seconds` after a jump to it (the jump takes 1 ms).
  void jump_and_hold(const Eigen::Vector3d& x, double seconds, unsigned button = 0) {
    const double t0 = t.t_s.empty() ? 0 : end() + 0.001;
    at(t0, x, button);
    at(t0 + seconds, x, button);
  }
  void move_to(const Eigen::Vector3d& x, double seconds, unsigned button = 0) {
    at(end() + seconds, x, button);
  }
};

// A point outside the scene's box, level with `x` along the shortest axis's negative side.
Eigen::Vector3d outside(const Layout& l, const Eigen::Vector3d& x) {
  return x + (l.scene.lo.dot(l.across) - x.dot(l.across) - 30.0) * l.across;
}

// The middle body (by index), and its surface point furthest to the −across side (a vertex:
// on the surface whatever the body's shape).
int middle(const Layout& l) { return int(l.bodies.size()) / 2; }
Eigen::Vector3d face_point(const Layout& l, int b) { return l.extremes[std::size_t(b)]; }

Trajectory teleport(const Layout& l) {
  Builder b;
  const int n = int(l.bodies.size()), picks = std::min(n, 6);
  for (int k = 0; k < picks; ++k) {
    const int body = picks == 1 ? 0 : k * (n - 1) / (picks - 1);
    const Eigen::Vector3d c = l.centres[std::size_t(body)];
    b.jump_and_hold(outside(l, c), 0.1);
    b.jump_and_hold(c, 0.15);
  }
  b.jump_and_hold(outside(l, l.centres.back()), 0.1);
  return b.t;
}

Trajectory start_inside(const Layout& l) {
  Builder b;
  const Eigen::Vector3d c = l.centres[std::size_t(middle(l))];
  b.at(0, c);
  b.move_to(c, 0.3);
  b.move_to(outside(l, c), 0.5);
  b.move_to(outside(l, c), 0.2);
  return b.t;
}

Trajectory sweep(const Layout& l, double offset_mm) {
  const double speed_mm_s = 2500;
  const Eigen::Vector3d mid = l.scene.centre() + offset_mm * l.across;
  const Eigen::Vector3d p = mid - (0.5 * l.length + 30) * l.along,
                        q = mid + (0.5 * l.length + 30) * l.along;
  const double leg = (q - p).norm() / speed_mm_s;
  Builder b;
  b.at(0, p);
  b.move_to(p, 0.1);
  for (int k = 0; k < 3; ++k) {
    b.move_to(q, leg);
    b.move_to(p, leg);
  }
  b.move_to(p, 0.1);
  return b.t;
}

Trajectory shake(const Layout& l) {
  const Eigen::Vector3d s = face_point(l, middle(l));
  Builder b;
  b.at(0, s - 40 * l.across);
  b.move_to(s, 0.2);
  for (int k = 1; k <= 1000; ++k)  // 1 s at 30 Hz, a set-point every ms
    b.move_to(s + 8 * std::sin(2 * kPi * 30 * k * 1e-3) * l.across, 0.001);
  b.move_to(s - 40 * l.across, 0.2);
  return b.t;
}

Trajectory hammer(const Layout& l) {
  const Eigen::Vector3d s = face_point(l, middle(l)) + 2 * l.across;
  Builder b;
  b.at(0, s - 40 * l.across);
  b.move_to(s, 0.2);
  // 1.6 s dragged ±20 mm along the long axis (0.625 Hz), the button toggled every 20 ms.
  for (int k = 1; k <= 80; ++k) {
    const double phase = 2 * kPi * k / 80.0;
    b.move_to(s + 20 * std::sin(phase) * l.along, 0.02, unsigned(k % 2));
  }
  b.move_to(s - 40 * l.across, 0.2);
  return b.t;
}

}  // namespace

const std::vector<std::string>& hostile_names() {
  static const std::vector<std::string> names = {"teleport", "start-inside", "sweep",
                                                 "skim",     "shake",        "hammer"};
  return names;
}

void check_hostile_name(const std::string& name) {
  std::string known;
  for (const std::string& n : hostile_names()) {
    if (n == name) return;
    known += (known.empty() ? "" : ", ") + n;
  }
  throw std::invalid_argument("no such hostile trajectory '" + name + "' (there are: " + known +
                              ")");
}

Trajectory hostile_trajectory(const std::string& name, const Scene& scene,
                              const ScenePoses& poses) {
  check_hostile_name(name);
  const Layout l = layout_of(scene, poses);
  if (name == "teleport") return teleport(l);
  if (name == "start-inside") return start_inside(l);
  if (name == "sweep") return sweep(l, 0);
  if (name == "skim") return sweep(l, -0.35 * l.depth);
  if (name == "shake") return shake(l);
  return hammer(l);
}

}  // namespace spinesim::haptics

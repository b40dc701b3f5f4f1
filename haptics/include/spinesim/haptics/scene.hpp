// The rigid stage's scene: the vertebrae (and sacrum) as rigid bodies, each with its surface in
// its own reference coordinates, its AABB tree and the surface sample points of the Gao–Gibson
// renderer; their current poses arrive separately (ScenePoses), so bodies move without a
// rebuild.
#pragma once

#include "spinesim/haptics/aabb_tree.hpp"
#include "spinesim/mesh/io.hpp"
#include "spinesim/spine/kinematics.hpp"

#include <Eigen/Core>

#include <array>
#include <string>
#include <vector>

namespace spinesim::haptics {

/// At most this many bodies (the spine has 18: T1…L5 and the sacrum).
inline constexpr int kMaxBodies = 48;  ///< the spine's 18 bodies and the rib cage's 25

/// Points on a surface for the probe-normal method: every triangle is cut into an n × n grid of
/// similar sub-triangles (n = ⌈longest edge / spacing⌉) and each sub-triangle's centroid is a
/// sample carrying that sub-triangle's area, so Σ area = the surface area exactly and a sum
/// Σ g(p_i) a_i is a midpoint-rule integral of g over the surface.
struct SurfaceSamples {
  double spacing_mm = 0;
  Eigen::MatrixX3d points;   ///< all samples, reference coordinates, mm
  Eigen::VectorXd area_mm2;  ///< the area each sample stands for
  std::vector<int> first;    ///< samples of triangle t: [first[t], first[t+1])
};
SurfaceSamples sample_surface(const mesh::TriSurface& s, double spacing_mm);

struct RigidBody {
  std::string name;
  AabbTree tree;           ///< over the surface in reference coordinates
  SurfaceSamples samples;  ///< empty unless the Gao–Gibson renderer asked for them
};

/// Poses of the bodies: x_world = R x_reference + t. Copying allocates nothing.
struct ScenePoses {
  std::array<spine::Pose, kMaxBodies> pose;
  double time_s = 0;  ///< when the poses were computed (for the watchdog's staleness check)
};

class Scene {
 public:
  /// Adds a body; throws std::invalid_argument beyond kMaxBodies, for an empty surface or for a
  /// name already in the scene (bodies are found by name).
  void add_body(const std::string& name, const mesh::TriSurface& surface);
  /// Samples every body's surface for the Gao–Gibson renderer (spacing in mm, > 0).
  void sample_surfaces(double spacing_mm);
  int size() const { return int(bodies_.size()); }
  const RigidBody& body(int i) const { return bodies_[std::size_t(i)]; }
  int index(const std::string& name) const;  ///< −1 when absent
  int triangle_count() const;

 private:
  std::vector<RigidBody> bodies_;
};

/// The probe centre in body i's reference frame.
inline Eigen::Vector3d to_body(const ScenePoses& poses, int i, const Eigen::Vector3d& world) {
  const auto& p = poses.pose[std::size_t(i)];
  return p.R.transpose() * (world - p.t);
}

/// Distance from `p` (world) to the nearest surface of the scene within `max_distance`
/// (max_distance if none), one-sided when `front_only`; body, triangle and closest point (world)
/// of the nearest. No allocation.
struct NearestSurface {
  double distance_mm = 0;
  int body = -1, triangle = -1;
  Eigen::Vector3d point_mm = Eigen::Vector3d::Zero();
};
NearestSurface nearest_surface(const Scene& scene, const ScenePoses& poses,
                               const Eigen::Vector3d& p, double max_distance, bool front_only);

/// A plane (z = 0 in its frame, normal +z, a square of side `size_mm`) triangulated on a grid of
/// `cell_mm` — the Gao–Gibson plane test's surface.
mesh::TriSurface square_plane(double size_mm, double cell_mm);

}  // namespace spinesim::haptics

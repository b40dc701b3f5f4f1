#include "spinesim/mesh/disc_level.hpp"

#include "spinesim/mesh/disc_geometry.hpp"

#include <Eigen/Geometry>

#include <algorithm>
#include <stdexcept>
#include <string>

namespace spinesim::mesh {

DiscFrame disc_level_frame(const std::string& level, const std::string& data_dir,
                           DiscPlacement placement) {
  const auto dims = disc_dimensions(level, data_dir);  // refuses an unknown level
  return placement == DiscPlacement::spine ? disc_frame_in_spine(dims.level, data_dir)
                                           : DiscFrame();
}

TetMesh mesh_disc_level(const std::string& level, const MeshOptions& options,
                        const std::string& data_dir, DiscPlacement placement) {
  const auto dims = disc_dimensions(level, data_dir);
  return mesh_parametric_disc(dims, options, disc_level_frame(dims.level, data_dir, placement));
}

TetMesh mesh_disc_level(const std::string& level, double cell_size_mm,
                        const std::string& data_dir) {
  MeshOptions options;
  options.cell_size_mm = cell_size_mm;
  return mesh_disc_level(level, options, data_dir);
}

TetMesh mesh_structured_level(const std::string& level, const StructuredDiscOptions& options,
                              const std::string& data_dir, DiscPlacement placement) {
  const auto dims = disc_dimensions(level, data_dir);
  return mesh_structured_disc(dims, options, disc_level_frame(dims.level, data_dir, placement));
}

void carry_between(TetMesh& m, const DiscFrame& frame, double height_mm, const RigidMotion& lower,
                   const RigidMotion& upper) {
  if (!(height_mm > 0))
    throw std::invalid_argument("carry_between: the disc height must be > 0 mm");
  const TetMesh before = m;
  const DiscFrame f = frame;  // `frame` may be m.frame, which is carried below
  for (Eigen::Index i = 0; i < m.V.rows(); ++i) {
    const Eigen::Vector3d x = before.V.row(i).transpose();
    const double y = (f.axes.transpose() * (x - f.origin_mm)).y();
    const double s = std::clamp((y + 0.5 * height_mm) / height_mm, 0.0, 1.0);
    m.V.row(i) = ((1 - s) * lower.apply(x) + s * upper.apply(x)).transpose();
  }
  // The disc's own frame goes to mid-height: its origin midway, its axes turned halfway from the
  // lower vertebra's rotation to the upper one's (the mid-plane of a wedged disc).
  Eigen::AngleAxisd turn(lower.R.transpose() * upper.R);
  turn.angle() *= 0.5;
  m.frame.origin_mm = 0.5 * (lower.apply(f.origin_mm) + upper.apply(f.origin_mm));
  m.frame.axes = lower.R * turn.toRotationMatrix() * f.axes;
  for (Eigen::Index t = 0; t < m.T.rows(); ++t)
    if (!(tet_volume(m, t) > 0))
      throw std::invalid_argument("carry_between: tet " + std::to_string(t) +
                                  " inverts between the posed vertebrae");
}

}  // namespace spinesim::mesh

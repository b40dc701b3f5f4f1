// A closed tube swept along a smooth curve through given points: the surface of the long, thin
// bones (the ribs with their cartilage, the sternum) that the viewer draws and the probe touches.
// Units: mm.
#pragma once

#include "spinesim/mesh/io.hpp"

#include <Eigen/Core>

#include <vector>

namespace spinesim::mesh {

struct TubeOptions {
  int sides = 12;             ///< vertices around each ring (>= 3)
  int rings_per_segment = 8;  ///< rings from one given point to the next (>= 1)
  /// The cross-section's first axis at the start, projected normal to the curve and then
  /// carried along it without twist (parallel transport); zero: any normal.
  Eigen::Vector3d width_direction = Eigen::Vector3d::Zero();
};

/// A closed, outward-oriented tube through `points` — a uniform Catmull–Rom curve, which passes
/// through every point, its ends extended by reflection — with an elliptical cross-section of
/// half-axes `width_mm[i]` (along the carried axis) and `depth_mm[i]` at point i, linear in
/// between, and flat caps. Throws std::invalid_argument for fewer than 2 points, sizes that do
/// not match, a half-axis that is not > 0, two consecutive points closer than 1e-6 mm, or bad
/// options.
TriSurface tube_surface(const std::vector<Eigen::Vector3d>& points,
                        const std::vector<double>& width_mm, const std::vector<double>& depth_mm,
                        const TubeOptions& options = {});

}  // namespace spinesim::mesh

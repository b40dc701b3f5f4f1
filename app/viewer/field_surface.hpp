// A tetrahedral mesh seen from outside, coloured by a field: its boundary triangles (each on the
// tet that owns it) as a viewer Body, with one colour per triangle from a point field (the mean
// over the triangle's corners) or a cell field (the owning tet's value). Shared by the live
// session (the palpated disc) and the playback of a series (the spine's discs).
#pragma once

#include "spinesim/viewer/viewer.hpp"

#include <Eigen/Core>

#include <string>

namespace spinesim::viewer {

/// The fields a disc is coloured by, with their units.
enum class DiscField { displacement, spring_strain, volume_change };
inline constexpr const char* kDiscFieldNames[3] = {"displacement", "spring_strain",
                                                   "volume_change"};
inline constexpr const char* kDiscFieldLabels[3] = {
    "displacement |u| (mm)", "spring strain (l - L)/L, largest of the tet's edges",
    "volume change (V - V0)/V0 of the tet"};
/// Throws std::invalid_argument (one line) for another name.
DiscField disc_field(const std::string& name);

class FieldSurface {
 public:
  FieldSurface() = default;
  /// The boundary of tetrahedra T (#T×4) over #V points.
  explicit FieldSurface(const Eigen::MatrixXi& T);
  bool empty() const { return owner_.size() == 0; }
  /// Per-triangle values of a point field (#V: the corners' mean) or a cell field (#T).
  Eigen::VectorXd from_points(const Eigen::VectorXd& point_values) const;
  Eigen::VectorXd from_cells(const Eigen::VectorXd& cell_values) const;
  /// The colour range for `values`: symmetric about 0 for a signed field, [0, max] otherwise,
  /// at least `floor` wide (so that a field at rest shows its lowest colour, not noise).
  /// Non-finite values are ignored (and drawn grey).
  static void range(const Eigen::VectorXd& values, double floor, double& lo, double& hi);
  /// The same for a point field (#V), over the surface's own points: the legend then reaches the
  /// deepest point (a pressed node), which the triangles' corner means fall short of.
  void point_range(const Eigen::VectorXd& point_values, double floor, double& lo, double& hi) const;
  /// `body` shows the surface at `V` (#V×3) coloured by `values` on [lo, hi].
  void fill(Body& body, const Eigen::MatrixX3d& V, const Eigen::VectorXd& values, double lo,
            double hi) const;
  const Eigen::MatrixX3i& faces() const { return F_; }
  const Eigen::VectorXi& owners() const { return owner_; }

 private:
  Eigen::MatrixX3i F_;
  Eigen::VectorXi owner_;
};

}  // namespace spinesim::viewer

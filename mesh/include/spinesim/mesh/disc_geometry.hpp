// Parametric disc geometry for the 17 thoracolumbar levels T1-T2 ... L5-S1.
//
// Cross-section: a kidney-shaped closed curve (posterior concavity) of lateral width W and
// antero-posterior depth D; the nucleus is the same curve scaled by sqrt(0.4) about the
// area centroid, i.e. 40 % of the cross-section area (thesis 5.2.5, Krismer et al. 1996).
// The lower outline (inferior vertebra's upper endplate) and the upper outline (superior
// vertebra's lower endplate) may differ in size; the wall is the linear loft between them.
// Dimensions come from data/disc_morphometry.csv (each value cited there).
#pragma once

#include "spinesim/mesh/tet_mesh.hpp"

#include <Eigen/Core>

#include <string>
#include <vector>

namespace spinesim::mesh {

/// One level's sourced dimensions, mm.
struct DiscDimensions {
  std::string level;          ///< e.g. "L4-L5"
  double lower_width_mm = 0;  ///< lateral width of the lower outline
  double lower_depth_mm = 0;  ///< antero-posterior depth of the lower outline
  double upper_width_mm = 0;
  double upper_depth_mm = 0;
  double height_mm = 0;  ///< mid-disc height
};

/// Nucleus share of the cross-section area (thesis 5.2.5).
inline constexpr double kNucleusAreaFraction = 0.4;

/// Kidney-shaped closed curve in the transverse (x lateral, z anterior) plane, mm.
///
/// Shape: an ellipse in polar form r_e(θ) = ab / sqrt((b cos θ)^2 + (a sin θ)^2), a = 1,
/// b = 0.75, with a smooth posterior indentation r(θ) = r_e(θ) (1 - δ ((1 - sin θ)/2)^n),
/// δ = 0.3, n = 16 (a notch ≈ 7 % of the depth deep, ≈ 50° wide, at θ = -90°, the posterior
/// midpoint; concave there since r'' > r), then scaled
/// separately in x and z so that the x-extent is exactly `width_mm` and the z-extent exactly
/// `depth_mm`, and shifted so that the area centroid is the origin. x = sx r cos θ,
/// z = sz r sin θ - shift, θ in [0, 2π) counter-clockwise from +x towards +z (anterior).
/// The curve is star-shaped about (0, -shift), so `contains` is an exact O(1) test.
class KidneyOutline {
 public:
  KidneyOutline(double width_mm, double depth_mm);  ///< throws std::invalid_argument if <= 0

  double width_mm() const { return width_; }
  double depth_mm() const { return depth_; }
  Eigen::Vector2d point(double theta) const;          ///< (x, z) on the curve, mm
  bool contains(const Eigen::Vector2d& xz_mm) const;  ///< inside or on the curve
  /// Signed curvature (1/mm) at θ: > 0 convex, < 0 concave (posterior notch).
  double signed_curvature(double theta) const;
  double area_mm2() const;              ///< exact up to ~1e-13 (spectral trapezoid rule)
  Eigen::Vector2d centroid_mm() const;  ///< area centroid, (0, 0) up to round-off
  double min_z_mm() const;              ///< posterior extreme; max_z = min_z + depth
  /// Nucleus test: the outline scaled by sqrt(kNucleusAreaFraction) about the centroid.
  bool nucleus_contains(const Eigen::Vector2d& xz_mm) const;
  /// `n` points of the outline (θ_k = 2πk/n), scaled by `scale` about the centroid.
  std::vector<Eigen::Vector2d> sample(int n, double scale = 1.0) const;

 private:
  double width_, depth_, sx_, sz_, shift_;
};

/// The disc body in its local frame: y in [-h/2, h/2], outline at height y = KidneyOutline of
/// linearly interpolated width and depth (lower at y = -h/2, upper at y = +h/2). The area
/// centroid of every cross-section lies on the y axis.
class ParametricDisc {
 public:
  explicit ParametricDisc(const DiscDimensions& dims);  ///< throws std::invalid_argument
  const DiscDimensions& dims() const { return dims_; }
  KidneyOutline outline_at(double y_mm) const;
  /// 0 outside, 1 annulus, 2 nucleus (local coordinates, mm).
  int label(const Eigen::Vector3d& p_local_mm) const;
  /// Boundary facet (centroid, outward unit normal; local frame) -> nearest bounding surface.
  Surface classify_facet(const Eigen::Vector3d& centroid_mm, const Eigen::Vector3d& normal) const;
  /// Exact volume, mm^3: h [w0 d0 + (w0 Δd + d0 Δw)/2 + Δw Δd / 3] · A(1×1 outline).
  double volume_mm3() const;
  /// Sharp edges as closed polylines (first point repeated last), local frame, ~`spacing_mm`
  /// apart: lower and upper rim, and the nucleus/annulus junction on both endplates.
  std::vector<std::vector<Eigen::Vector3d>> feature_polylines(double spacing_mm) const;

 private:
  DiscDimensions dims_;
};

/// The 17 level names in cranial-to-caudal order: "T1-T2", ..., "L5-S1".
const std::vector<std::string>& disc_levels();

/// Reads data/disc_morphometry.csv; throws std::invalid_argument for an unknown level
/// (the message lists the known ones).
DiscDimensions disc_dimensions(const std::string& level, const std::string& data_dir);

/// Where the disc sits in the spine model: origin at the table F.2 joint point of the level,
/// axial direction from the inferior to the superior vertebra centre (table F.1), lateral
/// axis = global x. Reads data/thesis/F1_vertebra_cm.csv and F2_joint_markers.csv.
DiscFrame disc_frame_in_spine(const std::string& level, const std::string& data_dir);

}  // namespace spinesim::mesh

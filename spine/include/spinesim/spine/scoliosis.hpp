// A scoliotic spine (spine/README.md, "Scoliotic spines"): a lateral curve described as a
// radiograph is read — the Cobb angle between its end vertebrae, its apex, the apical vertebra's
// axial rotation and the side of its convexity — turned into the rest posture θ0 of the model's
// joints. The curve is structural: the joints (the wedged discs) are stress-free at θ0, so the
// spine stands in its curve without muscle effort, and loads bend it from there.
//
// The posture, per joint (θ_z lateral bending, θ_y axial rotation; small per joint):
// - primary curve: the joints between the lower and the upper end vertebra bend toward the
//   concavity, each by a share of the Cobb angle that follows a half sine over the curve with
//   its peak at the apex (apex in the curve's middle: sin(π s); elsewhere the two halves are
//   stretched to meet at the apex). The shares are scaled until the Cobb angle measured on the
//   posed vertebrae (their frontal-plane tilts) equals the asked one.
// - compensatory curves: the joints above the upper and below the lower end vertebra bend the
//   other way (half sines again), by the two amounts that leave T1 level and over the sacrum
//   (balanced in the frontal plane). A curve that ends at T1 or at L5 has one compensatory curve,
//   which balances T1's position (its tilt then stays).
// - axial rotation: each vertebra of the curve turns toward the convexity by the apical rotation
//   times its distance from the nearer end vertebra relative to the apex's (linear), relative to
//   the end vertebrae.
// A joint bent beyond the angle that would close its disc's concave side (tan θ = 2 h / w,
// disc_morphometry.csv, scaled with the body) cannot be posed: refused.
//
// Units: deg in the curve, rad in θ; frame of the spine model (x lateral, the body's right −x;
// y up; z anterior).
#pragma once

#include "spinesim/spine/model.hpp"

#include <Eigen/Core>

#include <string>
#include <vector>

namespace spinesim::spine {

/// The common curve types and their usual extent: "thoracic" (T5–T11, apex T8, convex right),
/// "thoracolumbar" (T10–L2, apex T12, convex right) and "lumbar" (T12–L4, apex L2, convex left)
/// with the given Cobb angle (apex regions: Lenke et al. 2001; the end vertebrae typical ones,
/// an assumption). Throws std::invalid_argument naming the types for another name.
ScoliosisCurve scoliosis_curve(const std::string& type, double cobb_deg);

/// The curve types scoliosis_curve knows.
const std::vector<std::string>& scoliosis_curve_types();

/// Throws std::invalid_argument (one line) for a Cobb angle outside 0 < c ≤ 120°, an unknown
/// vertebra, ends out of order, an apex outside the curve, a curve of fewer than two joints or an
/// axial rotation beyond ±45°.
void check_scoliosis_curve(const ScoliosisCurve& c);

struct ScoliosisPosture {
  Eigen::VectorXd theta;           ///< the rest posture, rad, 3 per joint
  double cobb_deg = 0;             ///< measured on the posed vertebrae
  double apex_offset_mm = 0;       ///< the apical vertebra's centre from the line through the ends
  double apical_rotation_deg = 0;  ///< measured: the apex's axial turn against the ends' mean
  double t1_offset_mm = 0;         ///< T1's centre from the sacrum's vertical, lateral (+x left)
  double t1_tilt_deg = 0;          ///< T1's frontal-plane tilt
  double largest_share = 0;        ///< the largest |θ_z| over its disc's closing angle (≤ 1)
  std::string largest_share_joint;
};

/// The rest posture of `m` for the curve. Throws std::invalid_argument (one line) for a bad
/// curve (check_scoliosis_curve) or one that would close a disc (its joint named).
ScoliosisPosture scoliotic_posture(const SpineModel& m, const ScoliosisCurve& c);

/// The frontal-plane tilt of a vertebra turned by R, as an AP radiograph shows it: the angle of
/// its endplates (its lateral axis R·x̂ projected onto the frontal plane) from the horizontal,
/// positive when its long axis leans toward +x (the body's left), deg.
double frontal_tilt_deg(const Eigen::Matrix3d& R);

}  // namespace spinesim::spine

// The three angle springs of one triangle face evaluated together — the hot loop of the MSS
// force evaluation (thesis (5.6)-(5.8): ~3 springs per face, ~6 faces per node).
//
// Same energy as three calls of angle_spring (elements.hpp), E = sum_c 1/2 k (theta_c - theta0_c)^2,
// but sharing what the corners share: the face normal n = (x1-x0) x (x2-x0) (every corner's
// |a x b| equals |n|), the edge vectors and squared lengths, and 1/|n|. theta_c - theta0_c comes
// from one atan2 of the rotation between the rest and current corner directions,
//   dtheta = atan2(s cos0 - d sin0, d cos0 + s sin0),  s = |a x b|, d = a.b,
// evaluated by an odd Taylor series when |dtheta| is small (the usual case: |y/x| < 0.1, the
// series to z^17 is exact to round-off) and by std::atan2 otherwise. Measured (bench_mss,
// L4-L5 5k tets): std::atan2 of theta was 35 % of the whole force evaluation.
// Tested against angle_spring in tests/mss/test_face_angles.cpp.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <cmath>

namespace spinesim::mss {

struct FaceRest {
  double cos0[3], sin0[3];  ///< cos and sin of the rest angle at corners 0, 1, 2
};

/// atan(y/x) for x > 0, |y| < 0.1 x by series, else atan2(y, x).
inline double small_angle_atan2(double y, double x) {
  if (x > 0.0 && std::abs(y) < 0.1 * x) {
    const double z = y / x, z2 = z * z;
    // atan z = z - z^3/3 + z^5/5 - ... ; truncation < 0.1^19/19 relative: below round-off.
    double p = -1.0 / 17.0;
    p = p * z2 + 1.0 / 15.0;
    p = p * z2 - 1.0 / 13.0;
    p = p * z2 + 1.0 / 11.0;
    p = p * z2 - 1.0 / 9.0;
    p = p * z2 + 1.0 / 7.0;
    p = p * z2 - 1.0 / 5.0;
    p = p * z2 + 1.0 / 3.0;
    p = p * z2 - 1.0;
    return -z * p;
  }
  return std::atan2(y, x);
}

/// Energy of the face's three angle springs (stiffness k each); adds dE/dx to g0, g1, g2 when
/// `with_gradient`. Corner c is the angle at x_c between the arms to the other two vertices.
template <bool with_gradient>
inline double face_angle_springs(const double* x0, const double* x1, const double* x2, double k,
                                 const FaceRest& rest, double* g0, double* g1, double* g2) {
  using V3 = Eigen::Vector3d;
  const Eigen::Map<const V3> p0(x0), p1(x1), p2(x2);
  const V3 e01 = p1 - p0, e12 = p2 - p1, e20 = p0 - p2;
  const double s = e01.cross(e20).norm();  // |a x b| of every corner, = 2 area
  const double l01 = e01.squaredNorm(), l12 = e12.squaredNorm(), l20 = e20.squaredNorm();
  // Corner c: a = next edge out of x_c, b = minus the edge into x_c; d = a.b.
  const double d0 = -e01.dot(e20), d1 = -e12.dot(e01), d2 = -e20.dot(e12);
  const double dt0 = small_angle_atan2(s * rest.cos0[0] - d0 * rest.sin0[0], d0 * rest.cos0[0] + s * rest.sin0[0]);
  const double dt1 = small_angle_atan2(s * rest.cos0[1] - d1 * rest.sin0[1], d1 * rest.cos0[1] + s * rest.sin0[1]);
  const double dt2 = small_angle_atan2(s * rest.cos0[2] - d2 * rest.sin0[2], d2 * rest.cos0[2] + s * rest.sin0[2]);
  const double energy = 0.5 * k * (dt0 * dt0 + dt1 * dt1 + dt2 * dt2);
  if constexpr (with_gradient) {
    if (!(s > 0.0)) return energy;  // flat triangle: no direction to turn in (as angle_spring)
    const double inv_s = 1.0 / s;
    // d theta_c / d a = (d/|a|^2 a - b)/s,  d theta_c / d b = (d/|b|^2 b - a)/s.
    const double f0 = k * dt0 * inv_s, f1 = k * dt1 * inv_s, f2 = k * dt2 * inv_s;
    // corner 0: a = e01 (to x1), b = -e20 (to x2)
    const V3 ga0 = f0 * (d0 / l01 * e01 + e20), gb0 = f0 * (-d0 / l20 * e20 - e01);
    // corner 1: a = e12 (to x2), b = -e01 (to x0)
    const V3 ga1 = f1 * (d1 / l12 * e12 + e01), gb1 = f1 * (-d1 / l01 * e01 - e12);
    // corner 2: a = e20 (to x0), b = -e12 (to x1)
    const V3 ga2 = f2 * (d2 / l20 * e20 + e12), gb2 = f2 * (-d2 / l12 * e12 - e20);
    Eigen::Map<V3> G0(g0), G1(g1), G2(g2);
    G0 += -(ga0 + gb0) + gb1 + ga2;
    G1 += ga0 - (ga1 + gb1) + gb2;
    G2 += gb0 + ga1 - (ga2 + gb2);
  }
  return energy;
}

}  // namespace spinesim::mss

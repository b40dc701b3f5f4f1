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

#include <algorithm>
#include <cmath>
#include <vector>

namespace spinesim::mss {

struct FaceRest {
  double cos0[3], sin0[3];  ///< cos and sin of the rest angle at corners 0, 1, 2
};

/// atan z for |z| < 0.1: z - z^3/3 + z^5/5 - ... to z^17; the truncation, < 0.1^19/19
/// relative, is below round-off.
inline double atan_series(double z) {
  const double z2 = z * z;
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

/// atan(y/x) for x > 0, |y| < 0.1 x by series, else atan2(y, x).
inline double small_angle_atan2(double y, double x) {
  if (x > 0.0 && std::abs(y) < 0.1 * x) return atan_series(y / x);
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
  const double dt0 =
      small_angle_atan2(s * rest.cos0[0] - d0 * rest.sin0[0], d0 * rest.cos0[0] + s * rest.sin0[0]);
  const double dt1 =
      small_angle_atan2(s * rest.cos0[1] - d1 * rest.sin0[1], d1 * rest.cos0[1] + s * rest.sin0[1]);
  const double dt2 =
      small_angle_atan2(s * rest.cos0[2] - d2 * rest.sin0[2], d2 * rest.cos0[2] + s * rest.sin0[2]);
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

/// Faces packed for face_angle_springs_blocks: kFaceBlock faces in structure-of-arrays form
/// (16: measured 18 % faster than 8 with AVX-512, about equal with AVX2; 4 was slower)
/// — corner indices, rest cos and sin, stiffness — so the hot loop reads 68 bytes a face in
/// sequence instead of the model's whole face records. Padding lanes repeat the last face with
/// k = 0.
inline constexpr int kFaceBlock = 16;
struct FaceBlock {
  int n = 0;  ///< faces in use
  int v[3][kFaceBlock];
  double c0[3][kFaceBlock], s0[3][kFaceBlock], k[kFaceBlock];
};

/// `faces` (each with v[3] and rest) in blocks; k_of(face) is its stiffness.
template <class Face, class KOf>
std::vector<FaceBlock> pack_faces(const std::vector<Face>& faces, KOf k_of) {
  constexpr int B = kFaceBlock;
  std::vector<FaceBlock> blocks((faces.size() + B - 1) / B);
  for (std::size_t b = 0; b < blocks.size(); ++b) {
    FaceBlock& out = blocks[b];
    out.n = static_cast<int>(std::min<std::size_t>(B, faces.size() - b * B));
    for (int f = 0; f < B; ++f) {
      const Face& face = faces[b * B + static_cast<std::size_t>(std::min(f, out.n - 1))];
      for (int c = 0; c < 3; ++c) {
        out.v[c][f] = face.v[c];
        out.c0[c][f] = face.rest.cos0[c];
        out.s0[c][f] = face.rest.sin0[c];
      }
      out.k[f] = f < out.n ? k_of(face) : 0.0;
    }
  }
  return blocks;
}

/// All faces at once, block by block: gather the corners' positions, run the branch-free series
/// path of face_angle_springs<true> over the block (a plain loop the compiler vectorises), redo
/// the rare faces outside the series range (or flat) with the scalar kernel, and scatter-add the
/// gradients. Same energy and gradient as the scalar loop up to round-off
/// (tests/mss/test_face_angles.cpp, tests/mss/test_model.cpp).
inline double face_angle_springs_blocks(const std::vector<FaceBlock>& blocks, const double* x,
                                        double* g) {
  constexpr int B = kFaceBlock;
  double energy = 0.0;
  alignas(64) double P[9][B], E[B], G[9][B];
  alignas(64) int ok[B];
  for (const FaceBlock& fb : blocks) {
    for (int f = 0; f < B; ++f)  // gather
      for (int c = 0; c < 3; ++c)
        for (int d = 0; d < 3; ++d) P[3 * c + d][f] = x[3 * fb.v[c][f] + d];
    for (int f = 0; f < B; ++f) {  // the vectorised part: same formulas as face_angle_springs
      const double a0 = P[3][f] - P[0][f], a1 = P[4][f] - P[1][f], a2 = P[5][f] - P[2][f];  // e01
      const double b0 = P[6][f] - P[3][f], b1 = P[7][f] - P[4][f], b2 = P[8][f] - P[5][f];  // e12
      const double c0 = P[0][f] - P[6][f], c1 = P[1][f] - P[7][f], c2 = P[2][f] - P[8][f];  // e20
      const double n0 = a1 * c2 - a2 * c1, n1 = a2 * c0 - a0 * c2, n2 = a0 * c1 - a1 * c0;
      const double sq = std::sqrt(n0 * n0 + n1 * n1 + n2 * n2);
      const double l01 = a0 * a0 + a1 * a1 + a2 * a2, l12 = b0 * b0 + b1 * b1 + b2 * b2,
                   l20 = c0 * c0 + c2 * c2 + c1 * c1;
      const double d0 = -(a0 * c0 + a1 * c1 + a2 * c2), d1 = -(b0 * a0 + b1 * a1 + b2 * a2),
                   d2 = -(c0 * b0 + c1 * b1 + c2 * b2);
      const double C0 = fb.c0[0][f], C1 = fb.c0[1][f], C2 = fb.c0[2][f];
      const double S0 = fb.s0[0][f], S1 = fb.s0[1][f], S2 = fb.s0[2][f];
      const double y0 = sq * C0 - d0 * S0, x0 = d0 * C0 + sq * S0;
      const double y1 = sq * C1 - d1 * S1, x1 = d1 * C1 + sq * S1;
      const double y2 = sq * C2 - d2 * S2, x2 = d2 * C2 + sq * S2;
      ok[f] = (x0 > 0.0) & (x1 > 0.0) & (x2 > 0.0) & (std::abs(y0) < 0.1 * x0) &
              (std::abs(y1) < 0.1 * x1) & (std::abs(y2) < 0.1 * x2) & (sq > 0.0);
      const double t0 = atan_series(y0 / x0), t1 = atan_series(y1 / x1), t2 = atan_series(y2 / x2);
      const double K = fb.k[f];
      E[f] = 0.5 * K * (t0 * t0 + t1 * t1 + t2 * t2);
      const double ks = K / sq;
      const double f0 = ks * t0, f1 = ks * t1, f2 = ks * t2;
      // Three reciprocals of the squared edge lengths instead of six quotients d_c / |.|^2.
      const double i01 = 1.0 / l01, i12 = 1.0 / l12, i20 = 1.0 / l20;
      const double q0 = d0 * i01, q1 = d1 * i12, q2 = d2 * i20;  // corner c: d_c / |a|^2
      const double r0 = d0 * i20, r1 = d1 * i01, r2 = d2 * i12;  // corner c: d_c / |b|^2
      const double A[3] = {a0, a1, a2}, Bv[3] = {b0, b1, b2}, Cv[3] = {c0, c1, c2};
      for (int d = 0; d < 3; ++d) {
        const double ga0 = f0 * (q0 * A[d] + Cv[d]), gb0 = f0 * (-r0 * Cv[d] - A[d]);
        const double ga1 = f1 * (q1 * Bv[d] + A[d]), gb1 = f1 * (-r1 * A[d] - Bv[d]);
        const double ga2 = f2 * (q2 * Cv[d] + Bv[d]), gb2 = f2 * (-r2 * Bv[d] - Cv[d]);
        G[d][f] = -(ga0 + gb0) + gb1 + ga2;
        G[3 + d][f] = ga0 - (ga1 + gb1) + gb2;
        G[6 + d][f] = gb0 + ga1 - (ga2 + gb2);
      }
    }
    for (int f = 0; f < fb.n; ++f) {
      const int v0 = fb.v[0][f], v1 = fb.v[1][f], v2 = fb.v[2][f];
      if (!ok[f]) {  // outside the series range or a flat triangle: the scalar kernel
        FaceRest rest;
        for (int c = 0; c < 3; ++c) rest.cos0[c] = fb.c0[c][f], rest.sin0[c] = fb.s0[c][f];
        double gs[9] = {0, 0, 0, 0, 0, 0, 0, 0, 0};
        E[f] = face_angle_springs<true>(x + 3 * v0, x + 3 * v1, x + 3 * v2, fb.k[f], rest, gs,
                                        gs + 3, gs + 6);
        for (int r = 0; r < 9; ++r) G[r][f] = gs[r];
      }
      energy += E[f];
      const int v[3] = {v0, v1, v2};
      for (int c = 0; c < 3; ++c)
        for (int d = 0; d < 3; ++d) g[3 * v[c] + d] += G[3 * c + d][f];
    }
  }
  return energy;
}

/// face_angle_springs_blocks over `faces` packed for this call (k_of(face) their stiffness).
template <class Face, class KOf>
double face_angle_springs_all(const std::vector<Face>& faces, KOf k_of, const double* x,
                              double* g) {
  return face_angle_springs_blocks(pack_faces(faces, k_of), x, g);
}

}  // namespace spinesim::mss

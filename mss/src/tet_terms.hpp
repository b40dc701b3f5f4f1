// The per-tetrahedron terms of the MSS force evaluation — the radial springs (thesis
// (5.3)-(5.5)) and the per-tet volume penalty — over all tets at once, in blocks of 16:
// gather the four corners into structure-of-arrays buffers, run both formulas over the block as
// plain loops the compiler vectorises, scatter-add the gradients. Same energy and gradient as
// radial_springs and volume_penalty (elements.hpp) one tet at a time, up to round-off
// (tests/mss/test_tet_terms.cpp).
//
// Measured (bench_mss TermGradient, L4-L5 2.5 mm, 5,099 tets, AMD EPYC): one tet at a time the
// radial springs took 134 us and the volume penalty 86 us of a 460 us force evaluation, mostly
// gathering and scattering the same four corners twice; see docs/benchmarks.md.
#pragma once

#include "spinesim/mss/elements.hpp"

#include <Eigen/Core>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <vector>

namespace spinesim::mss::detail {

/// One tet's radial-spring and volume-penalty constants (k = 0 switches a term off).
struct TetTermBlockInput {
  int t;               ///< tetrahedron
  double k_radial;     ///< k_s, N/mm
  double rest_sum;     ///< S0, mm
  double k_volume;     ///< k_v, N/mm^5
  double rest_volume;  ///< V0, mm^3
};

/// Energy of the radial springs (when with_radial) and volume penalties (when with_volume) of
/// `tets` at positions x (3n); adds the gradient to g (3n). T: the mesh's tets (rows of four
/// node indices).
template <bool with_radial, bool with_volume>
double tet_terms_all(const std::vector<TetTermBlockInput>& tets, const Eigen::MatrixX4i& T,
                     const double* x, double* g) {
  constexpr int B = 16;
  double energy = 0.0;
  alignas(64) double P[12][B], KR[B], S0[B], KV[B], V0[B], E[B], G[12][B];
  const std::size_t nt = tets.size();
  for (std::size_t b = 0; b < nt; b += B) {
    const int n = static_cast<int>(std::min<std::size_t>(B, nt - b));
    for (int f = 0; f < B; ++f) {  // gather; padding lanes repeat the last tet with k = 0
      const TetTermBlockInput& in = tets[b + static_cast<std::size_t>(std::min(f, n - 1))];
      for (int c = 0; c < 4; ++c) {
        const double* p = x + 3 * T(in.t, c);
        for (int d = 0; d < 3; ++d) P[3 * c + d][f] = p[d];
      }
      KR[f] = f < n ? in.k_radial : 0.0;
      KV[f] = f < n ? in.k_volume : 0.0;
      S0[f] = in.rest_sum;
      V0[f] = in.rest_volume;
    }
    for (int f = 0; f < B; ++f) {  // the vectorised part
      // Radial springs: E = k_s/2 (S - S0)^2, S = sum_j |x_j - x_B|; dS/dx_i = u_i - mean u.
      double u[4][3] = {}, es = 0.0, fs = 0.0;
      if constexpr (with_radial) {
        double bc[3];
        for (int d = 0; d < 3; ++d)
          bc[d] = 0.25 * (P[d][f] + P[3 + d][f] + P[6 + d][f] + P[9 + d][f]);
        double S = 0.0;
        for (int c = 0; c < 4; ++c) {
          const double r0 = P[3 * c][f] - bc[0], r1 = P[3 * c + 1][f] - bc[1],
                       r2 = P[3 * c + 2][f] - bc[2];
          const double len = std::sqrt(r0 * r0 + r1 * r1 + r2 * r2);
          S += len;
          const double inv = len < kMinLength_mm ? 0.0 : 1.0 / len;
          u[c][0] = r0 * inv, u[c][1] = r1 * inv, u[c][2] = r2 * inv;
        }
        es = S - S0[f];
        fs = KR[f] * es;
      }
      // Volume penalty: V = a.(b x c)/6 with arms from x_0; 6 dV/dx_i = twice the area vector
      // of the face opposite x_i.
      double bxc[3] = {}, cxa[3] = {}, axb[3] = {}, ev = 0.0, fv = 0.0;
      if constexpr (with_volume) {
        const double a0 = P[3][f] - P[0][f], a1 = P[4][f] - P[1][f], a2 = P[5][f] - P[2][f];
        const double b0 = P[6][f] - P[0][f], b1 = P[7][f] - P[1][f], b2 = P[8][f] - P[2][f];
        const double c0 = P[9][f] - P[0][f], c1 = P[10][f] - P[1][f], c2 = P[11][f] - P[2][f];
        bxc[0] = b1 * c2 - b2 * c1, bxc[1] = b2 * c0 - b0 * c2, bxc[2] = b0 * c1 - b1 * c0;
        cxa[0] = c1 * a2 - c2 * a1, cxa[1] = c2 * a0 - c0 * a2, cxa[2] = c0 * a1 - c1 * a0;
        axb[0] = a1 * b2 - a2 * b1, axb[1] = a2 * b0 - a0 * b2, axb[2] = a0 * b1 - a1 * b0;
        ev = (a0 * bxc[0] + a1 * bxc[1] + a2 * bxc[2]) / 6.0 - V0[f];
        fv = KV[f] * ev / 6.0;
      }
      E[f] = 0.5 * (KR[f] * es * es + KV[f] * ev * ev);
      for (int d = 0; d < 3; ++d) {
        const double um = 0.25 * (u[0][d] + u[1][d] + u[2][d] + u[3][d]);
        const double g1 = fv * bxc[d], g2 = fv * cxa[d], g3 = fv * axb[d];
        G[d][f] = fs * (u[0][d] - um) - (g1 + g2 + g3);
        G[3 + d][f] = fs * (u[1][d] - um) + g1;
        G[6 + d][f] = fs * (u[2][d] - um) + g2;
        G[9 + d][f] = fs * (u[3][d] - um) + g3;
      }
    }
    for (int f = 0; f < n; ++f) {
      const int t = tets[b + static_cast<std::size_t>(f)].t;
      energy += E[f];
      for (int c = 0; c < 4; ++c) {
        double* gp = g + 3 * T(t, c);
        for (int d = 0; d < 3; ++d) gp[d] += G[3 * c + d][f];
      }
    }
  }
  return energy;
}

}  // namespace spinesim::mss::detail

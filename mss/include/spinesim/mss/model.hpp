// MssModel — the thesis's tetrahedral mass-spring disc (ch. 5.2), built from a tet mesh and a
// material, as one energy E(x) with exact gradient and sparse Hessian.
//
//   E(x) = sum_edges   1/2 k_e (|x_j - x_i| - L0)^2                 main springs (5.2), (5.12)
//        + sum_tets    1/2 k_s (S_t(x) - S0_t)^2                   radial springs (5.3)-(5.5)
//        + sum_angles  1/2 k_t (theta - theta0)^2                  torsional springs (5.6)-(5.8)
//        + sum_tets    1/2 k_v (V_t(x) - V0_t)^2                   volume term (beyond thesis)
//        + 1/2 k_g (V(x) - V0)^2,  V = sum_t V_t                   whole-disc volume (beyond thesis)
//        + sum_tets sum_f V0_t psi_f(I4_f(x))                      fibre springs (beyond thesis)
// Internal force f_int = -dE/dx; ambient damping f_damp = -K_d v per node (5.11) is applied by
// the integrators. Element formulas: elements.hpp.
//
// Constants:
//   masses (5.1)   m_i = sum_{tets ∋ i} rho_t V_t / 4                       tonne
//   main (5.2)     k_e = sum_{tets ∋ e} E_t V_t / L0^2                      N/mm (Van Gelder)
//   radial         k_s = c_s E_t V_t / S0_t^2, c_s = MssOptions::radial_factor (the thesis gives
//                  no value for k_s; this is the Van Gelder form applied to the summed length)
//   torsion (5.8)  k_t = G pi D_m^4 / (32 L_m n_t): D_m = (D_u + D_l)/2 (5.6) with D_u, D_l the
//                  equal-area diameters of the endplates (surface labels 2, 1), L_m = 4V/(pi D_m^2)
//                  (5.7), n_t the number of angle springs. Per region: each spring takes the mean
//                  G of the tetrahedra that share its face (one G for a homogeneous disc, as in
//                  the thesis).
//   volume         k_v = c_v K_t / V0_t, K_t = E/(3(1-2 nu)) the bulk modulus, c_v =
//                  MssOptions::volume_factor; off unless MssOptions::volume_term.
//   disc volume    k_g = c_g K_mean / V0, K_mean the volume-weighted bulk modulus, c_g =
//                  MssOptions::disc_volume_factor; off unless MssOptions::disc_volume_term. It
//                  couples every node, so its Hessian k_g ∇V ∇V^T + k_g (V - V0) H_V is split: the
//                  sparse part k_g (V - V0) H_V is in hessian() (exact mode), the dense rank-one
//                  part comes from disc_volume_rank_one() for Sherman–Morrison in the solvers.
//                  Why both volume terms: stiff per-tet penalties lock (the disc gets far too
//                  stiff and still loses volume) while the whole-disc term lets the wall bulge
//                  freely (tests/mss/test_volume.cpp; numbers in docs/benchmarks.md).
//   fibres         in every tet of a fibre-reinforced region (mesh/fibre_field.hpp), one embedded
//                  spring per fibre family along its direction (elements.hpp fibre_spring),
//                  tension-only with the exponential toe: k1 = k/4 (k = E_f/2 the family's
//                  linear stiffness, the nonlinear FEM's k1), k2 the region's toe exponent. Off
//                  unless MssOptions::fibre_springs; annulus scale only. They have no stiffness
//                  at rest (a fibre at its rest length is at the tension-only kink), so the
//                  linearised calibration cannot see them: calibration/nonlinear_fit.hpp.
//   damping (5.11) K_d = MssOptions::damping_n_s_per_mm, or by default 2 zeta omega_1 m_mean with
//                  omega_1 = (pi / L_m) sqrt(E_mean / rho_mean) (the first axial mode of the
//                  equivalent cylinder between fixed plates), zeta = MssOptions::damping_ratio.
// Angle springs (5.6)-(5.8): three per triangle face (one at each corner, in the face's plane),
// a face shared by two tetrahedra carrying them once — "tetrahedra sharing three vertices share
// the three torsional springs".
//
// Every stiffness is the sum of an annulus part and a nucleus part; MssOptions::scales (and
// set_scales) multiply them per term and region without rebuilding (the calibration knobs).
// On top of the region scales, each main (edge) spring may carry its own multiplier mu_e
// (MssOptions::edge_multipliers, the per-spring calibration):
//   k_e = mu_e (s_main,annulus k_e,annulus + s_main,nucleus k_e,nucleus).
// Multipliers belong to one mesh: they are indexed in the model's edge order (edge_springs()).
//
// Positions are flat vectors of 3·#nodes, interleaved (x0, y0, z0, x1, ...), mm; the Hessian
// is 3#nodes square, both triangles stored, its pattern built once (3×3 blocks of every node
// pair that shares a tetrahedron) and refilled in place.
#pragma once

#include "spinesim/mesh/material.hpp"
#include "spinesim/mesh/tet_mesh.hpp"
#include "spinesim/mss/elements.hpp"

#include <Eigen/Core>
#include <Eigen/SparseCore>

#include <array>
#include <memory>
#include <vector>

namespace spinesim::mss {

/// The energy terms of the model.
/// Term::disc_volume is one term for the whole disc: it uses region index 0 (its scale is
/// scales[disc_volume].by_region[0]; term_energy(x, disc_volume, 1) is zero).
/// Term::fibre exists in fibre-reinforced regions only: its scale is by_region[0] (by_region[1]
/// is unused, term_energy(x, fibre, 1) is zero).
enum class Term : int { main = 0, radial = 1, torsion = 2, volume = 3, disc_volume = 4, fibre = 5 };
inline constexpr int kNumTerms = 6;

/// Stiffness multipliers for one term, per region (index 0 annulus = region 1, 1 nucleus =
/// region 2; any other region label counts as annulus).
struct RegionScales {
  std::array<double, 2> by_region{1.0, 1.0};
};

struct MssOptions {
  bool radial_springs = true;     ///< thesis (5.3)-(5.5)
  bool torsion_springs = true;    ///< thesis (5.6)-(5.8)
  bool volume_term = false;       ///< per-tetrahedron volume penalty (beyond the thesis)
  bool disc_volume_term = false;  ///< whole-disc volume penalty (beyond the thesis)
  /// Embedded tension-only fibre springs in fibre-reinforced regions (beyond the thesis); needs
  /// a material with fibres.
  bool fibre_springs = false;
  /// The fibres on their tet's isochoric stretch J^(−2/3) I4, as the nonlinear FEM
  /// (elements.hpp isochoric_fibre); false: on the spring's own stretch. Fitted to the nonlinear
  /// FEM disc, the isochoric fibres halve the network's reaction errors in bending
  /// (docs/disc-model.md).
  bool isochoric_fibres = true;
  double radial_factor = 1.0;  ///< c_s in k_s = c_s E V0 / S0^2 (dimensionless)
  double volume_factor = 1.0;  ///< c_v in k_v = c_v K_bulk / V0 (dimensionless)
  /// c_g in k_g = c_g K_mean / V0_disc (dimensionless). 10: near-incompressible disc — on L4-L5
  /// under 10 % compression dV/V = -4.2, -2.0, -0.69, -0.24 % at c_g = 1, 3, 10, 30 with the
  /// plate force saturating (1.19, 1.47, 1.62, 1.68 kN; no locking), tests/mss/test_volume.cpp.
  double disc_volume_factor = 10.0;
  double damping_ratio = 1.0;        ///< zeta of the default K_d (dimensionless)
  double damping_n_s_per_mm = -1.0;  ///< K_d per node; < 0 means the default from damping_ratio
  std::array<RegionScales, kNumTerms> scales{};  ///< indexed by Term
  /// Per-spring multipliers mu_e of the main springs, one per edge spring in the model's edge
  /// order (MssModel::edge_springs), each finite and > 0; empty = all 1.
  std::vector<double> edge_multipliers;
};

/// One main (edge) spring as the model holds it (MssModel::edge_springs).
struct EdgeSpringInfo {
  int i = 0, j = 0;                        ///< end nodes, i < j
  double rest_mm = 0;                      ///< L0
  std::array<double, 2> k_part{0.0, 0.0};  ///< annulus / nucleus parts of k (5.2), N/mm, unscaled
  double k_region = 0;    ///< s_main,annulus k_part[0] + s_main,nucleus k_part[1], N/mm (no mu_e)
  double multiplier = 1;  ///< mu_e; the spring's stiffness is multiplier * k_region
};

/// Whether `options` switch `term` on (the main springs always are).
inline bool term_enabled(const MssOptions& options, Term term) {
  switch (term) {
    case Term::main:
      return true;
    case Term::radial:
      return options.radial_springs;
    case Term::torsion:
      return options.torsion_springs;
    case Term::volume:
      return options.volume_term;
    case Term::disc_volume:
      return options.disc_volume_term;
    case Term::fibre:
      return options.fibre_springs;
  }
  return false;
}

/// Equivalent cylinder of the thesis (5.6)-(5.8), for reports.
struct EquivalentCylinder {
  double upper_diameter_mm = 0, lower_diameter_mm = 0, mean_diameter_mm = 0, length_mm = 0;
  double volume_mm3 = 0;
  Eigen::Index num_angle_springs = 0;
  double k_t_per_shear_modulus = 0;  ///< k_t / G, mm^3 (k_t = G * this), N·mm/rad per MPa
};

class MssModel {
 public:
  /// Validates mesh (mesh::validate) and materials and options (finite, positive
  /// factors, damping finite, one positive multiplier per edge spring if any); throws
  /// std::invalid_argument with a one-line message.
  MssModel(const mesh::TetMesh& mesh, const mesh::RegionMaterials& materials,
           const MssOptions& options = MssOptions());
  ~MssModel();
  MssModel(MssModel&&) noexcept;
  MssModel& operator=(MssModel&&) noexcept;
  MssModel(const MssModel&);
  MssModel& operator=(const MssModel&);

  const mesh::TetMesh& mesh() const;
  const MssOptions& options() const;
  Eigen::Index num_nodes() const;
  Eigen::Index num_dofs() const { return 3 * num_nodes(); }

  const Eigen::VectorXd& rest_positions_mm() const;  ///< 3#nodes, interleaved
  const Eigen::VectorXd& node_masses_t() const;      ///< #nodes, tonne (5.1)
  double total_mass_t() const;
  double damping_n_s_per_mm() const;  ///< K_d (5.11)
  const EquivalentCylinder& cylinder() const;

  Eigen::Index num_edge_springs() const;
  /// The main springs in the model's edge order (unique mesh edges sorted by (i, j)) — the
  /// order of MssOptions::edge_multipliers.
  std::vector<EdgeSpringInfo> edge_springs() const;
  Eigen::Index num_radial_tets() const;    ///< 0 when radial springs are off
  Eigen::Index num_angle_springs() const;  ///< 0 when torsion springs are off
  Eigen::Index num_volume_terms() const;   ///< 0 when the volume term is off
  Eigen::Index num_fibre_springs() const;  ///< two per fibre-reinforced tet; 0 when off

  /// Replaces the calibration multipliers (all must be finite and > 0).
  void set_scales(const std::array<RegionScales, kNumTerms>& scales);
  /// Replaces the per-spring multipliers (empty = all 1; else one finite value > 0 per edge
  /// spring); throws std::invalid_argument otherwise.
  void set_edge_multipliers(const std::vector<double>& multipliers);

  /// Total energy, N·mm.
  double energy(const Eigen::VectorXd& x_mm) const;
  /// Energy of one term with its region scale set to 1 for `region_index` and 0 for the other
  /// (dE/d scale for calibration), N·mm; region_index 0 annulus, 1 nucleus. For Term::main the
  /// per-spring multipliers stay in (dE/d s_main = sum_e mu_e k_e,region part).
  double term_energy(const Eigen::VectorXd& x_mm, Term term, int region_index) const;
  /// Energy, and grad = dE/dx (3#nodes, N; the internal force is -grad).
  double gradient(const Eigen::VectorXd& x_mm, Eigen::VectorXd& grad) const;
  /// Gradient of term_energy(x, term, region_index) (for calibration adjoints).
  void term_gradient(const Eigen::VectorXd& x_mm, Term term, int region_index,
                     Eigen::VectorXd& grad) const;
  /// Hessian d2E/dx2, N/mm, into H (pattern built on first use, values refilled after) —
  /// without the whole-disc volume term's rank-one part (see disc_volume_rank_one).
  void hessian(const Eigen::VectorXd& x_mm, HessianMode mode, Eigen::SparseMatrix<double>& H) const;

  /// The stiffness at rest that a fixed-matrix solver factorises: hessian(rest, exact) with
  /// every fibre element's tension-side tangent (elements.hpp fibre_rest_tangent) in place of
  /// its exact one, which is zero at the kink. Equal to the rest Hessian without fibre elements.
  /// It bounds the fibres' true tangent from above near rest (a compressed fibre has none), so
  /// a step with this fixed matrix does not overshoot there.
  void rest_tangent(Eigen::SparseMatrix<double>& H) const;

  /// Hessian of term_energy(x, term, region_index), same pattern as hessian() (without the
  /// whole-disc term's rank-one part: that is disc_volume_rank_one(x, u) / its scale). The
  /// model's energy is linear in the scales, so hessian() = sum over terms and regions of
  /// scale * term_hessian() — the calibration's dK/d scale.
  void term_hessian(const Eigen::VectorXd& x_mm, Term term, int region_index, HessianMode mode,
                    Eigen::SparseMatrix<double>& H) const;

  bool has_disc_volume_term() const;
  /// The rank-one part of the whole-disc volume Hessian: u = dV/dx (3#nodes, mm^2), returns
  /// k_g (N/mm^5, scaled) so that d2E/dx2 = hessian(x) + k_g u u^T. Returns 0 (u = 0) when the
  /// term is off.
  double disc_volume_rank_one(const Eigen::VectorXd& x_mm, Eigen::VectorXd& u) const;

  /// Sum of signed tetrahedron volumes at x, mm^3 (evaluated through the outer surface: the same
  /// sum up to round-off, at a third of the cost).
  double volume_mm3(const Eigen::VectorXd& x_mm) const;
  /// Tetrahedra turned inside out at x (signed volume <= 0). Edge, radial and angle springs
  /// barely resist inversion, so an overloaded thesis network can reach an "equilibrium" with
  /// inverted tets (seen: 500 N on a thoracic disc); the volume terms prevent it.
  Eigen::Index inverted_tets(const Eigen::VectorXd& x_mm) const;
  /// volume_mm3 at the rest positions (so that a disc at rest has exactly zero volume change).
  double rest_volume_mm3() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace spinesim::mss

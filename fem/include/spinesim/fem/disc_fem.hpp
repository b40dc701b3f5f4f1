// Linear FEM reference for a disc between a fixed inferior endplate and a rigid superior plate.
//
// Small-strain isotropic linear elasticity, P1 or P2 tetrahedra, material per region.
// Boundary conditions (docs/units-and-frame.md):
//   - nodes with surface == 1 (inferior endplate) are fixed;
//   - nodes with surface == 2 (superior endplate; for P2 also edge midpoints whose two ends
//     are both labelled 2) move rigidly with the plate: u_i = t + theta x (x_i - c), small
//     rotation vector theta in radians inside (degrees on the command line), c = plate centre;
//   - the plate is driven by a prescribed 6-DOF motion q = (t, theta) or by an applied
//     wrench w = (F, M about c); all other nodes are free.
// Reaction wrench: the force and moment the disc exerts on the plate, about c, N and N·mm;
// so a compressive motion (t_y < 0) gives F_y > 0. With the condensed 6x6 stiffness K6
// (N/mm, N, N·mm/rad blocks): reaction = -K6 q.
//
// Method: u = T (u_f, q) eliminates the fixed nodes and slaves the plate nodes (assembly.hpp);
// K_ff is factorised once (CHOLMOD; or, for large P2 problems, solved by p-multigrid CG — see
// SolverOptions), Z = K_ff^-1 K_fp by 6 solves, and
//   K6 = K_pp - K_fp^T Z,   motion q: u_f = -Z q,   wrench w: q = K6^-1 w.
// The reaction is evaluated directly from the assembled blocks, -(K_fp^T u_f + K_pp q), which
// equals -K6 q (and -w for a wrench solve) up to round-off — the tests check that.
// Cost: the sparse Cholesky factorisation dominates (3-D fill), assembly is a few per cent;
// measured per mesh size in docs/benchmarks.md ("FEM reference").
#pragma once

#include "spinesim/fem/fibres.hpp"
#include "spinesim/mesh/material.hpp"
#include "spinesim/mesh/tet_mesh.hpp"

#include <Eigen/Core>

#include <limits>
#include <memory>

namespace spinesim::fem {

using Vector6d = Eigen::Matrix<double, 6, 1>;
using Matrix6d = Eigen::Matrix<double, 6, 6>;

struct Timings {
  double setup_s = 0, assembly_s = 0, analyse_s = 0, factorise_s = 0, solve_s = 0;
  int cg_iterations = 0;  ///< p-multigrid CG iterations (0 with the direct solver)
};

/// How K_ff^-1 K_fp is computed. `direct`: CHOLMOD on K_ff. `p_multigrid_cg`: CG with a
/// two-level P2→P1 preconditioner (P2 only; p2_multigrid.hpp) — the P1 block is factorised
/// instead, and K6 uses the energy form K_pp - 2 sym(K_fp^T Z) + Z^T K_ff Z, whose error is
/// quadratic in the CG error. `automatic`: CG for P2 above `cg_min_dofs` free DOF, else direct.
/// The threshold is where CG overtook the direct solve on the meshes measured (bench_fem;
/// docs/benchmarks.md, "CG or direct"): earlier on boxes, later on discs with a nu = 0.49
/// nucleus, which slows CG.
enum class LinearSolver { automatic, direct, p_multigrid_cg };

/// `displacement`: the P1/P2 displacement form. `mixed`: Taylor–Hood P2–P1 displacement–pressure
/// (mixed.hpp; order 2 only), for a nearly incompressible nucleus; K_ff is then quasi-definite
/// and factorised by LDL^T (direct only).
enum class Formulation { displacement, mixed };

struct SolverOptions {
  LinearSolver solver = LinearSolver::automatic;
  Formulation formulation = Formulation::displacement;
  Eigen::Index cg_min_dofs = 150000;
  double cg_relative_tolerance = 1e-10;  ///< per column, ||r|| <= tol ||b||
  int cg_max_iterations = 1000;
};

struct PlateSolution {
  Eigen::MatrixX3d displacement_mm;  ///< #V×3 displacement at the mesh vertices, mm
  Eigen::MatrixX3d
      node_displacement_mm;  ///< #nodes×3 at every FE node (P2: vertices, then edge nodes)
  Vector6d plate_motion;     ///< (t mm, theta rad)
  Vector6d reaction_wrench;  ///< (F N, M N·mm) the disc exerts on the plate, about c
  /// Mixed formulation only (empty / NaN otherwise): hydrostatic pressure -tr(sigma)/3 (MPa,
  /// positive in compression) at each mesh vertex, averaged over the regions meeting there;
  /// and its volume average over the nucleus (region 2), the intradiscal pressure.
  Eigen::VectorXd pressure_mpa;
  double nucleus_pressure_mpa = std::numeric_limits<double>::quiet_NaN();
  /// Mixed formulation only (empty otherwise): the mean stress p (MPa, tension > 0) at each
  /// tet's four vertices, for the tet's region — what stress_fields.hpp needs.
  Eigen::MatrixX4d element_mean_stress_mpa;
};

/// Solver object: assembles and factorises once, then answers any number of plate loads.
/// Throws std::invalid_argument for bad input (one-line message) and std::runtime_error if
/// the stiffness is not positive definite.
class DiscFem {
 public:
  /// Validates the mesh (endplate labels required), the materials and `order` (1 or 2);
  /// throws std::invalid_argument with a one-line message otherwise.
  DiscFem(const mesh::TetMesh& mesh, const mesh::RegionMaterials& materials, int order,
          const Eigen::Vector3d& plate_center_mm, const SolverOptions& options = SolverOptions());
  ~DiscFem();
  DiscFem(DiscFem&&) noexcept;
  DiscFem& operator=(DiscFem&&) noexcept;

  /// Default plate centre: arithmetic mean of the vertices labelled 2.
  static Eigen::Vector3d default_plate_center(const mesh::TetMesh& mesh);

  PlateSolution solve_motion(const Vector6d& motion) const;  ///< (t mm, theta rad)
  PlateSolution solve_wrench(const Vector6d& wrench) const;  ///< (F N, M N·mm)
  /// Condensed plate stiffness (symmetric positive definite), units (N/mm | N/rad ; N | N·mm/rad).
  const Matrix6d& stiffness_6x6() const;

  /// ||K6 - K6^T||_F / ||K6||_F before symmetrisation (round-off level for a correct model;
  /// with the CG solver the energy form is symmetric by construction, so this checks little).
  double stiffness_asymmetry() const;
  const Eigen::Vector3d& plate_center() const;  ///< c, mm

  int order() const;
  Formulation formulation() const;
  /// The annulus fibre field (empty when the material has no fibres), for output.
  const ElementFibres& fibres() const;
  Eigen::Index num_dofs() const;   ///< free unknowns (displacements, and pressures when mixed)
  Eigen::Index num_nodes() const;  ///< P1 vertices or P2 vertices + edge midpoints
  const Timings& timings() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace spinesim::fem

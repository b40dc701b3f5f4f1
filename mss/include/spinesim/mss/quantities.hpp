// What a mass-spring state shows: displacements, volume changes (per tetrahedron and of the
// whole disc) and the VTU arrays of a state, for reports, files and viewers.
#pragma once

#include "spinesim/mesh/io.hpp"
#include "spinesim/mss/model.hpp"

#include <Eigen/Core>

#include <vector>

namespace spinesim::mss {

/// Displacement x − X at the mesh vertices, #V×3, mm (x flat 3#V, interleaved).
Eigen::MatrixX3d displacement(const MssModel& model, const Eigen::VectorXd& x_mm);

/// Largest vertex displacement |x_i − X_i|, mm.
double max_displacement_mm(const MssModel& model, const Eigen::VectorXd& x_mm);

/// Relative volume change (V_t − V0_t)/V0_t of every tetrahedron (signed volumes), #T.
Eigen::VectorXd tet_volume_change(const MssModel& model, const Eigen::VectorXd& x_mm);

/// Spring strain of every tetrahedron: of its six edges' strains (l − L)/L, the one of largest
/// magnitude (signed: > 0 stretched, < 0 compressed), #T.
Eigen::VectorXd tet_edge_strain(const MssModel& model, const Eigen::VectorXd& x_mm);

/// Relative volume change of the whole disc at x, (V − V0)/V0.
double volume_change(const MssModel& model, const Eigen::VectorXd& x_mm);

/// Green–Lagrange strain E = (F^T F - I)/2 of every tetrahedron (F = dx/dX, constant in a
/// linear tet), #T×6 in ParaView's order (xx, yy, zz, xy, yz, xz); the small strain for small
/// motions, and frame-indifferent for the large ones a mass-spring disc may take.
Eigen::MatrixXd tet_green_lagrange_strain(const MssModel& model, const Eigen::VectorXd& x_mm);

/// Axial force k_e (l - L0) of the main (edge) spring along each of every tetrahedron's six
/// edges, in the local order (0,1) (1,2) (0,2) (0,3) (1,3) (2,3), #T×6, N, tension > 0 — with
/// the calibrated stiffness (region scales and per-spring multipliers). An edge shared by several
/// tetrahedra is one spring: each of them shows its whole force.
Eigen::MatrixXd tet_edge_spring_forces(const MssModel& model, const Eigen::VectorXd& x_mm);

/// The VTU arrays of a state: point data `displacement` (mm); cell data `volume_change`,
/// `green_lagrange_strain` (6) and `edge_spring_force_N` (6).
struct StateFields {
  std::vector<mesh::DataArray> point, cell;
};
StateFields state_fields(const MssModel& model, const Eigen::VectorXd& x_mm);

}  // namespace spinesim::mss

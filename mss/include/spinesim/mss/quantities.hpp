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

/// The VTU arrays of a state: point data `displacement` (mm), cell data `volume_change`.
struct StateFields {
  std::vector<mesh::DataArray> point, cell;
};
StateFields state_fields(const MssModel& model, const Eigen::VectorXd& x_mm);

}  // namespace spinesim::mss

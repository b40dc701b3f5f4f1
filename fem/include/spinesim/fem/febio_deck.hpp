// The linear disc problem of DiscFem as an FEBio input file (.feb, febio_spec 4.0).
//
// What the file holds:
//   - <Mesh>: the P1 vertices or the P2 vertices then edge nodes (ids from 1), tet4 or tet10
//     (FEBio's tet10 edge order 1-2 2-3 3-1 1-4 2-4 3-4 is ours, fe_space.hpp); one <Elements>
//     part per region ("region_<r>") for the tets without fibres, and one part per
//     fibre-reinforced tet ("fibre_<id>"), which carries its own material;
//     node sets "inferior" (fixed) and "superior" (the plate; node_surface_labels);
//   - <Material>: per region "isotropic elastic" (E, v); per fibre tet "orthotropic elastic"
//     with the engineering constants of D = D_iso + sum_f k_f m_f m_f^T in the fibre pair's axes
//     and those axes as <mat_axis type="vector"> (orthotropic.hpp: that D is exactly orthotropic
//     there). FEBio's orthotropic elastic is a hyperelastic law whose small-strain limit is this
//     linear tensor, so the file reproduces the linear problem for small plate motions;
//   - <Boundary>: "inferior" zero displacement; the plate motion t + theta x (x - c) (the
//     small-rotation map DiscFem uses) prescribed on every "superior" node, one dof a <bc>,
//     values from <MeshData> node tables ux, uy, uz (lid: the position in the node set), ramped
//     by load controller 1 over one static step;
//   - <Output>: displacement, stress and Lagrange strain to the plot file; the superior nodes'
//     reaction forces to a log file (their sum is the plate force).
// Units: mm, N, MPa. Only a prescribed plate motion: FEBio applies a wrench through a rigid body,
// which needs a rigid part the disc mesh does not have.
#pragma once

#include "spinesim/fem/disc_fem.hpp"
#include "spinesim/mesh/material.hpp"
#include "spinesim/mesh/tet_mesh.hpp"

#include <Eigen/Core>

#include <ostream>
#include <string>

namespace spinesim::fem {

struct FebioDeck {
  int order = 2;                                          ///< 1 (tet4) or 2 (tet10)
  Eigen::Vector3d plate_center_mm = Eigen::Vector3d::Zero();
  Vector6d motion = Vector6d::Zero();                     ///< (t mm, theta rad)
  std::string title = "spinesim disc";                    ///< a comment at the top
};

/// Writes the file. Throws std::invalid_argument for an order other than 1 or 2, a mesh without
/// both endplate labels, a non-finite motion or centre, or a fibre tet whose elasticity is not
/// orthotropic in its fibre axes.
void write_febio_deck(std::ostream& os, const mesh::TetMesh& mesh,
                      const mesh::RegionMaterials& materials, const FebioDeck& deck);

}  // namespace spinesim::fem

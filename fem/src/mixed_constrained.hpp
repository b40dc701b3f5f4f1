// The Taylor–Hood system of the disc problem reduced by its boundary roles (assembly.hpp):
// unknowns are the free nodes' displacements (3·free_index + d) followed by every pressure
// unknown (3·nf + p), the plate's 6 DOF kept apart in K_fp (rows: all those unknowns) and K_pp.
#pragma once

#include "spinesim/fem/assembly.hpp"
#include "spinesim/fem/mixed.hpp"

namespace spinesim::fem {

struct MixedConstrained {
  PressureSpace pressure;
  Eigen::SparseMatrix<double> lower;  ///< (3nf + #P) square, lower triangle
  PlateCoupling coupling;             ///< K_fp (3nf + #P)×6, K_pp
};

MixedConstrained assemble_mixed_constrained(const FeSpace& p2, const Eigen::MatrixX4i& T,
                                            const Eigen::VectorXi& region,
                                            const mesh::RegionMaterials& materials,
                                            const std::vector<NodeRole>& roles,
                                            const FreeBlockPattern& numbering,
                                            const Eigen::Vector3d& plate_center_mm,
                                            const ElementFibres* fibres);

}  // namespace spinesim::fem

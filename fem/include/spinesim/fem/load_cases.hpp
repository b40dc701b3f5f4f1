// Named disc load cases (docs/units-and-frame.md): compression, tension, shear-ap,
// shear-lat, flexion, extension, lateral-bending, torsion.
//
// Each case is a wrench applied to the superior plate, given in the disc's local frame
// (x lateral, y axial up, z anterior; mesh::DiscFrame) and rotated into the global frame.
// Sign conventions (right-handed, x × y = z):
//   compression  F_y = -500 N            (thesis fig. 5.9 load)
//   tension      F_y = +200 N
//   shear-ap     F_z = +100 N            (superior plate pushed anteriorly)
//   shear-lat    F_x = +100 N            (towards the body's left; right is -x)
//   flexion      M_x = +7500 N·mm        (rotation about +x carries +y towards +z: forward)
//   extension    M_x = -7500 N·mm
//   lateral-bending M_z = +7500 N·mm     (rotation about +z carries +y towards -x: to the right)
//   torsion      M_y = +7500 N·mm        (axial rotation, anticlockwise seen from above)
// 7.5 N·m pure moments are the in-vitro testing standard (Wilke et al. 1998, Eur Spine J
// 7:148-154); 500 N axial load as in the thesis's compression figure.
#pragma once

#include "spinesim/mesh/tet_mesh.hpp"

#include <Eigen/Core>

#include <string>
#include <vector>

namespace spinesim::fem {

struct LoadCase {
  std::string name;
  Eigen::Matrix<double, 6, 1> wrench_local;  ///< (F N, M N·mm) in the disc frame
};

/// All eight cases in the order listed above.
const std::vector<LoadCase>& standard_load_cases();

/// Looks a case up by name; throws std::invalid_argument listing the known names.
const LoadCase& load_case(const std::string& name);

/// Parses a comma-separated list ("compression,flexion" or "all").
std::vector<LoadCase> parse_load_cases(const std::string& list);

/// The case's wrench in the global frame (forces and moments rotated by frame.axes).
Eigen::Matrix<double, 6, 1> global_wrench(const LoadCase& c, const mesh::DiscFrame& frame);

}  // namespace spinesim::fem

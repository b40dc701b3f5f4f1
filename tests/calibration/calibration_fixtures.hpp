// A small two-region disc-like box, its materials and a synthetic MSS "reference" for the
// calibration tests.
#pragma once

#include "spinesim/calibration/objective.hpp"
#include "spinesim/mesh/box_mesh.hpp"
#include "spinesim/mss/boundary.hpp"

namespace spinesim::calibration::fixtures {

/// Box 20 x 8 x 16 mm (y up), 5 x 3 x 4 cells, centred on x = z = 0, the central cells nucleus.
inline mesh::TetMesh two_region_disc() {
  mesh::TetMesh m =
      spinesim::mesh::box_mesh(5, 3, 4, 20.0, 8.0, 16.0, Eigen::Vector3d(-10.0, 0.0, -8.0));
  for (Eigen::Index t = 0; t < m.num_tets(); ++t) {
    Eigen::Vector3d c = Eigen::Vector3d::Zero();
    for (int k = 0; k < 4; ++k) c += 0.25 * m.V.row(m.T(t, k)).transpose();
    if (std::abs(c.x()) < 6.0 && std::abs(c.z()) < 4.0) m.region(t) = 2;
  }
  return m;
}

inline mesh::RegionMaterials two_materials() {
  mesh::RegionMaterials m;
  m.name = "test-two-region";
  m.fallback = {4.2, 0.45, 1200.0};
  m.by_region[2] = {1.0, 0.49, 1000.0};
  return m;
}

inline mss::MssOptions all_terms() {
  mss::MssOptions o;
  o.volume_term = true;
  o.disc_volume_term = true;
  return o;
}

/// A reference computed by the linearised MSS itself at scales `s` (and per-spring multipliers
/// `mu` when given): a calibration with the same freedom must find a zero objective.
inline FemReference synthetic_reference(LinearMss& lin, const mesh::TetMesh& m,
                                        const Eigen::VectorXd& s, const Eigen::Vector3d& center,
                                        const Eigen::VectorXd& mu = Eigen::VectorXd()) {
  const LinearState st = mu.size() ? lin.solve(s, mu) : lin.solve(s);
  FemReference ref;
  ref.plate_center_mm = center;
  ref.plate_rms_radius_mm = plate_rms_radius(m, center);
  ref.k6 = st.k6;
  for (const fem::LoadCase& lc : fem::standard_load_cases()) {
    CaseReference c;
    c.name = lc.name;
    c.wrench = fem::global_wrench(lc, m.frame);
    const Eigen::VectorXd z = st.Z * c.wrench;
    c.displacement_mm = lin.displacement(z);
    c.plate_motion = z.tail<6>();
    ref.cases.push_back(c);
  }
  return ref;
}

}  // namespace spinesim::calibration::fixtures

#include "spinesim/mesh/fibre_field.hpp"
#include "spinesim/common/constants.hpp"

#include "spinesim/mesh/annulus_frames.hpp"

#include <cmath>
#include <limits>

namespace spinesim::mesh {

ElementFibres fibre_field(const TetMesh& mesh, const RegionMaterials& materials) {
  ElementFibres f;
  if (!materials.has_fibres()) return f;
  const AnnulusFrames frames = annulus_frames(mesh);
  const Eigen::Index nt = mesh.num_tets();
  const double nan = std::numeric_limits<double>::quiet_NaN();
  f.direction_1.setZero(nt, 3);
  f.direction_2.setZero(nt, 3);
  f.stiffness_mpa.setZero(nt);
  f.angle_deg.setConstant(nt, nan);
  f.toe_k2.setConstant(nt, nan);
  f.depth = frames.depth;
  for (Eigen::Index t = 0; t < nt; ++t) {
    const auto it = materials.fibres.find(mesh.region(t));
    if (it == materials.fibres.end() || !std::isfinite(frames.depth(t))) continue;
    const double s = frames.depth(t);
    const double alpha = it->second.angle_deg(s);
    const Eigen::RowVector3d c = std::cos(alpha * kRadPerDeg) * frames.circumferential.row(t);
    const Eigen::RowVector3d z = std::sin(alpha * kRadPerDeg) * frames.axial.row(t);
    f.direction_1.row(t) = c + z;
    f.direction_2.row(t) = c - z;
    f.stiffness_mpa(t) = 0.5 * it->second.modulus_mpa(s);
    f.angle_deg(t) = alpha;
    f.toe_k2(t) = it->second.toe_k2;
  }
  return f;
}

}  // namespace spinesim::mesh

#include "spinesim/mesh/fibre_field.hpp"
#include "spinesim/common/constants.hpp"

#include "spinesim/mesh/annulus_frames.hpp"

#include <cmath>
#include <limits>

namespace spinesim::mesh {
namespace {

/// Whether the mesh brings fibre directions for tet t (both families non-zero).
bool has_path(const FibrePaths& p, Eigen::Index t) {
  return !p.empty() && p.direction_1.row(t).squaredNorm() > 0 &&
         p.direction_2.row(t).squaredNorm() > 0;
}

/// Inclination of the unit direction `a` out of tet t's lamella plane's circumferential
/// direction towards its axial one, deg in [0, 90] (the alpha a material would have given it).
double inclination_deg(const Eigen::RowVector3d& a, const AnnulusFrames& frames, Eigen::Index t) {
  return std::atan2(std::abs(a.dot(frames.axial.row(t))),
                    std::abs(a.dot(frames.circumferential.row(t)))) /
         kRadPerDeg;
}

}  // namespace

ElementFibres fibre_field(const TetMesh& mesh, const RegionMaterials& materials) {
  ElementFibres f;
  if (!materials.has_fibres()) return f;
  validate_fibre_paths(mesh);  // a mesh assembled by hand (Python) may not have been validated
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
    if (has_path(mesh.fibre_paths, t)) {
      const Eigen::RowVector3d a1 = mesh.fibre_paths.direction_1.row(t).normalized();
      const Eigen::RowVector3d a2 = mesh.fibre_paths.direction_2.row(t).normalized();
      f.direction_1.row(t) = a1;
      f.direction_2.row(t) = a2;
      f.angle_deg(t) = 0.5 * (inclination_deg(a1, frames, t) + inclination_deg(a2, frames, t));
    } else {
      const double alpha = it->second.angle_deg(s);
      const Eigen::RowVector3d c = std::cos(alpha * kRadPerDeg) * frames.circumferential.row(t);
      const Eigen::RowVector3d z = std::sin(alpha * kRadPerDeg) * frames.axial.row(t);
      f.direction_1.row(t) = c + z;
      f.direction_2.row(t) = c - z;
      f.angle_deg(t) = alpha;
    }
    f.stiffness_mpa(t) = 0.5 * it->second.modulus_mpa(s);
    f.toe_k2(t) = it->second.toe_k2;
  }
  return f;
}

}  // namespace spinesim::mesh

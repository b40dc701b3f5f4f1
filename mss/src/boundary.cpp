// Rigid poses of the endplates and the check of a Boundary (boundary.hpp).
#include "spinesim/mss/boundary.hpp"
#include "spinesim/common/skew.hpp"

#include <cmath>
#include <stdexcept>
#include <string>

namespace spinesim::mss {

namespace {

void require(bool ok, const std::string& message) {
  if (!ok) throw std::invalid_argument(message);
}

void validate_pose(const RigidPose& p, const std::string& what) {
  require(p.rotation.allFinite() && p.translation_mm.allFinite(),
          "boundary: " + what + " pose has non-finite entries");
  const double orth =
      (p.rotation.transpose() * p.rotation - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff();
  require(orth <= 1e-8 && p.rotation.determinant() > 0.0,
          "boundary: " + what + " rotation is not a proper orthonormal matrix (|R^T R - I| = " +
              std::to_string(orth) + ")");
}

}  // namespace

Eigen::Matrix3d rotation_from_vector(const Eigen::Vector3d& theta) {
  // R = I + a [θ]x + b [θ]x^2, a = sin φ / φ, b = (1 - cos φ) / φ^2 = 2 sin^2(φ/2) / φ^2.
  // b in the half-angle form has no cancellation; a and b fall back to Taylor series near 0.
  const double phi2 = theta.squaredNorm();
  const double phi = std::sqrt(phi2);
  double a, b;
  if (phi < 1e-4) {
    a = 1.0 - phi2 / 6.0;
    b = 0.5 - phi2 / 24.0;
  } else {
    a = std::sin(phi) / phi;
    const double s = std::sin(0.5 * phi) / phi;
    b = 2.0 * s * s;
  }
  const Eigen::Matrix3d W = skew(theta);
  return Eigen::Matrix3d::Identity() + a * W + b * (W * W);
}

RigidPose plate_pose(const Vector6d& q, const Eigen::Vector3d& c) {
  RigidPose p;
  p.rotation = rotation_from_vector(q.tail<3>());
  // x = c + t + R (X - c) = R X + (c + t - R c)
  p.translation_mm = c + q.head<3>() - p.rotation * c;
  return p;
}

Vector6d plate_motion(const RigidPose& pose, const Eigen::Vector3d& c) {
  Vector6d q;
  q.head<3>() = pose.apply(c) - c;
  const Eigen::AngleAxisd aa(Eigen::Quaterniond(pose.rotation).normalized());
  q.tail<3>() = aa.angle() * aa.axis();
  return q;
}

Eigen::Vector3d default_plate_center(const mesh::TetMesh& m) {
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  Eigen::Index n = 0;
  for (Eigen::Index i = 0; i < m.num_vertices() && i < m.surface.size(); ++i)
    if (m.surface(i) == int(mesh::Surface::superior_endplate)) {
      sum += m.V.row(i).transpose();
      ++n;
    }
  require(n > 0,
          "boundary: mesh has no superior endplate nodes (surface = 2) for the plate centre");
  return sum / double(n);
}

void validate(const Boundary& bc, Eigen::Index num_nodes) {
  validate_pose(bc.inferior, "inferior");
  validate_pose(bc.superior, "superior");
  require(bc.wrench.allFinite(), "boundary: plate wrench has non-finite components");
  require(bc.plate_center_mm.allFinite(), "boundary: plate centre has non-finite coordinates");
  for (std::size_t k = 0; k < bc.probes.size(); ++k) {
    const Probe& p = bc.probes[k];
    const std::string what = "boundary: probe " + std::to_string(k);
    require(p.center_mm.allFinite(), what + " has a non-finite centre");
    require(std::isfinite(p.radius_mm) && p.radius_mm >= 0.0,
            what + " radius must be finite and >= 0 mm, got " + std::to_string(p.radius_mm));
    require(std::isfinite(p.stiffness_n_per_mm) && p.stiffness_n_per_mm >= 0.0,
            what + " stiffness must be finite and >= 0 N/mm (0: default), got " +
                std::to_string(p.stiffness_n_per_mm));
  }
  if (bc.nodal_forces_n.size() != 0) {
    require(bc.nodal_forces_n.size() == 3 * num_nodes,
            "boundary: nodal forces have " + std::to_string(bc.nodal_forces_n.size()) +
                " entries, expected 0 or 3 x " + std::to_string(num_nodes));
    require(bc.nodal_forces_n.allFinite(), "boundary: nodal forces are not finite");
  }
}

}  // namespace spinesim::mss

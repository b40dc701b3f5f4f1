#include "spinesim/haptics/hybrid_spine.hpp"

#include "spinesim/common/constants.hpp"
#include "spinesim/mss/quantities.hpp"
#include "spinesim/mss/solver.hpp"

#include <stdexcept>
#include <string>

namespace spinesim::haptics {
namespace {

/// The pose of vertebra `i` (the sacrum, i < 0, does not move).
mss::RigidPose vertebra_pose(const std::vector<spine::Pose>& poses, int i) {
  mss::RigidPose p;
  if (i < 0) return p;
  if (std::size_t(i) >= poses.size())
    throw std::invalid_argument("hybrid spine: vertebra " + std::to_string(i) + " has no pose (" +
                                std::to_string(poses.size()) + " given)");
  p.rotation = poses[std::size_t(i)].R;
  p.translation_mm = poses[std::size_t(i)].t;
  return p;
}

}  // namespace

mss::Boundary disc_boundary(const HybridDisc& disc, const std::vector<spine::Pose>& poses) {
  mss::Boundary bc;
  bc.inferior = vertebra_pose(poses, disc.lower);
  bc.superior = vertebra_pose(poses, disc.upper);
  bc.plate_center_mm = disc.centre_mm;
  return bc;
}

SegmentState segment_state(const HybridDisc& disc, const mss::Boundary& bc,
                           const Eigen::VectorXd& x) {
  const Eigen::Matrix3d& A = disc.model->mesh().frame.axes;
  const Eigen::Matrix3d Rl = bc.inferior.rotation, Ru = bc.superior.rotation;
  const Eigen::Vector3d c = disc.centre_mm;
  const Eigen::Vector3d moved =
      Rl.transpose() * (bc.superior.apply(c) - bc.inferior.translation_mm);
  SegmentState s;
  s.shift_mm = A.transpose() * (moved - c);
  s.rotation_deg = A.transpose() * spine::rotation_log(Rl.transpose() * Ru) * kDegPerRad;
  const mss::Vector6d w = mss::plate_reaction(*disc.model, x, bc.superior.apply(c));
  const Eigen::Matrix3d to_disc = (Rl * A).transpose();
  s.force_n = to_disc * w.head<3>();
  s.moment_nmm = to_disc * w.tail<3>();
  s.volume_change = mss::volume_change(*disc.model, x);
  s.inverted_tets = long(disc.model->inverted_tets(x));
  return s;
}

}  // namespace spinesim::haptics

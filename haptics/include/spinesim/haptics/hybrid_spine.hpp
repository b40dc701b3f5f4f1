// The hybrid spine's coupling (thesis 5.4): a mass-spring disc between two rigid vertebrae. Its
// inferior endplate (label 1) moves rigidly with the lower vertebra, its superior endplate
// (label 2) with the upper one; the sacrum (index -1) stays put. And what a disc's state tells
// about the segment: the upper plate's motion relative to the lower vertebra and its reaction,
// both in the disc's own axes carried by the lower vertebra.
#pragma once

#include "spinesim/mss/boundary.hpp"
#include "spinesim/mss/model.hpp"
#include "spinesim/spine/kinematics.hpp"

#include <Eigen/Core>

#include <vector>

namespace spinesim::haptics {

/// One disc of the hybrid spine: its model, the superior plate's centre at the reference
/// posture (mm), and the indices of its vertebrae in the spine model (T1 = 0 … L5 = 16; the
/// lower of L5-S1 is -1, the fixed sacrum).
struct HybridDisc {
  const mss::MssModel* model = nullptr;
  Eigen::Vector3d centre_mm = Eigen::Vector3d::Zero();
  int upper = 0, lower = -1;
};

/// The boundary of `disc` with the vertebrae at `poses` (one per vertebra, T1 … L5): each
/// endplate follows its vertebra's rigid motion (x ↦ R x + t, reference coordinates).
mss::Boundary disc_boundary(const HybridDisc& disc, const std::vector<spine::Pose>& poses);

/// The segment as the disc sees it, in the disc's axes (x lateral, y axial, z anterior) carried
/// by the lower vertebra.
struct SegmentState {
  Eigen::Vector3d shift_mm = Eigen::Vector3d::Zero();      ///< upper plate centre, relative
  Eigen::Vector3d rotation_deg = Eigen::Vector3d::Zero();  ///< relative rotation vector
  Eigen::Vector3d force_n = Eigen::Vector3d::Zero();       ///< reaction on the upper plate
  Eigen::Vector3d moment_nmm = Eigen::Vector3d::Zero();    ///< about the plate centre
  double volume_change = 0;                                ///< (V − V0)/V0
  long inverted_tets = 0;
};

/// The state of `disc` at positions x (mm) under its boundary `bc` (from disc_boundary).
SegmentState segment_state(const HybridDisc& disc, const mss::Boundary& bc,
                           const Eigen::VectorXd& x_mm);

}  // namespace spinesim::haptics

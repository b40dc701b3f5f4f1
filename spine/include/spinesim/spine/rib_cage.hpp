// The rib cage (spine/README.md, "The rib cage"): twelve pairs of rigid ribs and a rigid sternum
// on the thoracic vertebrae. Each rib hangs on its vertebrae by the costovertebral complex (the
// rib head's and the tubercle's joints together, as Lebschy et al. 2024 tested them: a 6-DOF
// bushing), ribs 1-7 reach the sternum and ribs 8-10 the cartilage above through costal
// cartilage (a point spring), ribs 11 and 12 float. Geometry and stiffness: data/spine/rib_cage.json.
//
// The ribs carry no load of their own (their weight is in the per-level trunk masses), so in
// equilibrium they sit where their springs put them: linear in the thoracic vertebrae's motion.
// The network is condensed once onto the twelve thoracic vertebrae (a 72 × 72 stiffness, the
// ribs and sternum recovered from it) and measured in T6's frame — corotational, so the whole
// thorax turns and moves freely and only the vertebrae's motion relative to one another strains
// the cage.
//
// Units: mm, N, N·mm; frame of the spine model (x lateral, the body's right −x; y up; z anterior).
#pragma once

#include "spinesim/spine/kinematics.hpp"

#include <Eigen/Core>

#include <string>
#include <vector>

namespace spinesim::spine {

/// What a rib connects to at its front.
enum class RibFront { Sternum, RibAbove, Floating };

struct Rib {
  std::string name;  ///< "rib_R7" (right) or "rib_L7" (left); never a vertebra's name
  int number = 0;    ///< 1 … 12
  int side = -1;     ///< −1 right (x < 0), +1 left
  /// The vertebrae its head articulates with (ribs 2-9: the one above and its own; the others
  /// their own only) and the bushing's share on each.
  std::vector<int> vertebrae;
  /// Reference points (mm): the head (the costovertebral complex's centre), the tubercle (drawn),
  /// the widest point (drawn), the costochondral junction (the front end of the bone) and where
  /// its cartilage ends (on the sternum or on the cartilage of the rib above).
  Eigen::Vector3d head_mm, tubercle_mm, lateral_mm, front_mm, cartilage_end_mm;
  RibFront front = RibFront::Floating;
};

/// Which parts of the cage act (the in-vitro comparison removes the anterior cage, which leaves
/// the ribs on their heads; no cage at all is ModelOptions::rib_cage = false).
struct RibCageParts {
  bool cartilage = true;              ///< the costal cartilage (the anterior cage)
  double cartilage_scale = 1.0;       ///< its stiffness × this (sensitivity)
  double costovertebral_scale = 1.0;  ///< the costovertebral complexes' stiffness × this
};

struct RibCage {
  std::vector<Rib> ribs;  ///< R1, L1, R2, L2, …, R12, L12
  Eigen::Vector3d sternum_top_mm, sternum_bottom_mm;
  std::vector<int> vertebrae;  ///< spine body index of T1 … T12 (the condensed bodies)
  int frame_body = 5;          ///< T6: the cage's energy is measured in its frame
  /// Stiffness (Lebschy et al. 2024; data/spine/rib_cage.json): costovertebral translation (N/mm)
  /// and rotation (N·mm/rad), costal cartilage translation (N/mm).
  double k_costovertebral_n_per_mm = 0, k_costovertebral_nmm_per_rad = 0;
  double k_cartilage_n_per_mm = 0;
  /// Condensed stiffness over the thoracic vertebrae's small motions u = (p, φ) per vertebra —
  /// the translation of its centre and its rotation vector, both in T6's reference frame —
  /// 6·12 square, and the rib and sternum motions it implies: q = recovery · u (6 per rib, in
  /// `ribs` order, then 6 for the sternum), each about its own reference point.
  Eigen::MatrixXd stiffness, recovery;
  std::vector<Eigen::Vector3d> body_centres_mm;  ///< the ribs' (their heads) and the sternum's
  RibCageParts parts;
};

/// Reads data/spine/rib_cage.json and builds the cage on `vertebrae` (their centres, after any
/// scaling) with every length scaled by `length_scale` (translational springs ∝ s, rotational
/// ∝ s³: the same tissue). Throws std::runtime_error naming the file for missing or malformed
/// data.
RibCage build_rib_cage(const std::string& data_dir, const std::vector<Vertebra>& vertebrae,
                       double length_scale = 1.0, const RibCageParts& parts = RibCageParts());

/// The cage's energy (N·mm) at the vertebrae's poses and the forces and couples it puts on the
/// thoracic vertebrae: `force` and `couple` per spine body (world axes, N and N·mm; the force
/// acts at the vertebra's centre). Both vectors are resized to poses.size().
double rib_cage_energy(const RibCage& cage, const std::vector<Vertebra>& vertebrae,
                       const std::vector<Pose>& poses, std::vector<Eigen::Vector3d>& force,
                       std::vector<Eigen::Vector3d>& couple);

/// World poses of the ribs (in `ribs` order) and then the sternum, for the vertebrae's poses.
std::vector<Pose> rib_cage_poses(const RibCage& cage, const std::vector<Vertebra>& vertebrae,
                                 const std::vector<Pose>& poses);

/// rib_cage_poses for a real-time loop: its buffers are allocated once, here; pose() allocates
/// nothing. Holds references to `cage` and `vertebrae`, which must outlive it.
class RibCagePoser {
 public:
  RibCagePoser(const RibCage& cage, const std::vector<Vertebra>& vertebrae);
  /// `thoracic`: the poses of cage.vertebrae (T1 … T12, in that order); `out`: the ribs' and
  /// then the sternum's poses (cage.body_centres_mm.size() of them).
  void pose(const Pose* thoracic, Pose* out);
  std::size_t bodies() const { return cage_.body_centres_mm.size(); }

 private:
  const RibCage& cage_;
  const std::vector<Vertebra>& vertebrae_;
  Eigen::VectorXd u_, q_;
  std::size_t frame_ = 0;
};

}  // namespace spinesim::spine

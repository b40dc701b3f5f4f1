// The hybrid spine's coupling (haptics/hybrid_spine.hpp): each endplate follows its vertebra,
// and the segment state reads back the relative motion the vertebrae were given — whatever the
// lower vertebra does — with no reaction when the disc moves as a rigid body.
#include "spinesim/haptics/hybrid_spine.hpp"

#include "spinesim/common/constants.hpp"
#include "spinesim/mesh/disc_geometry.hpp"
#include "spinesim/mesh/material.hpp"
#include "spinesim/mesh/structured_disc.hpp"
#include "spinesim/mss/solver.hpp"

#include <gtest/gtest.h>
#include <Eigen/Geometry>

namespace hp = spinesim::haptics;
namespace mss = spinesim::mss;
namespace mesh = spinesim::mesh;
namespace sp = spinesim::spine;
using Eigen::Vector3d;

namespace {

const mss::MssModel& disc() {
  static const mss::MssModel m = [] {
    mesh::StructuredDiscOptions o;
    o.sectors = 24;
    o.layers = 2;
    mesh::TetMesh t =
        mesh::mesh_structured_disc(mesh::disc_dimensions("L4-L5", SPINESIM_DATA_DIR), o);
    // Tilt the disc's axes (a lumbar disc is not aligned with the global frame).
    const Eigen::Matrix3d R = Eigen::AngleAxisd(0.3, Vector3d::UnitX()).toRotationMatrix();
    t.V = (t.V * R.transpose()).eval();
    t.frame.axes = R * t.frame.axes;
    return mss::MssModel(t, mesh::load_material("real-disc", SPINESIM_DATA_DIR));
  }();
  return m;
}

sp::Pose pose(const Vector3d& rotation_rad, const Vector3d& t) {
  sp::Pose p;
  p.R = sp::rotation_exp(rotation_rad);
  p.t = t;
  return p;
}

TEST(HybridSpine, EndplatesFollowTheirVertebrae) {
  hp::HybridDisc d{&disc(), mss::default_plate_center(disc().mesh()), 1, 0};
  std::vector<sp::Pose> poses(17);
  poses[0] = pose(Vector3d(0.01, 0, 0.02), Vector3d(1, 0, 0));
  poses[1] = pose(Vector3d(0, -0.03, 0), Vector3d(0, 2, 0));
  const mss::Boundary bc = hp::disc_boundary(d, poses);
  EXPECT_EQ(bc.inferior.rotation, poses[0].R);
  EXPECT_EQ(bc.superior.translation_mm, poses[1].t);
  EXPECT_EQ(bc.plate_center_mm, d.centre_mm);
  // The sacrum (lower = -1) does not move; a vertebra without a pose is refused.
  d.lower = -1;
  EXPECT_TRUE(hp::disc_boundary(d, poses).inferior.rotation.isIdentity());
  d.upper = 17;
  EXPECT_THROW(hp::disc_boundary(d, poses), std::invalid_argument);
}

TEST(HybridSpine, SegmentStateIsTheRelativeMotionInTheDiscsAxes) {
  const hp::HybridDisc d{&disc(), mss::default_plate_center(disc().mesh()), 1, 0};
  const Eigen::Matrix3d& A = disc().mesh().frame.axes;
  // Upper vertebra moved relative to the lower by a rotation φ (disc axes) about the plate
  // centre and a shift s (disc axes); the lower vertebra itself moved anywhere.
  const Vector3d phi_disc(0.02, -0.01, 0.03), s_disc(0.2, -0.5, 0.1);
  const sp::Pose lower = pose(Vector3d(0.1, 0.2, -0.05), Vector3d(3, -4, 5));
  const Eigen::Matrix3d Rrel = sp::rotation_exp(A * phi_disc);
  sp::Pose rel;  // x ↦ Rrel (x − c) + c + A s
  rel.R = Rrel;
  rel.t = d.centre_mm - Rrel * d.centre_mm + A * s_disc;
  sp::Pose upper;
  upper.R = lower.R * rel.R;
  upper.t = lower.R * rel.t + lower.t;
  std::vector<sp::Pose> all(17);
  all[0] = lower, all[1] = upper;
  const mss::Boundary bc = hp::disc_boundary(d, all);
  // The disc moved rigidly with the lower vertebra (its rest state carried along) has no
  // reaction and no volume change when the upper moves with it too.
  Eigen::VectorXd x(3 * disc().mesh().num_vertices());
  for (Eigen::Index i = 0; i < disc().mesh().num_vertices(); ++i)
    x.segment<3>(3 * i) = lower.apply(disc().mesh().V.row(i).transpose());
  const hp::SegmentState s = hp::segment_state(d, bc, x);
  EXPECT_LT((s.shift_mm - s_disc).norm(), 1e-10);
  EXPECT_LT((s.rotation_deg - phi_disc * spinesim::kDegPerRad).norm(), 1e-8);
  std::vector<sp::Pose> rigid(17);
  rigid[0] = lower, rigid[1] = lower;
  const hp::SegmentState r = hp::segment_state(d, hp::disc_boundary(d, rigid), x);
  EXPECT_LT(r.shift_mm.norm(), 1e-10);
  EXPECT_LT(r.force_n.norm(), 1e-6);
  EXPECT_LT(r.moment_nmm.norm(), 1e-5);
  EXPECT_NEAR(r.volume_change, 0, 1e-12);
  EXPECT_EQ(r.inverted_tets, 0);
}

}  // namespace

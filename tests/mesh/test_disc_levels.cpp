// The 17 disc levels: sourced dimensions from data/disc_morphometry.csv and the disc frames
// placed in the thesis spine (tables F.1/F.2).
#include "spinesim/mesh/disc_geometry.hpp"
#include "spinesim/mesh/disc_level.hpp"

#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include <algorithm>
#include <stdexcept>
#include <string>
#include <vector>

namespace {

using spinesim::mesh::disc_dimensions;
using spinesim::mesh::disc_frame_in_spine;
using spinesim::mesh::disc_levels;

const std::string kData = SPINESIM_DATA_DIR;

TEST(DiscLevels, SeventeenInCranialToCaudalOrder) {
  const auto& levels = disc_levels();
  ASSERT_EQ(levels.size(), 17u);
  EXPECT_EQ(levels.front(), "T1-T2");
  EXPECT_EQ(levels[11], "T12-L1");
  EXPECT_EQ(levels.back(), "L5-S1");
  // Each level's inferior vertebra is the next level's superior one.
  for (std::size_t i = 0; i + 1 < levels.size(); ++i) {
    const std::string below = levels[i].substr(levels[i].find('-') + 1);
    EXPECT_EQ(levels[i + 1].substr(0, levels[i + 1].find('-')), below);
  }
}

TEST(DiscDimensions, EveryLevelIsPlausible) {
  for (const auto& level : disc_levels()) {
    SCOPED_TRACE(level);
    const auto d = disc_dimensions(level, kData);
    EXPECT_EQ(d.level, level);
    for (double w : {d.lower_width_mm, d.upper_width_mm}) {
      EXPECT_GE(w, 20.0);
      EXPECT_LE(w, 60.0);
    }
    for (double depth : {d.lower_depth_mm, d.upper_depth_mm}) {
      EXPECT_GE(depth, 10.0);
      EXPECT_LE(depth, 50.0);
    }
    EXPECT_GE(d.height_mm, 3.0);
    EXPECT_LE(d.height_mm, 15.0);
  }
}

TEST(DiscDimensions, LumbarValuesAsInSpec) {
  // Panjabi 1992 upper-endplate widths; a disc's lower outline is its inferior vertebra's
  // upper endplate, its upper outline the superior vertebra's lower endplate (taken as wide).
  const auto l34 = disc_dimensions("L3-L4", kData);
  const auto l45 = disc_dimensions("L4-L5", kData);
  EXPECT_DOUBLE_EQ(l34.lower_width_mm, 46.6);
  EXPECT_DOUBLE_EQ(l45.upper_width_mm, 46.6);
  EXPECT_DOUBLE_EQ(l45.lower_width_mm, 47.3);
  EXPECT_DOUBLE_EQ(disc_dimensions("L1-L2", kData).lower_width_mm, 42.6);
  EXPECT_DOUBLE_EQ(disc_dimensions("T12-L1", kData).lower_width_mm, 41.2);
  EXPECT_DOUBLE_EQ(disc_dimensions("T11-T12", kData).lower_width_mm, 39.2);
  EXPECT_DOUBLE_EQ(disc_dimensions("T1-T2", kData).upper_width_mm, 24.5);
  // Twomey 1985 heights, Busscher 2010 for T12-L1.
  EXPECT_DOUBLE_EQ(l45.height_mm, 11.3);
  EXPECT_DOUBLE_EQ(disc_dimensions("L5-S1", kData).height_mm, 10.6);
  EXPECT_DOUBLE_EQ(disc_dimensions("T12-L1", kData).height_mm, 9.3);
}

TEST(DiscDimensions, AdjacentDiscsShareTheirVertebra) {
  // Under the EPWl ~ EPWu assumption the vertebra between two discs gives both widths.
  const auto& levels = disc_levels();
  for (std::size_t i = 0; i + 1 < levels.size(); ++i) {
    SCOPED_TRACE(levels[i]);
    EXPECT_DOUBLE_EQ(disc_dimensions(levels[i], kData).lower_width_mm,
                     disc_dimensions(levels[i + 1], kData).upper_width_mm);
  }
}

TEST(DiscDimensions, LevelNamesAreCaseInsensitive) {
  const auto d = disc_dimensions("l4-l5", kData);
  EXPECT_EQ(d.level, "L4-L5");
  EXPECT_DOUBLE_EQ(d.height_mm, 11.3);
  EXPECT_EQ(disc_dimensions(" t12-l1 ", kData).level, "T12-L1");
}

TEST(DiscDimensions, UnknownLevelIsRefusedWithTheKnownOnes) {
  for (const char* bad : {"L5-L6", "C7-T1", "L4L5", ""}) {
    try {
      disc_dimensions(bad, kData);
      ADD_FAILURE() << "accepted " << bad;
    } catch (const std::invalid_argument& e) {
      const std::string m = e.what();
      EXPECT_NE(m.find("unknown disc level"), std::string::npos) << m;
      EXPECT_NE(m.find("T1-T2"), std::string::npos) << m;
      EXPECT_NE(m.find("L5-S1"), std::string::npos) << m;
      EXPECT_EQ(m.find('\n'), std::string::npos) << m;
    }
  }
  EXPECT_THROW(disc_frame_in_spine("X1-X2", kData), std::invalid_argument);
}

TEST(DiscDimensions, MissingDataFolderIsRefused) {
  EXPECT_THROW(disc_dimensions("L4-L5", "/nonexistent/spinesim-data"), std::invalid_argument);
  EXPECT_THROW(disc_frame_in_spine("L4-L5", "/nonexistent/spinesim-data"), std::invalid_argument);
}

TEST(DiscFrame, OrthonormalRightHandedAndAnterior) {
  for (const auto& level : disc_levels()) {
    SCOPED_TRACE(level);
    const auto f = disc_frame_in_spine(level, kData);
    const Eigen::Matrix3d& r = f.axes;
    EXPECT_TRUE((r.transpose() * r).isApprox(Eigen::Matrix3d::Identity(), 1e-12));
    EXPECT_NEAR(r.determinant(), 1.0, 1e-12);
    EXPECT_GT(r(1, 1), 0.8);           // axial axis points up (within ~37 degrees of global y)
    EXPECT_GT(r(2, 2), 0.0);           // anterior axis has a positive global-z component
    EXPECT_NEAR(r(0, 0), 1.0, 1e-12);  // the thesis spine is symmetric: lateral = global x
  }
}

TEST(DiscFrame, OriginsAreTheTableF2JointPoints) {
  const auto l45 = disc_frame_in_spine("L4-L5", kData);
  EXPECT_TRUE(l45.origin_mm.isApprox(Eigen::Vector3d(0, 93, 0)));
  EXPECT_TRUE(disc_frame_in_spine("T1-T2", kData).origin_mm.isApprox(Eigen::Vector3d(0, 510, -30)));
  EXPECT_TRUE(disc_frame_in_spine("L5-S1", kData).origin_mm.isApprox(Eigen::Vector3d(0, 63, -9)));
}

TEST(DiscFrame, AxisRunsFromInferiorToSuperiorCentre) {
  // L4-L5: L5 centre (0, 84, -12) -> L4 centre (0, 112, -8.5), table F.1.
  const Eigen::Vector3d l4l5 = Eigen::Vector3d(0, 28, 3.5).normalized();
  EXPECT_TRUE(disc_frame_in_spine("L4-L5", kData).axes.col(1).isApprox(l4l5, 1e-12));
  // L5-S1 has no sacrum centre: from the joint point (0, 63, -9) to L5 (0, 84, -12).
  const Eigen::Vector3d l5s1 = Eigen::Vector3d(0, 21, -3).normalized();
  EXPECT_TRUE(disc_frame_in_spine("l5-s1", kData).axes.col(1).isApprox(l5s1, 1e-12));
}

}  // namespace

// A level meshed in the spine is the same mesh as the upright one, carried by the level's frame.
TEST(DiscLevels, ALevelMeshedInTheSpineIsTheUprightMeshInItsFrame) {
  using spinesim::mesh::DiscPlacement;
  const auto local =
      spinesim::mesh::mesh_structured_level("T12-L1", {}, kData, DiscPlacement::local);
  const auto placed = spinesim::mesh::mesh_structured_level("T12-L1", {}, kData);
  const auto frame = disc_frame_in_spine("T12-L1", kData);
  ASSERT_EQ(local.num_vertices(), placed.num_vertices());
  ASSERT_TRUE((local.T.array() == placed.T.array()).all());
  double worst = 0;
  for (Eigen::Index i = 0; i < local.num_vertices(); ++i) {
    const Eigen::Vector3d mapped = frame.origin_mm + frame.axes * local.V.row(i).transpose();
    worst = std::max(worst, (mapped - placed.V.row(i).transpose()).norm());
  }
  EXPECT_LT(worst, 1e-9);
  EXPECT_TRUE(local.frame.axes.isIdentity());
  EXPECT_TRUE(placed.frame.axes.isApprox(frame.axes));
  EXPECT_THROW(spinesim::mesh::disc_level_frame("T12-L2", kData), std::invalid_argument);
}

// A disc carried between two vertebrae: unchanged when neither moves; its lower endplate stays
// and its upper one follows the upper vertebra rigidly; lifted by δ along its axis it is
// stretched to (h + δ)/h of its volume exactly; wedged by 5° about its AP axis it keeps its
// volume to second order and no tet inverts; a wedge that would invert tets is refused.
TEST(DiscCarry, EndplatesFollowTheirVertebraeAndTheWallStretchesLinearly) {
  using namespace spinesim::mesh;
  StructuredDiscOptions so;
  const auto d = disc_dimensions("T7-T8", kData);
  const TetMesh straight = mesh_structured_level("T7-T8", so, kData, DiscPlacement::local);
  const DiscFrame frame;  // local placement: the identity
  const double h = d.height_mm, v0 = mesh_volume(straight);
  auto endplate = [&](Eigen::Index i) {
    const double y = straight.V(i, 1);
    return std::abs(y + h / 2) < 1e-9 ? -1 : std::abs(y - h / 2) < 1e-9 ? 1 : 0;
  };

  TetMesh m = straight;
  carry_between(m, frame, h, RigidMotion(), RigidMotion());
  EXPECT_LT((m.V - straight.V).cwiseAbs().maxCoeff(), 1e-12);

  RigidMotion lift;
  lift.t = Eigen::Vector3d(0, 0.5, 0);
  m = straight;
  carry_between(m, frame, h, RigidMotion(), lift);
  EXPECT_NEAR(mesh_volume(m), v0 * (h + 0.5) / h, 1e-9 * v0);

  RigidMotion wedge;
  wedge.R = Eigen::AngleAxisd(5 * M_PI / 180, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  wedge.t = Eigen::Vector3d(0, h / 2, 0) -
            wedge.R * Eigen::Vector3d(0, h / 2, 0);  // about the upper centre
  m = straight;
  carry_between(m, frame, h, RigidMotion(), wedge);
  int lower = 0, upper = 0;
  for (Eigen::Index i = 0; i < m.V.rows(); ++i) {
    const Eigen::Vector3d x = straight.V.row(i).transpose(), y = m.V.row(i).transpose();
    if (endplate(i) < 0) {
      ++lower;
      EXPECT_LT((y - x).norm(), 1e-12);
    } else if (endplate(i) > 0) {
      ++upper;
      EXPECT_LT((y - wedge.apply(x)).norm(), 1e-12);
    }
  }
  EXPECT_GT(lower, 20);
  EXPECT_GT(upper, 20);
  EXPECT_NEAR(mesh_volume(m), v0, 0.01 * v0);
  for (Eigen::Index t = 0; t < m.T.rows(); ++t) ASSERT_GT(tet_volume(m, t), 0);
  // The frame goes halfway: its axis turned 2.5 deg about z, its origin midway.
  const Eigen::Matrix3d half =
      Eigen::AngleAxisd(2.5 * M_PI / 180, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  EXPECT_LT((m.frame.axes - half * straight.frame.axes).norm(), 1e-12);
  EXPECT_LT((m.frame.origin_mm - 0.5 * wedge.apply(straight.frame.origin_mm)).norm(), 1e-12);

  // Carried rigidly (both vertebrae the same motion), the frame is that motion's image.
  RigidMotion both;
  both.R = Eigen::AngleAxisd(0.3, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  both.t = Eigen::Vector3d(4, -5, 6);
  m = straight;
  carry_between(m, frame, h, both, both);
  EXPECT_LT((m.frame.axes - both.R * straight.frame.axes).norm(), 1e-12);
  EXPECT_LT((m.frame.origin_mm - both.apply(straight.frame.origin_mm)).norm(), 1e-12);

  RigidMotion flip;
  flip.R = Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  m = straight;
  EXPECT_THROW(carry_between(m, frame, h, RigidMotion(), flip), std::invalid_argument);
}

// Quality measures on tets with known answers.
#include "spinesim/mesh/quality.hpp"

#include <gtest/gtest.h>

#include <cmath>

using namespace spinesim::mesh;

namespace {
TetMesh one_tet(const Eigen::Matrix<double, 4, 3>& P) {
  TetMesh m;
  m.V = P;
  m.T.resize(1, 4);
  m.T << 0, 1, 2, 3;
  m.region = Eigen::VectorXi::Ones(1);
  m.surface = Eigen::VectorXi::Zero(4);
  return m;
}
}  // namespace

TEST(Quality, RegularTet) {
  // Unit-edge regular tet.
  Eigen::Matrix<double, 4, 3> P;
  P << 0, 0, 0, 1, 0, 0, 0.5, std::sqrt(3.0) / 2, 0, 0.5, std::sqrt(3.0) / 6, std::sqrt(2.0 / 3.0);
  const auto q = quality_report(one_tet(P), std::sqrt(2.0) / 12);
  const double dihedral = std::acos(1.0 / 3.0) * 180.0 / M_PI;  // 70.5288°
  EXPECT_NEAR(q.min_dihedral_deg, dihedral, 1e-9);
  EXPECT_NEAR(q.max_dihedral_deg, dihedral, 1e-9);
  EXPECT_NEAR(q.max_radius_edge_ratio, std::sqrt(6.0) / 4, 1e-12);
  EXPECT_NEAR(q.mean_radius_edge_ratio, std::sqrt(6.0) / 4, 1e-12);
  EXPECT_NEAR(q.min_edge_mm, 1.0, 1e-12);
  EXPECT_NEAR(q.max_edge_mm, 1.0, 1e-12);
  EXPECT_NEAR(q.volume_error(), 0.0, 1e-12);
  EXPECT_EQ(q.tets, 1);
  EXPECT_EQ(q.annulus_tets, 1);
}

TEST(Quality, RightCornerTet) {
  // Corner tet (0, e1, e2, e3): three right dihedrals at the corner edges, and at the three
  // hypotenuse edges acos(1/sqrt(3)) ≈ 54.74°. Circumradius sqrt(3)/2 (half the cube's
  // diagonal), shortest edge 1.
  Eigen::Matrix<double, 4, 3> P;
  P << 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1;
  const auto q = quality_report(one_tet(P), 1.0 / 6.0);
  EXPECT_NEAR(q.max_dihedral_deg, 90.0, 1e-9);
  EXPECT_NEAR(q.min_dihedral_deg, std::acos(1.0 / std::sqrt(3.0)) * 180.0 / M_PI, 1e-9);
  EXPECT_NEAR(q.max_radius_edge_ratio, std::sqrt(3.0) / 2, 1e-12);
  EXPECT_NEAR(q.max_edge_mm, std::sqrt(2.0), 1e-12);
  EXPECT_NEAR(q.mean_edge_mm, (3 + 3 * std::sqrt(2.0)) / 6, 1e-12);
  EXPECT_NEAR(q.volume_mm3, 1.0 / 6.0, 1e-15);
  const auto a = dihedral_angles_deg(P.row(0), P.row(1), P.row(2), P.row(3));
  EXPECT_NEAR(a[0], 90.0, 1e-9);                                            // edge (0,1)
  EXPECT_NEAR(a[5], std::acos(1.0 / std::sqrt(3.0)) * 180.0 / M_PI, 1e-9);  // edge (2,3)
}

TEST(Quality, ScaleInvariantAnglesAndRatios) {
  Eigen::Matrix<double, 4, 3> P;
  P << 0.1, 0.2, 0.0, 1.3, 0.1, 0.2, 0.4, 1.1, -0.1, 0.3, 0.5, 0.9;
  const auto q1 = quality_report(one_tet(P));
  const auto q2 = quality_report(one_tet(7.5 * P));
  EXPECT_NEAR(q1.min_dihedral_deg, q2.min_dihedral_deg, 1e-9);
  EXPECT_NEAR(q1.max_radius_edge_ratio, q2.max_radius_edge_ratio, 1e-9);
  EXPECT_NEAR(q2.volume_mm3, 7.5 * 7.5 * 7.5 * q1.volume_mm3, 1e-9);
  EXPECT_TRUE(std::isnan(q1.volume_error()));
}

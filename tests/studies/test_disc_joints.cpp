// Disc joints (studies/disc_joints.hpp): the shipped file is what the generator makes (the
// kernel, the rotational stiffness about the joint point, is tested in tests/fem).
#include "spinesim/fem/disc_fem.hpp"
#include "spinesim/studies/disc_joints.hpp"
#include "studies_fixtures.hpp"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <cmath>
#include <fstream>

using namespace spinesim;
using namespace spinesim::studies;

namespace {

TEST(DiscJoints, TheShippedFileIsWhatTheGeneratorMakes) {
  const std::string path =
      std::string(SPINESIM_DATA_DIR) + "/spine/disc_joints/fibre-reinforced.json";
  const nlohmann::json file = nlohmann::json::parse(std::ifstream(path));
  const DiscJointSet set =
      compute_disc_joints(SPINESIM_DATA_DIR, test::material("fibre-reinforced"),
                          fem::Formulation::displacement, {"L4-L5"});
  ASSERT_EQ(set.joints.size(), 1u);
  const auto& rows = file["joints"]["L4-L5"]["K_nmm_per_rad"];
  Eigen::Matrix3d shipped;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) shipped(r, c) = rows[std::size_t(r)][std::size_t(c)].get<double>();
  // Same mesher, seed and solver: equal up to floating-point differences between builds.
  EXPECT_LT((shipped - set.joints[0].K).norm(), 1e-3 * shipped.norm());
  // Mirror symmetry: no flexion-torsion or flexion-lateral coupling.
  EXPECT_EQ(set.joints[0].K(0, 1), 0.0);
  EXPECT_EQ(set.joints[0].K(0, 2), 0.0);
  EXPECT_LT(set.joints[0].mesh_asymmetry, 1e-2);
}

}  // namespace

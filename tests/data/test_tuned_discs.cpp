// The shipped tuned discs (data/tuned_discs.json, `spinesim calibrate --level all`): every
// level present and sound, and one level regenerated from scratch reproduces its scales.
#include "spinesim/calibration/calibrate.hpp"
#include "spinesim/calibration/tuned_set.hpp"
#include "spinesim/fem/disc_fem.hpp"
#include "spinesim/mesh/disc_geometry.hpp"
#include "spinesim/mesh/mesher.hpp"

#include <gtest/gtest.h>

#include <cmath>

namespace spinesim::calibration {
namespace {

const TunedSet& shipped() {
  static const TunedSet set = read_tuned_set(shipped_tuned_set_path(SPINESIM_DATA_DIR));
  return set;
}

TEST(ShippedTunedDiscs, EveryLevelIsThereAndBeatsVanGelder) {
  const TunedSet& set = shipped();
  EXPECT_EQ(set.material_name, "real-disc");
  ASSERT_TRUE(set.settings.contains("cell_size_mm"));
  for (const std::string& level : mesh::disc_levels()) {
    SCOPED_TRACE(level);
    const TunedDisc& d = tuned_level(set, level);
    EXPECT_TRUE(d.report["ipopt"]["success"].get<bool>()) << d.report["ipopt"]["status"];
    EXPECT_EQ(d.scales.size(), d.report["knobs"].size());
    // The fitted (linearised) model beats the untuned thesis network on every case, trained
    // or held out, and its 6x6 diagonal is within 10 % of the FEM's.
    for (const char* set_name : {"train", "holdout"})
      for (const auto& c : d.report[set_name])
        EXPECT_LT(c["tuned_error_linear"].get<double>(), c["untuned_error_linear"].get<double>()) << c["name"];
    for (const auto& r : d.report["stiffness_diagonal"]["ratio_tuned"]) EXPECT_NEAR(r.get<double>(), 1.0, 0.10);
  }
}

// Regenerate T12-L1 (the smallest mesh: 6,965 tets) with the shipped settings: same mesher, FEM, knobs,
// cases and weights. The scales agree to 5 %: a build with other compiler flags meshes the disc
// differently in the last bits (CGAL), which moves the optimum slightly; the fit itself is
// deterministic (same build: identical to ~1e-6).
TEST(ShippedTunedDiscs, RegeneratingOneLevelReproducesItsScales) {
  const std::string level = "T12-L1";
  const TunedDisc& shipped_disc = tuned_level(shipped(), level);
  mesh::MeshOptions opt;
  opt.cell_size_mm = shipped().settings["cell_size_mm"][level].get<double>();
  const mesh::TetMesh m = mesh::mesh_parametric_disc(mesh::disc_dimensions(level, SPINESIM_DATA_DIR), opt,
                                                    mesh::disc_frame_in_spine(level, SPINESIM_DATA_DIR));
  const mesh::RegionMaterials materials = mesh::load_material(shipped().material_name, SPINESIM_DATA_DIR);
  EXPECT_EQ(check_applies(shipped_disc, m, materials), "");

  const Eigen::Vector3d c = fem::DiscFem::default_plate_center(m);
  const fem::DiscFem fem(m, materials, shipped_disc.fem_order, c);
  std::vector<fem::LoadCase> cases;
  std::vector<std::string> train;
  for (const auto& r : shipped_disc.report["train"]) {
    cases.push_back(fem::load_case(r["name"]));
    train.push_back(r["name"]);
  }
  for (const auto& r : shipped_disc.report["holdout"]) cases.push_back(fem::load_case(r["name"]));
  const mss::MssModel model(m, materials, shipped_disc.options);
  LinearMss lin(model, available_knobs(model.options()), c);
  Weights w;
  w.reaction = shipped_disc.report["weights"]["reaction"];
  w.stiffness = shipped_disc.report["weights"]["stiffness"];
  w.regularisation = shipped_disc.report["weights"]["regularisation"];
  Objective obj(lin, make_reference(fem, m, cases), train, w);
  const CalibrationResult r = calibrate(obj, Eigen::VectorXd::Zero(Eigen::Index(lin.knobs().size())));
  ASSERT_TRUE(r.success) << r.status;
  ASSERT_EQ(lin.knobs().size(), shipped_disc.scales.size());
  for (std::size_t j = 0; j < lin.knobs().size(); ++j) {
    const std::string name = knob_name(lin.knobs()[j]);
    const double again = std::exp(r.log_scales(Eigen::Index(j)));
    EXPECT_NEAR(again, shipped_disc.scales.at(name), 0.05 * shipped_disc.scales.at(name)) << name;
  }
  // The objective it reaches is the shipped one's.
  EXPECT_NEAR(r.final.value, shipped_disc.report["objective"]["final"]["J"].get<double>(),
              0.05 * shipped_disc.report["objective"]["final"]["J"].get<double>());
}

}  // namespace
}  // namespace spinesim::calibration

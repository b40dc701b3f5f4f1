// The shipped tuned discs (data/tuned_discs.json, `spinesim calibrate --level all`): every
// level present and sound, and one level regenerated from scratch reproduces its scales.
#include "spinesim/calibration/calibrate.hpp"
#include "spinesim/calibration/tuned_set.hpp"
#include "spinesim/fem/disc_fem.hpp"
#include "spinesim/mesh/disc_geometry.hpp"
#include "spinesim/mesh/mesher.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

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
        EXPECT_LT(c["tuned_error_linear"].get<double>(), c["untuned_error_linear"].get<double>())
            << c["name"];
    for (const auto& r : d.report["stiffness_diagonal"]["ratio_tuned"])
      EXPECT_NEAR(r.get<double>(), 1.0, 0.10);
  }
}

// Regenerate T12-L1 (the smallest mesh: 6,965 tets) with the shipped settings: same mesher, FEM,
// knobs, cases and weights.
//  - Same mesh as the shipped fit (same fingerprint: a build like the one that wrote the file):
//    the fit is deterministic, so the scales and J agree to 1e-4.
//  - Another mesh (a build with other compiler flags — the debug+sanitizer preset is generic,
//    the release build -march=native — meshes the disc differently in the last bits, CGAL):
//    the raw scales then move by up to ~12 % (measured: main.annulus 0.122 -> 0.111), because J
//    is flat along a trade-off between the main springs and the other terms. What the file
//    promises is what the scales do, so that is checked: on the new mesh the shipped scales
//    reach J within 10 % of a fresh fit's, every case's error within 1 point of it, and the
//    6x6 diagonal within 2 %.
TEST(ShippedTunedDiscs, RegeneratingOneLevelReproducesItsScales) {
  const std::string level = "T12-L1";
  const TunedDisc& shipped_disc = tuned_level(shipped(), level);
  mesh::MeshOptions opt;
  opt.cell_size_mm = shipped().settings["cell_size_mm"][level].get<double>();
  const mesh::TetMesh m =
      mesh::mesh_parametric_disc(mesh::disc_dimensions(level, SPINESIM_DATA_DIR), opt,
                                 mesh::disc_frame_in_spine(level, SPINESIM_DATA_DIR));
  const mesh::RegionMaterials materials =
      mesh::load_material(shipped().material_name, SPINESIM_DATA_DIR);
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
  const CalibrationResult r =
      calibrate(obj, Eigen::VectorXd::Zero(Eigen::Index(lin.knobs().size())));
  ASSERT_TRUE(r.success) << r.status;
  ASSERT_EQ(lin.knobs().size(), shipped_disc.scales.size());
  Eigen::VectorXd shipped_p(Eigen::Index(lin.knobs().size()));
  for (std::size_t j = 0; j < lin.knobs().size(); ++j)
    shipped_p(Eigen::Index(j)) = std::log(shipped_disc.scales.at(knob_name(lin.knobs()[j])));
  const double shipped_J = shipped_disc.report["objective"]["final"]["J"].get<double>();

  if (fingerprint(m) == shipped_disc.mesh) {
    for (std::size_t j = 0; j < lin.knobs().size(); ++j)
      EXPECT_NEAR(r.log_scales(Eigen::Index(j)), shipped_p(Eigen::Index(j)), 1e-4)
          << knob_name(lin.knobs()[j]);
    EXPECT_NEAR(r.final.value, shipped_J, 1e-4 * shipped_J);
    return;
  }
  std::printf("another build's mesh (%lld tets, shipped %lld): comparing what the scales do\n",
              static_cast<long long>(m.num_tets()), static_cast<long long>(shipped_disc.mesh.tets));
  const Evaluation with_shipped = obj.evaluate(shipped_p, false);
  EXPECT_LT(with_shipped.value, 1.10 * r.final.value);
  for (std::size_t k = 0; k < with_shipped.cases.size(); ++k)
    EXPECT_NEAR(with_shipped.cases[k].displacement_error, r.final.cases[k].displacement_error, 0.01)
        << with_shipped.cases[k].name;
  for (int i = 0; i < 6; ++i)
    EXPECT_NEAR(with_shipped.k6(i, i) / r.final.k6(i, i), 1.0, 0.02) << "K6 " << i;
}

}  // namespace
}  // namespace spinesim::calibration

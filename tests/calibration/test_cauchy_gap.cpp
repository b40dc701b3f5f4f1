// The Cauchy gap, measured: a network of central springs behaves like lambda = mu (nu = 1/4), so
// tuning the thesis's spring constants cannot fit a nu = 0.45 disc's displacement field, and
// the per-tetrahedron volume term (the missing (tr eps)^2 energy) closes most of the gap. The
// property: what the volume term buys grows with nu.
#include "spinesim/calibration/calibrate.hpp"
#include "spinesim/fem/disc_fem.hpp"
#include "spinesim/mesh/disc_geometry.hpp"
#include "spinesim/mesh/structured_disc.hpp"

#include <gtest/gtest.h>

namespace spinesim::calibration {
namespace {

/// Tuned linear compression error on the structured L4-L5 disc (360 tets) for a homogeneous
/// material of Poisson ratio nu, with or without the per-tet volume term.
double tuned_compression_error(double nu, bool volume_term) {
  static const mesh::TetMesh m =
      mesh::mesh_structured_disc(mesh::disc_dimensions("L4-L5", SPINESIM_DATA_DIR));
  mesh::RegionMaterials mat;
  mat.name = "homogeneous";
  mat.fallback = {3.22, nu, 1038.0};
  const Eigen::Vector3d c = fem::DiscFem::default_plate_center(m);
  const fem::DiscFem fem(m, mat, 2, c);
  mss::MssOptions o;
  o.volume_term = volume_term;
  const mss::MssModel model(m, mat, o);
  LinearMss lin(model, available_knobs(o), c);
  Objective obj(lin, make_reference(fem, m, fem::standard_load_cases()),
                {"compression", "shear-ap", "flexion", "torsion"});
  const CalibrationResult r =
      calibrate(obj, Eigen::VectorXd::Zero(Eigen::Index(lin.knobs().size())));
  EXPECT_TRUE(r.success) << r.status;
  for (const CaseError& e : r.final.cases)
    if (e.name == "compression") return e.displacement_error;
  ADD_FAILURE() << "no compression case";
  return 0;
}

TEST(CauchyGap, TheVolumeTermBuysMoreTheMoreIncompressibleTheDisc) {
  const double thesis_25 = tuned_compression_error(0.25, false),
               volume_25 = tuned_compression_error(0.25, true);
  const double thesis_45 = tuned_compression_error(0.45, false),
               volume_45 = tuned_compression_error(0.45, true);
  std::printf(
      "compression error, tuned: nu 0.25 springs %.1f %% -> +volume %.1f %%; nu 0.45 springs %.1f "
      "%% -> "
      "+volume %.1f %%\n",
      100 * thesis_25, 100 * volume_25, 100 * thesis_45, 100 * volume_45);
  EXPECT_LT(volume_25, thesis_25);        // more knobs never fit worse
  EXPECT_LT(volume_45, 0.5 * thesis_45);  // at nu = 0.45 the volume term at least halves the error
  EXPECT_GT(thesis_45, 1.5 * thesis_25);  // the springs alone fail as nu leaves 1/4 ...
  EXPECT_GT(thesis_45 - volume_45,
            2.0 * (thesis_25 - volume_25));  // ... and the volume term is what helps
}

}  // namespace
}  // namespace spinesim::calibration

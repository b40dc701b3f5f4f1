// The MSS fitted to a nonlinear reference at several load levels (nonlinear_fit.hpp): scales
// that generated a synthetic reference are recovered from another start, the errors of the
// generating model are zero, bad requests are refused, and the FEM reference carries the load it
// was given (its reaction is minus the applied wrench) and stiffens with load in torsion.
#include "spinesim/calibration/nonlinear_fit.hpp"

#include "spinesim/mesh/disc_level.hpp"
#include "spinesim/mesh/material.hpp"
#include "spinesim/mesh/rigid_plate.hpp"
#include "spinesim/mss/boundary.hpp"
#include "spinesim/mss/quantities.hpp"

#include <gtest/gtest.h>

#include <stdexcept>

namespace spinesim::calibration {
namespace {

mesh::TetMesh disc() { return mesh::mesh_structured_level("L4-L5", {}, SPINESIM_DATA_DIR); }

mesh::RegionMaterials fibre_material() {
  return mesh::load_material("fibre-reinforced", SPINESIM_DATA_DIR);
}

mss::MssOptions fibre_options() {
  mss::MssOptions o;
  o.radial_springs = false;
  o.torsion_springs = false;
  o.volume_term = true;
  o.fibre_springs = true;
  return o;
}

/// A reference made by `truth` itself at given plate motions (so that the fit can reach zero).
NonlinearReference synthetic_reference(const mss::MssModel& truth) {
  NonlinearReference ref;
  ref.plate_center_mm = mss::default_plate_center(truth.mesh());
  ref.plate_rms_radius_mm = mesh::plate_rms_radius(truth.mesh(), ref.plate_center_mm);
  const Eigen::Vector3d axis = truth.mesh().frame.axes.col(1),
                        lateral = truth.mesh().frame.axes.col(2);
  struct Motion {
    const char* name;
    Vector6d q;
  };
  std::vector<Motion> motions;
  for (double level : {0.1, 1.0}) {
    Vector6d compression = Vector6d::Zero(), torsion = Vector6d::Zero(), flexion = Vector6d::Zero();
    compression.head<3>() = -0.4 * level * axis;
    torsion.tail<3>() = 0.06 * level * axis;
    flexion.tail<3>() = 0.08 * level * lateral;
    motions.push_back({"compression", compression});
    motions.push_back({"torsion", torsion});
    motions.push_back({"flexion", flexion});
  }
  int k = 0;
  for (const Motion& m : motions) {
    mss::Boundary bc;
    bc.plate_center_mm = ref.plate_center_mm;
    bc.superior = mss::plate_pose(m.q, ref.plate_center_mm);
    const mss::StaticResult s = mss::solve_static(truth, bc);
    EXPECT_TRUE(s.converged) << m.name;
    NonlinearReferenceCase c;
    c.name = m.name;
    c.level = k++ < 3 ? 0.1 : 1.0;
    c.plate_motion = m.q;
    c.reaction = s.reaction_wrench;
    c.vertex_displacement_mm = mss::displacement(truth, s.x_mm);
    ref.cases.push_back(c);
  }
  return ref;
}

// The two ways to the MSS's equilibrium at a reference pose agree where both converge: Newton
// from the reference's field, and the plate moved there in kPoseSteps steps from rest (the
// fallback when the first does not converge). Flexion at 0.08 rad (4.6 degrees) and
// torsion: same positions to 1e-6 mm and reaction to 1e-6 of its size.
TEST(MssAtReferencePose, PoseStepsReachTheSameEquilibriumAsNewtonFromTheField) {
  const mss::MssModel truth(disc(), fibre_material(), fibre_options());
  const NonlinearReference ref = synthetic_reference(truth);
  for (const NonlinearReferenceCase& c : ref.cases) {
    if (c.level != 1.0) continue;
    SCOPED_TRACE(c.name);
    // The field is the truth's own; start from a third of it so that Newton has work to do.
    NonlinearReferenceCase far = c;
    far.vertex_displacement_mm *= 1.0 / 3.0;
    const mss::StaticResult field =
        mss_at_reference_pose(truth, ref, far, {}, PoseStart::fem_field);
    const mss::StaticResult steps =
        mss_at_reference_pose(truth, ref, far, {}, PoseStart::pose_steps);
    ASSERT_TRUE(field.converged) << field.message;
    ASSERT_TRUE(steps.converged) << steps.message;
    EXPECT_LT((field.x_mm - steps.x_mm).cwiseAbs().maxCoeff(), 1e-6);
    EXPECT_LT((field.reaction_wrench - steps.reaction_wrench).norm(), 1e-6 * c.reaction.norm());
    EXPECT_LT((steps.reaction_wrench - c.reaction).norm(), 1e-6 * c.reaction.norm());
  }
}

TEST(NonlinearFit, RecoversTheScalesThatMadeTheReference) {
  const mesh::TetMesh m = disc();
  mss::MssModel truth(m, fibre_material(), fibre_options());
  auto scales = truth.options().scales;
  scales[int(mss::Term::main)].by_region = {0.4, 1.5};
  scales[int(mss::Term::volume)].by_region = {2.0, 0.7};
  scales[int(mss::Term::fibre)].by_region[0] = 3.0;
  truth.set_scales(scales);
  const NonlinearReference ref = synthetic_reference(truth);

  const std::vector<NonlinearCaseError> exact = nonlinear_errors(truth, ref, {"compression"});
  ASSERT_EQ(exact.size(), 6u);
  for (const NonlinearCaseError& e : exact) {
    EXPECT_TRUE(e.converged) << e.name;
    EXPECT_LT(e.reaction_error, 1e-6) << e.name;
    EXPECT_LT(e.displacement_error, 1e-6) << e.name;
    EXPECT_EQ(e.trained, e.name == "compression");
  }

  const mss::MssModel start(m, fibre_material(), fibre_options());  // every scale 1
  NonlinearFitRequest request;
  request.train = {"compression", "torsion"};
  request.fit.threads = 2;
  const NonlinearFitResult fit = fit_mss_nonlinear(start, ref, request);
  ASSERT_TRUE(fit.fit.success) << fit.fit.status;
  ASSERT_EQ(fit.knobs.size(), 5u);
  EXPECT_NEAR(fit.scales[int(mss::Term::main)].by_region[0], 0.4, 0.4e-3);
  EXPECT_NEAR(fit.scales[int(mss::Term::main)].by_region[1], 1.5, 1.5e-3);
  EXPECT_NEAR(fit.scales[int(mss::Term::volume)].by_region[0], 2.0, 2e-3);
  EXPECT_NEAR(fit.scales[int(mss::Term::volume)].by_region[1], 0.7, 0.7e-3);
  EXPECT_NEAR(fit.scales[int(mss::Term::fibre)].by_region[0], 3.0, 3e-3);
  // The held-out flexion comes right too, and the start was wrong on it.
  for (std::size_t i = 0; i < fit.after.size(); ++i) {
    if (fit.after[i].name != "flexion") continue;
    EXPECT_FALSE(fit.after[i].trained);
    EXPECT_GT(fit.before[i].reaction_error, 0.05);
    EXPECT_LT(fit.after[i].reaction_error, 1e-3);
  }
}

TEST(NonlinearFit, BadRequestsAreRefused) {
  const mesh::TetMesh m = disc();
  const mss::MssModel model(m, fibre_material(), fibre_options());
  const NonlinearReference ref = synthetic_reference(model);
  NonlinearFitRequest request;
  EXPECT_THROW(fit_mss_nonlinear(model, ref, request), std::invalid_argument);  // no case
  request.train = {"lateral-bending"};
  EXPECT_THROW(fit_mss_nonlinear(model, ref, request), std::invalid_argument);  // not there
  request.train = {"torsion"};
  request.displacement_weight = -1;
  EXPECT_THROW(fit_mss_nonlinear(model, ref, request), std::invalid_argument);
  request.displacement_weight = 1;
  NonlinearReference other = ref;
  other.cases[0].vertex_displacement_mm.conservativeResize(3, 3);
  EXPECT_THROW(fit_mss_nonlinear(model, other, request), std::invalid_argument);
  EXPECT_THROW(nonlinear_reference(m, fibre_material(), {}, {1.0}, 1), std::invalid_argument);
  EXPECT_THROW(nonlinear_reference(m, fibre_material(), {fem::load_case("torsion")}, {0.0}, 1),
               std::invalid_argument);
}

TEST(NonlinearFit, TheFemReferenceCarriesItsLoadAndStiffensInTorsion) {
  const mesh::TetMesh m = disc();
  const NonlinearReference ref =
      nonlinear_reference(m, fibre_material(), {fem::load_case("torsion")}, {0.1, 1.0}, 1);
  ASSERT_EQ(ref.cases.size(), 2u);
  double secant[2];
  for (int k = 0; k < 2; ++k) {
    const NonlinearReferenceCase& c = ref.cases[std::size_t(k)];
    // The plate's moment does the work M·θ with θ the rotation vector (fem/nonlinear_disc.hpp),
    // so the moment the disc returns is the applied one mapped by the rotation vector's
    // tangent, M + ½ θ × M to first order: the reaction is −W − ½ θ × M up to O(θ²).
    const double scale = c.wrench.norm(), theta = c.plate_motion.tail<3>().norm();
    Vector6d expected = -c.wrench;
    expected.tail<3>() -= 0.5 * c.plate_motion.tail<3>().cross(c.wrench.tail<3>());
    EXPECT_GT(theta, 0);
    EXPECT_LT((c.reaction - expected).norm(), scale * (1e-9 + theta * theta)) << c.level;
    secant[k] = c.wrench.tail<3>().norm() / c.plate_motion.tail<3>().norm();
    EXPECT_EQ(c.vertex_displacement_mm.rows(), m.num_vertices());
  }
  EXPECT_GT(secant[1], 1.05 * secant[0]);  // tension-only exponential fibres: a toe region
}

}  // namespace
}  // namespace spinesim::calibration

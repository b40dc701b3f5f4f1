// A frozen implicit step (one factor of the rest stiffness, as the palpated disc and the spine's
// discs run) on a network whose fibre elements carry the load: the factor takes the fibres from
// their tension side (MssModel::rest_tangent), and the step is line-searched, so under loads
// that stiffen the fibres the frozen run reaches the state the refreshed-matrix run reaches.
// Each part is needed (each removed, this test fails): with the rest Hessian as the factor and
// no line search, a fibre-tuned L4-L5 disc diverged within ten steps of the standard moment;
// with the line search but without the tension side, the frozen run lags (1e-5 behind after
// 300 ms at 3 kN); with the tension side but no line search, 3 kN and 40 N·m diverge; and
// the line search must not overwrite its own direction while it evaluates a trial.
#include "spinesim/mss/simulator.hpp"

#include "spinesim/mesh/disc_level.hpp"
#include "spinesim/mesh/material.hpp"

#include "solver_fixtures.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>

namespace spinesim::mss {
namespace {

using fixtures::vec6;

/// The fibre-reinforced L4-L5 structured disc with scales of the order `calibrate --nonlinear`
/// fits: main springs almost off, the annulus's fibres, radial and torsion springs carrying it.
MssModel fibre_network(const mesh::TetMesh& m) {
  MssOptions o;
  o.fibre_springs = true;
  o.volume_term = true;
  auto set = [&o](Term t, double annulus, double nucleus) {
    o.scales[static_cast<int>(t)].by_region = {annulus, nucleus};
  };
  set(Term::main, 0.002, 0.001);
  set(Term::radial, 9.0, 0.004);
  set(Term::torsion, 6.0, 0.001);
  set(Term::volume, 0.4, 0.1);
  set(Term::fibre, 0.8, 1.0);
  return MssModel(m, mesh::load_material("fibre-reinforced", SPINESIM_DATA_DIR), o);
}

/// Runs `steps` implicit 1 ms steps with one Newton iteration under a wrench ramped over the
/// first tenth; returns the final state (fails the test on a rejected step).
State run(const MssModel& model, MatrixUpdate update, const Boundary& full, int steps) {
  DynamicsOptions o;
  o.matrix_update = update;
  Simulator sim(model, o);
  State s = sim.rest_state();
  for (int k = 1; k <= steps; ++k) {
    Boundary bc = full;
    bc.wrench *= std::min(1.0, k / (0.1 * steps));
    const StepReport r = sim.step(s, bc);
    EXPECT_TRUE(r.ok) << "step " << k << ": " << r.message;
    if (!r.ok) break;
  }
  return s;
}

TEST(FrozenFibreNetwork, ReachesTheRefreshedRunsStateUnderStiffeningLoads) {
  const mesh::TetMesh m = mesh::mesh_structured_level("L4-L5", {}, SPINESIM_DATA_DIR);
  const MssModel model = fibre_network(m);
  ASSERT_GT(model.num_fibre_springs(), 0);
  // The standard flexion moment, 3 kN of compression, a 40 N·m torsion (N, N·mm).
  for (const Vector6d& w :
       {vec6(0, 0, 0, 7500, 0, 0), vec6(0, 0, -3000, 0, 0, 0), vec6(0, 0, 0, 0, 0, 40000)}) {
    SCOPED_TRACE(testing::Message() << "wrench " << w.transpose());
    const Boundary bc = fixtures::wrench_boundary(m, w);
    const State frozen = run(model, MatrixUpdate::frozen, bc, 300);
    const State fresh = run(model, MatrixUpdate::every_iteration, bc, 300);
    const double moved = (fresh.x_mm - model.rest_positions_mm()).norm();
    const double differ = (frozen.x_mm - fresh.x_mm).norm() / moved;
    std::printf("frozen vs refreshed, wrench (%g, %g, %g) N (%g, %g, %g) N·mm: %.2e of %.3g mm\n",
                w(0), w(1), w(2), w(3), w(4), w(5), differ, moved);
    EXPECT_GT(moved, 1.0);  // a load that moves the disc, well past the fibres' toe
    EXPECT_LT(differ, 1e-6);
  }
}

// A Simulator keeps the model's forces at the state its last step ended in, and a line-searched
// step starts there, so its first force evaluation is free. The steps must be exactly those of
// a Simulator that has never seen the state: bit for bit, under a moment and under a moving probe
// (whose contacts change the loads, not the model's forces).
TEST(FrozenFibreNetwork, KeptForcesStepExactlyAsAFreshSimulator) {
  const mesh::TetMesh m = mesh::mesh_structured_level("L4-L5", {}, SPINESIM_DATA_DIR);
  const MssModel model = fibre_network(m);
  DynamicsOptions o;
  o.matrix_update = MatrixUpdate::frozen;
  Boundary moment = fixtures::wrench_boundary(m, vec6(0, 0, 0, 7500, 0, 0));
  Boundary probe;
  probe.plate_center_mm = default_plate_center(m);
  // The probe at the most anterior outer-wall node, pressed in along the disc's anterior axis.
  const Eigen::Vector3d n = m.frame.axes.col(2);
  Eigen::Index front = -1;
  for (Eigen::Index i = 0; i < m.V.rows(); ++i)
    if (m.surface(i) == 3 && (front < 0 || m.V.row(i).dot(n) > m.V.row(front).dot(n))) front = i;
  ASSERT_GE(front, 0);
  for (const bool with_probe : {false, true}) {
    SCOPED_TRACE(with_probe ? "probe" : "moment");
    Simulator kept(model, o);
    State s = kept.rest_state();
    for (int k = 1; k <= 40; ++k) {
      Boundary bc = with_probe ? probe : moment;
      if (with_probe)
        bc.probes = {{m.V.row(front).transpose() + (4.0 - 0.05 * k) * n, 4.0, 50.0}};
      else
        bc.wrench *= std::min(1.0, k / 10.0);
      State fresh_state = s;
      Simulator fresh(model, o);
      const StepReport a = kept.step(s, bc), b = fresh.step(fresh_state, bc);
      ASSERT_TRUE(a.ok && b.ok) << a.message << b.message;
      ASSERT_EQ(a.newton_iterations, b.newton_iterations);
      ASSERT_TRUE(s.x_mm == fresh_state.x_mm) << "step " << k;
      ASSERT_TRUE(s.v_mm_s == fresh_state.v_mm_s) << "step " << k;
    }
    EXPECT_GT((s.x_mm - model.rest_positions_mm()).norm(), 0.1);
  }
}

}  // namespace
}  // namespace spinesim::mss

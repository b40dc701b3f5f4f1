// Measurements on the CGAL-meshed L4-L5 disc with the real-disc material (slow label):
//  1. the largest stable dt of the thesis's explicit Euler and of symplectic Euler, by
//     bisection, against Simulator::predicted_stable_dt_s;
//  2. the cost of one implicit step (frozen and refreshed matrix) and of a static solve versus
//     tetrahedron count (the per-step solve of each Cholesky backend is bench/bench_mss_cholesky).
// Timings are printed, never asserted (shared 2-core machines); each is the best of 5 batches.
// Run with OPENBLAS_NUM_THREADS=1 for the one-core numbers.
#include "spinesim/mss/simulator.hpp"
#include "spinesim/mss/solver.hpp"

#include "solver_fixtures.hpp"
#include "stability.hpp"

#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <random>

namespace spinesim::mss {
namespace {

using fixtures::vec6;
using namespace stability;
using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point t0) {
  return std::chrono::duration<double>(Clock::now() - t0).count();
}

/// Best of `batches` timings of `reps` calls of f, seconds per call.
template <class F>
double best_time(F&& f, int reps, int batches = 5) {
  double best = 1e300;
  for (int b = 0; b < batches; ++b) {
    const auto t0 = Clock::now();
    for (int k = 0; k < reps; ++k) f();
    best = std::min(best, seconds_since(t0) / reps);
  }
  return best;
}

TEST(DynamicsSlow, L4L5ExplicitStabilityLimitsMeasuredAgainstPredicted) {
  const mesh::TetMesh& m = fixtures::l4_l5(3.5);
  const MssModel model(m, fixtures::real_disc());
  Simulator sim(model, DynamicsOptions());
  std::printf(
      "L4-L5, real disc (E 3.22 MPa, nu 0.4557, rho 1038), %ld tets, %ld nodes, K_d %.3g N·s/mm, "
      "node mass %.3g..%.3g t\n",
      long(m.num_tets()), long(m.num_vertices()), model.damping_n_s_per_mm(),
      model.node_masses_t().minCoeff(), model.node_masses_t().maxCoeff());
  for (Integrator integ : {Integrator::explicit_euler, Integrator::symplectic_euler}) {
    const double predicted = sim.predicted_stable_dt_s(integ);
    const double lo = measured_stable_dt(model, integ, 0.5 * predicted, 2.0 * predicted, 1500, 10);
    std::printf(
        "  %-10s largest stable dt: measured %.4g s (1500 steps, +-0.15 %%), predicted %.4g s, "
        "ratio %.3f\n",
        integ == Integrator::explicit_euler ? "explicit" : "symplectic", lo, predicted,
        lo / predicted);
    EXPECT_GE(lo / predicted, 0.98);
    EXPECT_LE(lo / predicted, 1.25);
  }
}

TEST(DynamicsSlow, StepAndSolveCostVersusTetrahedronCount) {
  std::printf("L4-L5 real disc; ms per call, best of 5 batches\n");
  std::printf("%6s %6s %6s %6s | %8s %8s | %8s %8s %8s | %8s %5s\n", "cell", "tets", "nodes", "DOF",
              "gradient", "hessian", "impl.frz", "impl.1it", "impl.evr", "static", "iters");
  for (double cell : {3.5, 2.5, 2.0, 1.6}) {
    const mesh::TetMesh& m = fixtures::l4_l5(cell);
    const MssModel model(m, fixtures::real_disc());
    const Boundary bc = fixtures::motion_boundary(m, vec6(0.05, -0.3, 0.0, 0.0, 0.01, 0.0));
    Eigen::VectorXd g;
    Eigen::SparseMatrix<double> H;
    const Eigen::VectorXd& X = model.rest_positions_mm();
    const double t_grad = best_time([&] { model.gradient(X, g); }, 20);
    const double t_hess = best_time([&] { model.hessian(X, HessianMode::exact, H); }, 5);
    // One implicit step at dt = 1 ms: frozen factor with the boundary held, frozen with the
    // plate moving every step (the 1 kHz use), and the matrix refactorised every step.
    const auto time_steps = [&](MatrixUpdate mu, bool moving, int reps) {
      DynamicsOptions o;
      o.matrix_update = mu;
      Simulator sim(model, o);
      State s = sim.rest_state();
      Boundary b = bc;
      EXPECT_TRUE(sim.step(s, b).ok);  // analysis and first factorisation
      int step = 0;
      return best_time(
          [&] {
            if (moving)
              b.superior = plate_pose(vec6(0.0, -0.3 * std::cos(0.01 * ++step), 0.0, 0.0, 0.0, 0.0),
                                      b.plate_center_mm);
            EXPECT_TRUE(sim.step(s, b).ok);
          },
          reps);
    };
    const double t_frozen = time_steps(MatrixUpdate::frozen, false, 50);
    const double t_moving = time_steps(MatrixUpdate::frozen, true, 50);
    const double t_every = time_steps(MatrixUpdate::every_iteration, true, 5);
    Eigen::Index dofs = 0;
    const Boundary compress = fixtures::motion_boundary(m, vec6(0.0, -1.13, 0.0, 0.0, 0.0, 0.0));
    StaticResult r;
    const double t_static = best_time([&] { r = solve_static(model, compress); }, 1, 3);
    for (Eigen::Index i = 0; i < m.num_vertices(); ++i)  // unknowns with both endplates held
      dofs += (m.surface(i) != int(mesh::Surface::inferior_endplate) &&
               m.surface(i) != int(mesh::Surface::superior_endplate))
                  ? 3
                  : 0;
    std::printf("%6.2f %6ld %6ld %6ld | %8.3f %8.3f | %8.3f %8.3f %8.3f | %8.1f %5d\n", cell,
                long(m.num_tets()), long(m.num_vertices()), long(dofs), 1e3 * t_grad, 1e3 * t_hess,
                1e3 * t_frozen, 1e3 * t_moving, 1e3 * t_every, 1e3 * t_static, r.iterations);
    EXPECT_TRUE(r.converged) << r.message;
  }
  std::printf(
      "impl.frz: frozen matrix, held boundary; impl.1it: frozen, boundary moving every step;\n"
      "impl.evr: matrix refactorised every step (1 Newton iteration); static: 10 %% compression\n");
}

}  // namespace
}  // namespace spinesim::mss

// Measuring the stability limit of an integrator (shared by the dynamics tests, unit and slow):
// run from a perturbed rest state with both endplates fixed and watch the total energy.
#pragma once

#include "spinesim/mss/simulator.hpp"
#include "spinesim/mss/solver.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

namespace spinesim::mss::stability {

inline double kinetic_energy(const MssModel& model, const State& s) {
  double k = 0;
  for (Eigen::Index i = 0; i < model.num_nodes(); ++i)
    k += 0.5 * model.node_masses_t()(i) * s.v_mm_s.segment<3>(3 * i).squaredNorm();
  return k;
}

/// Runs `steps` steps with both endplates fixed from rest plus a random 1 µm perturbation of
/// the free nodes. Stable: no step rejected and the total (elastic + kinetic) energy at the end
/// below the start's — a damped system loses energy; an unstable mode grows geometrically.
inline bool stays_stable(const MssModel& model, Integrator integrator, double dt, int steps) {
  DynamicsOptions o;
  o.integrator = integrator;
  o.dt_s = dt;
  Simulator sim(model, o);
  State s = sim.rest_state();
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-1e-3, 1e-3);
  const Eigen::VectorXi& label = model.mesh().surface;
  for (Eigen::Index i = 0; i < model.num_nodes(); ++i)
    if (label(i) != 1 && label(i) != 2)
      for (int d = 0; d < 3; ++d) s.x_mm(3 * i + d) += u(rng);
  const double e0 = model.energy(s.x_mm);
  const Boundary fixed;
  for (int k = 0; k < steps; ++k)
    if (!sim.step(s, fixed).ok) return false;
  return model.energy(s.x_mm) + kinetic_energy(model, s) < e0;
}

/// Largest stable dt by bisection in log dt between a stable and an unstable bracket.
inline double measured_stable_dt(const MssModel& model, Integrator integrator, double lo, double hi,
                                 int steps, int bisections) {
  EXPECT_TRUE(stays_stable(model, integrator, lo, steps))
      << "lower bracket " << lo << " s unstable";
  EXPECT_FALSE(stays_stable(model, integrator, hi, steps)) << "upper bracket " << hi << " s stable";
  for (int k = 0; k < bisections; ++k) {
    const double mid = std::sqrt(lo * hi);
    (stays_stable(model, integrator, mid, steps) ? lo : hi) = mid;
  }
  return lo;
}

}  // namespace spinesim::mss::stability

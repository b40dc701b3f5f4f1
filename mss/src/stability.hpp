// Largest stable dt of the integrators at rest, endplates fixed (private to mss/; the
// derivation is in stability.cpp, the public entry Simulator::predicted_stable_dt_s).
#pragma once

#include "spinesim/mss/model.hpp"
#include "spinesim/mss/simulator.hpp"
#include "spinesim/mss/solver.hpp"

#include <Eigen/SparseCore>

namespace spinesim::mss::detail {

/// `H_rest`: the model's sparse Hessian at rest (3#nodes square). s; +infinity for implicit.
double predicted_stable_dt(const MssModel& model, const Eigen::SparseMatrix<double>& H_rest,
                           Integrator integrator);

}  // namespace spinesim::mss::detail

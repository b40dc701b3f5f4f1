// Largest eigenvalue of a symmetric operator by Lanczos with full reorthogonalisation (private
// to mss/), for the stable-time-step predictions of the explicit integrators.
#pragma once

#include <Eigen/Core>

#include <functional>

namespace spinesim::mss::detail {

struct TopEigenpair {
  double value = 0;
  Eigen::VectorXd vector;  ///< unit 2-norm
  int iterations = 0;
};

/// Top eigenpair of the symmetric n×n operator `apply(v, out)` (out = A v). Stops when the
/// Ritz residual |A z - theta z| <= rel_tol * theta or after max_iterations (<= n) steps.
/// Deterministic start vector.
TopEigenpair largest_eigenpair(
    const std::function<void(const Eigen::VectorXd&, Eigen::VectorXd&)>& apply, Eigen::Index n,
    double rel_tol = 1e-8, int max_iterations = 300);

}  // namespace spinesim::mss::detail

// The static potential in reduced coordinates (private to mss/):
//   Pi(y) = E(x(y)) + V_ext(x(y)) - w . q,      r = dPi/dy = P^T (dE/dx + dV_ext/dx) - (0, w)
// x(y) = x_D + P y (reduced_space.hpp); the Dirichlet nodes of x() are set by the caller.
// Shared by the static Newton solve and the implicit Euler step (which adds its inertial terms).
#pragma once

#include "external_loads.hpp"
#include "reduced_space.hpp"
#include "spinesim/mss/model.hpp"

#include <Eigen/Core>

namespace spinesim::mss::detail {

class ReducedPotential {
 public:
  ReducedPotential(const MssModel& model, const ReducedSpace& space, const ExternalLoads* loads,
                   const Vector6d& wrench)
      : model_(&model),
        space_(&space),
        loads_(loads),
        wrench_(wrench),
        x_(model.rest_positions_mm()),
        g_(Eigen::VectorXd::Zero(model.num_dofs())) {}
  ReducedPotential() = default;

  /// New loads and wrench, same model and space; keeps the workspaces (no allocation).
  void set_loads(const ExternalLoads* loads, const Vector6d& wrench) {
    loads_ = loads;
    wrench_ = wrench;
  }

  /// Full positions; set the Dirichlet nodes here before evaluating.
  Eigen::VectorXd& x() { return x_; }
  const Eigen::VectorXd& x() const { return x_; }
  /// dE/dx of the model at the last value_and_gradient() point, 3#nodes, N.
  const Eigen::VectorXd& model_gradient() const { return g_; }

  double value(const Eigen::VectorXd& y) {
    space_->set_unknown_positions(y, x_);
    return model_->energy(x_) + (no_loads() ? 0.0 : loads_->energy(x_)) - plate_work(y);
  }

  /// Keep the model's energy and gradient for the next value_and_gradient at exactly the same
  /// full positions (bit for bit): an implicit step starts where the previous step's accepted
  /// trial ended, so its first force evaluation is then free. Only while the model does not
  /// change (the Simulator's contract).
  void reuse_repeated_points(bool on) {
    reuse_ = on;
    have_last_ = false;
  }
  /// Pi(y) and r = dPi/dy (r preallocated to space.size()).
  double value_and_gradient(const Eigen::VectorXd& y, Eigen::VectorXd& r) {
    space_->set_unknown_positions(y, x_);
    double e;
    if (reuse_ && have_last_ && x_ == last_x_) {
      e = last_energy_;  // g_ still holds its gradient
    } else {
      e = model_->gradient(x_, g_);
      if (reuse_) last_x_ = x_, last_energy_ = e, have_last_ = true;
    }
    if (no_loads()) {
      space_->reduce_vector(g_, r);
    } else {
      gtot_ = g_;
      e += loads_->add_gradient(x_, gtot_);
      space_->reduce_vector(gtot_, r);
    }
    if (space_->has_plate_dofs()) r.tail<6>() -= wrench_;
    return e - plate_work(y);
  }

 private:
  bool no_loads() const { return loads_ == nullptr || loads_->empty(); }
  double plate_work(const Eigen::VectorXd& y) const {
    return space_->has_plate_dofs() ? wrench_.dot(y.tail<6>()) : 0.0;
  }

  const MssModel* model_ = nullptr;
  const ReducedSpace* space_ = nullptr;
  const ExternalLoads* loads_ = nullptr;
  Vector6d wrench_ = Vector6d::Zero();
  Eigen::VectorXd x_, g_, gtot_;
  bool reuse_ = false, have_last_ = false;
  Eigen::VectorXd last_x_;  ///< where g_ was evaluated, when reuse_
  double last_energy_ = 0;
};

}  // namespace spinesim::mss::detail

// Static equilibrium of the MSS disc (solver.hpp): Newton with an Armijo backtracking line
// search on Pi(y) = E(x(y)) + V_ext(x(y)) - w . q in reduced coordinates (reduced_space.hpp),
// and the reaction wrench and probe forces at a configuration.
//
// Convergence: |r| <= relative_tolerance * (|dE/dx| + |f_ext| + |F_w| + |M_w| / L), all norms in
// N over every node (so the Dirichlet reactions set the scale of a prescribed motion), with the
// plate-moment components of r and of the wrench divided by L, the RMS arm of the plate nodes
// about the centre. Below a round-off floor 100 eps k̄ |X|_max sqrt(n) (k̄ the mean diagonal of
// the rest stiffness) the residual counts as zero, so an unloaded disc converges at once.
// Near convergence Pi changes by less than its round-off; there a step is accepted when it
// lowers |r| instead (the Armijo test cannot see the decrease).
#include "spinesim/mss/solver.hpp"

#include "spinesim/common/timer.hpp"

#include "external_loads.hpp"
#include "reduced_potential.hpp"
#include "reduced_space.hpp"
#include "tangent.hpp"

#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

namespace spinesim::mss {

namespace {

using detail::ExternalLoads;
using detail::ReducedPotential;
using detail::ReducedSpace;

void check_positions(const Eigen::VectorXd& x, const MssModel& model, const char* what) {
  if (x.size() != model.num_dofs())
    throw std::invalid_argument(std::string("mss: ") + what + " has " + std::to_string(x.size()) +
                                " entries, expected 3 x " + std::to_string(model.num_nodes()));
  if (!x.allFinite()) throw std::invalid_argument(std::string("mss: ") + what + " is not finite");
}

double round_off_floor(const MssModel& model, const Eigen::SparseMatrix<double>& H_rest) {
  const double mean_diag = H_rest.diagonal().cwiseAbs().mean();
  const double x_max = model.rest_positions_mm().cwiseAbs().maxCoeff();
  return 100.0 * std::numeric_limits<double>::epsilon() * mean_diag * std::max(1.0, x_max) *
         std::sqrt(double(model.num_dofs()));
}

/// 1. The input of a static solve, checked (std::invalid_argument, one line).
void check_static_input(const MssModel& model, const Boundary& bc, const StaticOptions& options,
                        const Eigen::VectorXd& x_start) {
  validate(bc, model.num_nodes());
  if (!(options.relative_tolerance > 0.0) || !std::isfinite(options.relative_tolerance))
    throw std::invalid_argument("mss: static relative tolerance must be finite and > 0");
  if (options.max_iterations < 1)
    throw std::invalid_argument("mss: static max_iterations must be >= 1");
  if (x_start.size() != 0) check_positions(x_start, model, "static start vector");
  // Finite components whose norm overflows (1e155 N): no tolerance can be tested against them.
  if (bc.plate_mode == PlateMode::wrench && !std::isfinite(bc.wrench.norm()))
    throw std::invalid_argument("mss: the plate wrench is too large (its norm overflows)");
}

/// Backtracking (Armijo) line search from y along the Newton direction d (slope = r·d < 0);
/// the accepted point is left in y_trial. False when 40 halvings find none.
bool line_search(const MssModel& model, const ReducedSpace& space, ReducedPotential& pot,
                 const Eigen::VectorXd& y, const Eigen::VectorXd& d, double Pi, double slope,
                 double residual_n, Eigen::VectorXd& y_trial, Eigen::VectorXd& r_trial) {
  double alpha = 1.0;
  for (int ls = 0; ls < 40; ++ls, alpha *= 0.5) {
    y_trial = y + alpha * d;
    const double Pi_trial = pot.value(y_trial);
    if (!std::isfinite(Pi_trial)) continue;
    if (Pi_trial <= Pi + 1e-4 * alpha * slope) return true;
    if (std::abs(Pi_trial - Pi) <= 1e-12 * (std::abs(Pi) + model.energy(pot.x()))) {
      // Round-off regime: Pi cannot resolve the decrease; accept if the residual drops.
      pot.value_and_gradient(y_trial, r_trial);
      if (space.force_norm(r_trial) < residual_n) return true;
    }
  }
  return false;
}

}  // namespace

StaticResult solve_static(const MssModel& model, const Boundary& bc, const StaticOptions& options,
                          const Eigen::VectorXd& x_start) {
  const Timer t0;
  check_static_input(model, bc, options, x_start);  // 1.
  const Eigen::VectorXd& X = model.rest_positions_mm();

  // 2. Reduced space, loads, and the rest Hessian (pattern, probe default, round-off floor).
  Eigen::SparseMatrix<double> H, A;
  model.hessian(X, HessianMode::exact, H);
  const ReducedSpace space(model, H, bc.plate_mode, bc.plate_center_mm);
  const ExternalLoads loads(bc, detail::default_probe_stiffness(model, H), &model.mesh().surface);
  const double floor = round_off_floor(model, H);
  const Vector6d wrench = space.has_plate_dofs() ? bc.wrench : Vector6d::Zero();
  const double L = space.moment_length_mm();
  const double wrench_scale = wrench.head<3>().norm() + wrench.tail<3>().norm() / L;

  // 3. Start: x_start or rest, endplates at their poses (plate DOF fitted to x_start).
  ReducedPotential pot(model, space, &loads, wrench);
  pot.x() = x_start.size() ? x_start : X;
  space.set_dirichlet_positions(bc, pot.x());
  const Vector6d q0 =
      space.has_plate_dofs() && x_start.size() ? space.fit_plate_motion(x_start) : Vector6d::Zero();
  const Eigen::Index n = space.size();
  Eigen::VectorXd y(n), r(n), d(n), y_trial(n), r_trial(n);
  space.gather(pot.x(), q0, y);

  // 4. Newton with backtracking line search.
  StaticResult res;
  detail::TangentSolver tangent;
  double Pi = pot.value_and_gradient(y, r);
  for (int it = 0;; ++it) {
    res.residual_n = space.force_norm(r);
    const double scale = pot.model_gradient().norm() + loads.force_scale(pot.x()) + wrench_scale;
    if (!std::isfinite(Pi) || !r.allFinite()) {
      res.message = "non-finite energy or gradient at Newton iteration " + std::to_string(it);
      break;
    }
    // A residual or force scale that overflows is never "converged" (inf <= tol * inf is true).
    if (!std::isfinite(res.residual_n) || !std::isfinite(scale)) {
      res.message = "the forces overflow double precision at Newton iteration " +
                    std::to_string(it) + " (load or material beyond the model's range)";
      break;
    }
    if (res.residual_n <= options.relative_tolerance * scale || res.residual_n <= floor) {
      res.converged = true;
      break;
    }
    if (it == options.max_iterations) {
      res.message = "no convergence in " + std::to_string(it) +
                    " Newton iterations (|r| = " + std::to_string(res.residual_n) + " N)";
      break;
    }
    const detail::TangentKind kind =
        detail::factor_tangent(model, space, loads, pot.x(), nullptr, 0.0, H, A, tangent);
    if (kind == detail::TangentKind::failed) {
      res.message = "the tangent stiffness could not be factorised (is the disc constrained?)";
      break;
    }
    d = -r;
    tangent.solve_in_place(d);
    if (!line_search(model, space, pot, y, d, Pi, r.dot(d), res.residual_n, y_trial, r_trial)) {
      res.message = "line search failed at Newton iteration " + std::to_string(it) +
                    " (|r| = " + std::to_string(res.residual_n) + " N)";
      break;
    }
    y.swap(y_trial);
    Pi = pot.value_and_gradient(y, r);
    res.iterations = it + 1;
  }

  // 5. Results: positions, plate motion, reaction about the moved plate centre.
  space.set_unknown_positions(y, pot.x());
  res.x_mm = pot.x();
  const Eigen::Vector3d& c = bc.plate_center_mm;
  Eigen::Vector3d moved_center;
  if (space.has_plate_dofs()) {
    res.plate_motion = y.tail<6>();
    moved_center = c + res.plate_motion.head<3>();
  } else {
    res.plate_motion = plate_motion(bc.superior, c);
    moved_center = bc.superior.apply(c);
  }
  res.reaction_wrench = plate_reaction(model, res.x_mm, moved_center);
  res.seconds = t0.seconds();
  return res;
}

Vector6d plate_reaction(const MssModel& model, const Eigen::VectorXd& x, const Eigen::Vector3d& c) {
  check_positions(x, model, "position vector");
  if (!c.allFinite()) throw std::invalid_argument("mss: reaction centre is not finite");
  Eigen::VectorXd g;
  model.gradient(x, g);
  const Eigen::VectorXi& label = model.mesh().surface;
  Vector6d w = Vector6d::Zero();
  for (Eigen::Index i = 0; i < label.size(); ++i)
    if (label(i) == int(mesh::Surface::superior_endplate)) {
      const Eigen::Vector3d f = -g.segment<3>(3 * i);  // the node pulls the plate with -dE/dx_i
      w.head<3>() += f;
      w.tail<3>() += (x.segment<3>(3 * i) - c).cross(f);
    }
  return w;
}

std::vector<Eigen::Vector3d> probe_forces(const MssModel& model, const Boundary& bc,
                                          const Eigen::VectorXd& x) {
  validate(bc, model.num_nodes());
  check_positions(x, model, "position vector");
  double k_default = 0;
  for (const Probe& p : bc.probes)
    if (p.stiffness_n_per_mm == 0.0 && k_default == 0.0) k_default = default_probe_stiffness(model);
  const ExternalLoads loads(bc, k_default, &model.mesh().surface);
  std::vector<Eigen::Vector3d> out;
  Eigen::Vector3d gi;
  for (const Probe& p : loads.probes()) {
    Eigen::Vector3d f = Eigen::Vector3d::Zero();
    for (Eigen::Index i = 0; i < model.num_nodes(); ++i) {
      if (!loads.touchable(i)) continue;
      probe_contact(x.segment<3>(3 * i), p.center_mm, p.radius_mm, p.stiffness_n_per_mm, &gi);
      f += gi;  // the node is pushed with -gi, the probe with +gi
    }
    out.push_back(f);
  }
  return out;
}

double default_probe_stiffness(const MssModel& model) {
  Eigen::SparseMatrix<double> H;
  model.hessian(model.rest_positions_mm(), HessianMode::exact, H);
  return detail::default_probe_stiffness(model, H);
}

}  // namespace spinesim::mss

// Time integration of the MSS disc (solver.hpp, Simulator): explicit Euler (thesis 5.20-5.21),
// symplectic Euler and implicit Euler, in the reduced coordinates y = (x_f, q) of
// reduced_space.hpp, with the reduced lumped mass M_r = P^T M P and ambient damping
// K_d D_r = K_d P^T P (5.11) (diagonal on the free DOF, a 6x6 block on the plate DOF).
//
// Per step, with u the reduced velocity and r(y) = dPi/dy the static residual (reduced_potential):
//   explicit    u+ = u - dt M_r^-1 (r(y_n) + K_d D_r u),     y+ = y_n + dt u      (old u, 5.21)
//   symplectic  u+ = the same,                               y+ = y_n + dt u+
//   implicit    y+ = argmin Phi(y) = Pi(y) + |y - y_n - dt u|^2_{M_r}/(2 dt^2)
//                                          + K_d |y - y_n|^2_{D_r}/(2 dt),     u+ = (y+ - y_n)/dt
// The implicit step starts from y_n (free nodes where they are, endplates at their new poses);
// each Newton iteration solves (K + M_r/dt^2 + K_d D_r/dt) d = -dPhi/dy. With one iteration the
// full step is taken, and that step is exactly Baraff & Witkin's (1998) linearised backward
// Euler about x_n; with more, a backtracking line search on Phi guards every step (and the one
// step of a frozen network with fibre elements, see below). (Starting from
// the predictor y_n + dt u instead was tried: with a penalty probe the predictor extrapolates a
// node out of contact, the step drops it back in, and the contact flips every step.)
// MatrixUpdate::frozen uses the rest stiffness (exact = projected at rest; the fibre elements,
// whose exact Hessian at their tension-only kink is zero, from their tension side: model.hpp
// rest_tangent) and keeps the numeric factor across steps; it is refactorised only when the plate mode (or the wrench-mode centre)
// changes. MatrixUpdate::every_iteration factorises the current Hessian each iteration (exact,
// falling back to projected).
// Probe contacts never enter the factorised matrix. Each Newton direction solves the quadratic
// model of Phi with the linearised gap of every node near a probe,
//   r.d + d.A d / 2 + sum_pairs k_p/2 max(0, p0 - n.d_i)^2   (p0 penetration, n outward normal),
// by an active-set loop: the active pairs add k_p P^T n n^T P as low-rank terms (Woodbury,
// tangent.hpp) with A^-1 of each contact node's unit vectors solved once and cached per
// factorisation. So a node entering or leaving the probe within the step is stopped at the
// linearised surface instead of overshooting (a linear step with the contact set of its start
// made the contact flip every step at 1 ms: force jumping 19 -> 1380 N), and a contact costs
// O(n) per step with the frozen factor, never a refactorisation.
// Dirichlet nodes jump to the poses of the next boundary; their velocity is the displacement
// over dt.
#include "spinesim/mss/simulator.hpp"
#include "spinesim/mss/solver.hpp"

#include "external_loads.hpp"
#include "reduced_potential.hpp"
#include "reduced_space.hpp"
#include "sparse_cholesky.hpp"
#include "stability.hpp"
#include "tangent.hpp"

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>

#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>
#include <unordered_map>
#include <utility>
#include <vector>

namespace spinesim::mss {

namespace {

using detail::ExternalLoads;
using detail::LumpedReduced;
using detail::ReducedPotential;
using detail::ReducedSpace;

void require(bool ok, const std::string& message) {
  if (!ok) throw std::invalid_argument(message);
}

/// Passes of the implicit step's contact active-set loop.
constexpr int kActiveSetPasses = 10;

void validate_options(const DynamicsOptions& o) {
  require(std::isfinite(o.dt_s) && o.dt_s > 0.0, "mss: time step dt must be finite and > 0 s");
  require(o.newton_iterations >= 1, "mss: newton_iterations must be >= 1");
  require(std::isfinite(o.newton_relative_tolerance) && o.newton_relative_tolerance >= 0.0,
          "mss: newton_relative_tolerance must be finite and >= 0");
  require(std::isfinite(o.divergence_distance_mm) && o.divergence_distance_mm >= 0.0,
          "mss: divergence_distance_mm must be finite and >= 0 (0: bounding-box diagonal)");
}

}  // namespace

struct Simulator::Impl {
  const MssModel* model = nullptr;
  DynamicsOptions opt;
  double kd = 0;  ///< K_d, N·s/mm
  double divergence_mm = 0;
  double probe_k_default = 0;  ///< N/mm
  double floor_n = 0;          ///< round-off floor of residual norms, N
  Eigen::SparseMatrix<double> H_rest, H;

  // Reduced system of the current plate mode and centre.
  bool have_space = false;
  ReducedSpace space;
  ReducedPotential potential;         ///< on `space`; loads set per step
  LumpedReduced mass, damp, inertia;  ///< M_r, D_r, M_r/dt^2 + K_d D_r/dt
  Eigen::LDLT<Matrix6d> plate_mass;   ///< M_r's plate block (explicit integrators)
  Eigen::SparseMatrix<double> A;
  detail::TangentSolver tangent;
  Eigen::VectorXd u_rank_one, w_rank_one;  ///< workspaces of the rank-one Hessian part
  bool frozen_ready = false, contacts_attached = false;
  struct Pair {  ///< a node near a probe: normal, penetration at the step start, stiffness
    int node;
    Eigen::Vector3d n;
    double p0, k;
    bool active;
    int probe;
    double radius;
  };
  std::vector<Pair> pairs;
  std::vector<Eigen::Matrix3d> probe_K;  ///< each probe's stiffness in the last contact solve
  Eigen::MatrixXd base_W,
      base_Z;  ///< low-rank part of the factorised matrix (rank-one volume term)
  std::unordered_map<int, Eigen::MatrixXd>
      contact_solves;  ///< cached A^-1 e columns of contact nodes

  // Workspaces (sized once per reduced system): full 3#nodes and reduced vectors.
  Eigen::VectorXd x, v;
  Eigen::VectorXd y, yn, un, yhat, r, d, y_trial, r_trial, tmp, phi_work;
  Eigen::VectorXd contact_y0;    ///< A^-1 (-r) of the step (contact_direction)
  Eigen::MatrixXd contact_Zall;  ///< A^-1 of each pair's contact column (made when first active)

  void ensure_space(PlateMode mode, const Eigen::Vector3d& c);
  /// Phi(y) and its gradient into r (implicit Euler).
  double phi_and_gradient(ReducedPotential& pot, const Eigen::VectorXd& yy, Eigen::VectorXd& rr);
  /// Factorises the frozen matrix M_r/dt^2 + K_d D_r/dt + K_rest once per reduced system.
  bool factor_frozen();
  /// Newton direction d = -(A + contacts)^-1 r at xs, A the factorised matrix without probes
  /// (low-rank part base_W, base_Z), the probe contacts of the end of the step found by an
  /// active-set loop on the linearised gaps (more low-rank terms, Woodbury).
  /// Returns whether the active set settled within kActiveSetPasses.
  bool contact_direction(const ExternalLoads& loads, const Eigen::VectorXd& xs);
  /// probe_K from the contact solve's active pairs and its Woodbury matrix S.
  void contact_stiffness(const std::vector<std::size_t>& active, const Eigen::MatrixXd& S,
                         std::size_t probes);
  /// A^-1 of the reduced unit vectors of a free node (key = node) or of the plate DOF (key -1).
  const Eigen::MatrixXd& contact_solve(int key);
  /// contact_solve of every free node in `nodes` not cached yet, in one multi-column solve (a
  /// touch meets several new nodes at once).
  void prefetch_solves(const std::vector<int>& nodes);
  /// out += scale A^-1 P^T (e_i v): the A^-1 image of a node vector (cached solves).
  void add_inverse(int i, const Eigen::Vector3d& v, double scale, Eigen::Ref<Eigen::VectorXd> out);
  /// w^T z for a pair's contact column w = P^T (e_i sqrt(k) n).
  double contact_dot(const Pair& c, const Eigen::Ref<const Eigen::VectorXd>& z) const;
  StepReport explicit_step(State& s, const Boundary& bc, const ExternalLoads& loads,
                           bool symplectic);
  StepReport implicit_step(State& s, const Boundary& bc, const ExternalLoads& loads);
  StepReport commit(State& s, const Boundary& bc, int iterations);
};

void Simulator::Impl::ensure_space(PlateMode mode, const Eigen::Vector3d& c) {
  // The plate centre shapes the reduced space only through the wrench-mode plate map.
  if (have_space && space.mode() == mode && (mode == PlateMode::pose || space.center() == c))
    return;
  space = ReducedSpace(*model, H_rest, mode, c);
  const double dt = opt.dt_s;
  mass = space.lumped(model->node_masses_t());
  damp = space.lumped(Eigen::VectorXd::Ones(model->num_nodes()));
  inertia.diagonal = mass.diagonal / (dt * dt) + kd / dt * damp.diagonal;
  inertia.plate = mass.plate / (dt * dt) + kd / dt * damp.plate;
  plate_mass.compute(mass.plate);
  potential = ReducedPotential(*model, space, nullptr, Vector6d::Zero());
  potential.reuse_repeated_points(true);
  A = space.pattern();
  tangent = detail::TangentSolver();
  frozen_ready = false;
  const Eigen::Index n = space.size();
  for (Eigen::VectorXd* w : {&y, &yn, &un, &yhat, &r, &d, &y_trial, &r_trial, &tmp, &phi_work})
    w->setZero(n);
  have_space = true;
}

double Simulator::Impl::phi_and_gradient(ReducedPotential& pot, const Eigen::VectorXd& yy,
                                         Eigen::VectorXd& rr) {
  const double dt = opt.dt_s;
  double phi = pot.value_and_gradient(yy, rr);
  tmp = yy - yhat;
  phi += 0.5 * mass.quadratic_form(tmp) / (dt * dt);
  // Its own workspace: the line search evaluates Phi between trials along the direction d.
  mass.apply(tmp, phi_work);
  rr.noalias() += phi_work / (dt * dt);
  tmp = yy - yn;
  phi += 0.5 * kd * damp.quadratic_form(tmp) / dt;
  damp.apply(tmp, phi_work);
  rr.noalias() += (kd / dt) * phi_work;
  return phi;
}

bool Simulator::Impl::factor_frozen() {
  if (frozen_ready) return true;
  space.reduce_matrix(H_rest, A);
  space.add_lumped(inertia, 1.0, A);
  detail::SparseCholesky& chol = tangent.cholesky();
  if (!chol.analyzed()) chol.analyze(A);
  frozen_ready = chol.factorize(A);
  contact_solves.clear();
  contacts_attached = false;
  if (!frozen_ready) return false;
  // The whole-disc volume term's rank-one part at rest.
  tangent.set_rank_one(
      detail::reduced_rank_one(*model, space, model->rest_positions_mm(), u_rank_one, w_rank_one),
      w_rank_one);
  base_W = tangent.low_rank_W();
  base_Z = tangent.low_rank_Z();
  return true;
}

const Eigen::MatrixXd& Simulator::Impl::contact_solve(int key) {
  auto it = contact_solves.find(key);
  if (it != contact_solves.end()) return it->second;
  // A^-1 of the reduced unit vectors of one free node (3 columns) or of the plate DOF (6).
  const Eigen::Index first = key >= 0 ? 3 * space.free_index(key) : space.plate_offset();
  const int cols = key >= 0 ? 3 : 6;
  Eigen::MatrixXd G(space.size(), cols);
  Eigen::VectorXd e(space.size());
  for (int c = 0; c < cols; ++c) {
    e.setZero();
    e(first + c) = 1.0;
    tangent.cholesky().solve_in_place(e);
    G.col(c) = e;
  }
  return contact_solves.emplace(key, std::move(G)).first->second;
}

void Simulator::Impl::prefetch_solves(const std::vector<int>& nodes) {
  std::vector<int> missing;
  for (const int i : nodes)
    if (space.role(i) == detail::NodeRole::free && !contact_solves.count(i) &&
        std::find(missing.begin(), missing.end(), i) == missing.end())
      missing.push_back(i);
  if (missing.size() < 2) return;  // one node: contact_solve does it
  Eigen::MatrixXd G = Eigen::MatrixXd::Zero(space.size(), 3 * Eigen::Index(missing.size()));
  for (std::size_t k = 0; k < missing.size(); ++k)
    for (int c = 0; c < 3; ++c)
      G(3 * space.free_index(missing[k]) + c, 3 * Eigen::Index(k) + c) = 1;
  tangent.cholesky().solve_in_place(G);
  for (std::size_t k = 0; k < missing.size(); ++k)
    contact_solves.emplace(missing[k], G.middleCols<3>(3 * Eigen::Index(k)));
}

void Simulator::Impl::add_inverse(int i, const Eigen::Vector3d& v, double scale,
                                  Eigen::Ref<Eigen::VectorXd> out) {
  if (space.role(i) == detail::NodeRole::free) {
    out.noalias() += contact_solve(i) * (scale * v);
  } else {
    const Vector6d q =
        detail::plate_map(model->rest_positions_mm().segment<3>(3 * i) - space.center())
            .transpose() *
        (scale * v);
    out.noalias() += contact_solve(-1) * q;
  }
}

double Simulator::Impl::contact_dot(const Pair& c,
                                    const Eigen::Ref<const Eigen::VectorXd>& z) const {
  const Eigen::Vector3d v = std::sqrt(c.k) * c.n;
  if (space.role(c.node) == detail::NodeRole::free)
    return v.dot(z.segment<3>(3 * space.free_index(c.node)));
  return (detail::plate_map(model->rest_positions_mm().segment<3>(3 * c.node) - space.center())
              .transpose() *
          v)
      .dot(z.tail<6>());
}

bool Simulator::Impl::contact_direction(const ExternalLoads& loads, const Eigen::VectorXd& xs) {
  // Candidate (probe, node) pairs: unknown nodes within two radii of a probe centre, with the
  // outward normal n and penetration p0 = r - |x - c| (negative: a gap) at the start.
  pairs.clear();
  for (std::size_t pi = 0; pi < loads.probes().size(); ++pi) {
    const Probe& p = loads.probes()[pi];
    for (Eigen::Index i = 0; i < model->num_nodes(); ++i) {
      const Eigen::Vector3d a = xs.segment<3>(3 * i) - p.center_mm;
      const double dist = a.norm();
      if (dist >= 2.0 * p.radius_mm || dist <= 1e-12 * p.radius_mm || !space.is_unknown(int(i)) ||
          !loads.touchable(i))
        continue;
      pairs.push_back({int(i), a / dist, p.radius_mm - dist, p.stiffness_n_per_mm, false, int(pi),
                       p.radius_mm});
    }
  }
  const auto node_step = [&](int i) -> Eigen::Vector3d {
    if (space.role(i) == detail::NodeRole::free) return d.segment<3>(3 * space.free_index(i));
    return detail::plate_map(model->rest_positions_mm().segment<3>(3 * i) - space.center()) *
           d.tail<6>();
  };
  for (Pair& c : pairs) c.active = c.p0 > 0.0;
  // Active-set loop on the quadratic model r.d + d.A d/2 + sum k/2 max(0, p0 - n.d_i)^2: with the
  // active pairs S, (A + sum_S k P^T n n^T P) d = -r - sum_{p0>0} k p0 P^T n + sum_S k p0 P^T n
  // (r holds the contact gradients -k p0 n of the pairs already inside). Stop when S settles.
  // One triangular solve per step: A^-1 (-r) here; every contact term's A^-1 image comes from the
  // cached solves of its node, and the Woodbury correction of the active contacts (and the base
  // rank-one part) uses their sparsity (3 rows, or the 6 plate DOF), so a pass costs O(n #active)
  // instead of a solve and a dense W^T Z (which took ~1 ms a step at 5,000 tets pressed).
  const Eigen::Index r0 = base_W.cols();
  // Constant over the passes: y0 = A^-1 (-r - sum_{p0>0} k p0 P^T n), one triangular solve; each
  // pair's column z = A^-1 P^T (e_i sqrt(k) n), made when the pair is first active (its
  // k p0 P^T n term is sqrt(k) p0 z).
  contact_y0 = -r;
  for (const Pair& c : pairs) {
    if (!(c.p0 > 0.0)) continue;
    const Eigen::Vector3d v = -c.k * c.p0 * c.n;
    if (space.role(c.node) == detail::NodeRole::free)
      contact_y0.segment<3>(3 * space.free_index(c.node)) += v;
    else
      contact_y0.tail<6>() +=
          detail::plate_map(model->rest_positions_mm().segment<3>(3 * c.node) - space.center())
              .transpose() *
          v;
  }
  tangent.cholesky().solve_in_place(contact_y0);
  contact_Zall.resize(contact_y0.size(), Eigen::Index(pairs.size()));
  std::vector<char> made(pairs.size(), 0);
  bool settled = false;
  std::vector<std::size_t> active;
  Eigen::MatrixXd last_S;  // I + W^T A^-1 W of the last pass (base and active contact columns)
  for (int pass = 0; pass < kActiveSetPasses && !settled; ++pass) {
    active.clear();
    for (std::size_t p = 0; p < pairs.size(); ++p)
      if (pairs[p].active) active.push_back(p);
    const Eigen::Index m = r0 + Eigen::Index(active.size());
    std::vector<int> fresh;
    for (const std::size_t p : active)
      if (!made[p]) fresh.push_back(pairs[p].node);
    prefetch_solves(fresh);
    d = contact_y0;
    for (const std::size_t p : active) {
      auto z = contact_Zall.col(Eigen::Index(p));
      if (!made[p]) {
        z.setZero();
        add_inverse(pairs[p].node, pairs[p].n, std::sqrt(pairs[p].k), z);
        made[p] = 1;
      }
      d.noalias() += (std::sqrt(pairs[p].k) * pairs[p].p0) * z;
    }
    if (m > 0) {
      // Woodbury with Z = A^-1 W: d <- y - Z (I + W^T Z)^-1 W^T y.
      const auto zcol = [&](Eigen::Index b) {
        return b < r0 ? base_Z.col(b) : contact_Zall.col(Eigen::Index(active[std::size_t(b - r0)]));
      };
      const auto wdot = [&](Eigen::Index a, const Eigen::Ref<const Eigen::VectorXd>& z) {
        return a < r0 ? base_W.col(a).dot(z) : contact_dot(pairs[active[std::size_t(a - r0)]], z);
      };
      Eigen::MatrixXd S = Eigen::MatrixXd::Identity(m, m);
      Eigen::VectorXd t(m);
      for (Eigen::Index a = 0; a < m; ++a) {
        for (Eigen::Index b = 0; b < m; ++b) S(a, b) += wdot(a, zcol(b));
        t(a) = wdot(a, d);
      }
      last_S = 0.5 * (S + S.transpose());
      t = last_S.ldlt().solve(t);
      for (Eigen::Index b = 0; b < m; ++b) d.noalias() -= t(b) * zcol(b);
    }
    settled = true;
    for (Pair& c : pairs) {
      const bool inside = c.p0 - c.n.dot(node_step(c.node)) > 0.0;
      settled = settled && inside == c.active;
      c.active = inside;
    }
  }
  contact_stiffness(active, last_S, loads.probes().size());
  return settled;
}

void Simulator::Impl::contact_stiffness(const std::vector<std::size_t>& active,
                                        const Eigen::MatrixXd& S, std::size_t probes) {
  // Moving a probe's centre by dc changes the active pairs' gaps by n.dc; the step's quadratic
  // model then answers with dd = T^-1 W N dc (T = A + G G^T the whole matrix, G = [base W,
  // contact W], N the rows sqrt(k) n^T), and the disc's force on the probe F = -sum k p n
  // changes by dF = -N^T (I - W^T T^-1 W) N dc. With Q = G^T A^-1 G (S = I + Q, the matrix of
  // the Woodbury solve), G^T T^-1 G = I - S^-1, so the probe's stiffness -dF/dc is
  // N^T [S^-1]_contacts N: k n n^T per pair on a rigid disc, 0 on a limp one. The step's
  // matrix has only the Gauss-Newton part of the contact; the force itself also turns with the
  // probe (n follows c), which adds -k p (I - n n^T) / |x - c| per pair: a frictionless sphere
  // on a node tends to slide off it, so the tangential stiffness can be negative.
  probe_K.assign(probes, Eigen::Matrix3d::Zero());
  if (active.empty()) return;
  for (const std::size_t a : active) {
    const Pair& c = pairs[a];
    const double dist = c.p0 > 0 ? c.radius - c.p0 : 0;
    if (dist > 0)
      probe_K[std::size_t(c.probe)] -=
          c.k * c.p0 / dist * (Eigen::Matrix3d::Identity() - c.n * c.n.transpose());
  }
  const Eigen::Index r0 = S.rows() - Eigen::Index(active.size());
  const Eigen::MatrixXd Sinv = S.ldlt().solve(Eigen::MatrixXd::Identity(S.rows(), S.cols()));
  for (std::size_t a = 0; a < active.size(); ++a)
    for (std::size_t b = 0; b < active.size(); ++b) {
      const Pair &pa = pairs[active[a]], &pb = pairs[active[b]];
      if (pa.probe != pb.probe) continue;
      probe_K[std::size_t(pa.probe)] += Sinv(r0 + Eigen::Index(a), r0 + Eigen::Index(b)) *
                                        std::sqrt(pa.k * pb.k) * pa.n * pb.n.transpose();
    }
}

StepReport Simulator::Impl::explicit_step(State& s, const Boundary& bc, const ExternalLoads& loads,
                                          bool symplectic) {
  const double dt = opt.dt_s;
  // a(x_n, v_n) = -M_r^-1 (r(y_n) + K_d D_r u_n), forces at the current state (old endplates).
  ReducedPotential& pot = potential;
  pot.set_loads(&loads, space.has_plate_dofs() ? bc.wrench : Vector6d::Zero());
  pot.x() = s.x_mm;
  pot.value_and_gradient(yn, r);
  damp.apply(un, d);
  r.noalias() += kd * d;  // r <- M_r a with a sign flip
  const Eigen::Index nf3 = space.plate_offset();
  tmp.head(nf3) = -r.head(nf3).cwiseQuotient(mass.diagonal.head(nf3));  // acceleration
  if (space.has_plate_dofs()) tmp.tail<6>() = -plate_mass.solve(Vector6d(r.tail<6>()));
  if (symplectic) {
    un.noalias() += dt * tmp;  // u+
    y = yn + dt * un;          // x+ = x + dt v+
  } else {
    y = yn + dt * un;          // (5.21): x+ = x + dt v (old v)
    un.noalias() += dt * tmp;  // (5.20): v+ = v + dt a
  }
  x = s.x_mm;
  space.set_dirichlet_positions(bc, x);
  space.set_unknown_positions(y, x);
  return commit(s, bc, 0);
}

StepReport Simulator::Impl::implicit_step(State& s, const Boundary& bc,
                                          const ExternalLoads& loads) {
  const double dt = opt.dt_s;
  ReducedPotential& pot = potential;
  pot.set_loads(&loads, space.has_plate_dofs() ? bc.wrench : Vector6d::Zero());
  pot.x() = s.x_mm;
  space.set_dirichlet_positions(bc, pot.x());
  yhat = yn + dt * un;
  y = yn;
  double phi = phi_and_gradient(pot, y, r);
  const double r0 = space.force_norm(r);
  const bool probes = !loads.probes().empty();
  const bool frozen = opt.matrix_update == MatrixUpdate::frozen;
  // A fixed matrix underestimates stiffening fibres far from rest (their exponential toe), and
  // a full step with it then overshoots and diverges (measured: 3 kN on a fibre-tuned L4-L5
  // disc). So a frozen step of a network with fibre elements is always line-searched.
  const bool line_search = opt.newton_iterations > 1 || (frozen && model->num_fibre_springs() > 0);
  int it = 0;
  while (it < opt.newton_iterations) {
    if (!std::isfinite(phi) || !r.allFinite())
      return {false, it, "non-finite forces in the implicit step"};
    const double rn = space.force_norm(r);
    if (rn <= floor_n || (it > 0 && rn <= opt.newton_relative_tolerance * r0)) break;
    // 1. The matrix without probe contacts: the frozen factor, or the current Hessian.
    if (frozen) {
      if (!factor_frozen())
        return {false, it, "the frozen implicit matrix is not positive definite"};
    } else {
      if (detail::factor_tangent(*model, space, ExternalLoads(), pot.x(), &inertia, 1.0, H, A,
                                 tangent) == detail::TangentKind::failed)
        return {false, it, "the implicit step matrix could not be factorised"};
      base_W = tangent.low_rank_W();
      base_Z = tangent.low_rank_Z();
      contact_solves.clear();
    }
    // 2. The Newton direction, probe contacts by the active-set loop.
    if (probes) {
      contact_direction(loads, pot.x());
      contacts_attached = true;
    } else {
      probe_K.clear();
      if (contacts_attached) tangent.set_low_rank(base_W, base_Z);
      contacts_attached = false;
      d = -r;
      tangent.solve_in_place(d);
    }
    if (!line_search) {  // Baraff-Witkin: one linearised step, no line search
      y += d;
      ++it;
      break;
    }
    // 3. Backtracking line search on Phi.
    const double slope = r.dot(d);
    bool accepted = false;
    for (double alpha = 1.0; alpha > 1e-10 && !accepted; alpha *= 0.5) {
      y_trial = y + alpha * d;
      const double phi_trial = phi_and_gradient(pot, y_trial, r_trial);
      if (!std::isfinite(phi_trial)) continue;
      accepted =
          phi_trial <= phi + 1e-4 * alpha * slope ||
          (std::abs(phi_trial - phi) <= 1e-12 * std::abs(phi) && space.force_norm(r_trial) < rn);
      if (accepted) phi = phi_trial;
    }
    if (!accepted) {
      // No decrease of Phi is measurable: converged to round-off if the residual is within a
      // few hundred ulps of the force floor (a different summation order of the forces — e.g.
      // the blocked angle-spring kernel — moves the last bits), else a genuine failure.
      if (rn <= 1e3 * floor_n) break;
      return {false, it,
              "line search failed in the implicit step (|r| = " + std::to_string(rn) + " N)"};
    }
    y.swap(y_trial);
    r.swap(r_trial);
    ++it;
  }
  un = (y - yn) / dt;
  x = pot.x();
  space.set_unknown_positions(y, x);
  return commit(s, bc, it);
}

StepReport Simulator::Impl::commit(State& s, const Boundary& bc, int iterations) {
  const double dt = opt.dt_s;
  // Velocities: unknown nodes from u+, Dirichlet nodes from their displacement.
  v = (x - s.x_mm) / dt;
  space.set_unknown_rates(un, v);
  // Divergence: a node farther from rest than the allowance plus the largest displacement of a
  // Dirichlet node (so a large rigid motion of the vertebrae is not mistaken for a blow-up).
  const Eigen::VectorXd& X = model->rest_positions_mm();
  double worst = 0, driven = 0;
  for (Eigen::Index i = 0; i < model->num_nodes(); ++i) {
    const double d2 = (x.segment<3>(3 * i) - X.segment<3>(3 * i)).squaredNorm();
    worst = std::max(worst, d2);
    if (!space.is_unknown(int(i))) driven = std::max(driven, d2);
  }
  const double limit = divergence_mm + std::sqrt(driven);
  if (!x.allFinite() || !v.allFinite() || !std::isfinite(worst))
    return {false, iterations, "step diverged: non-finite positions or velocities (state kept)"};
  if (std::sqrt(worst) > limit)
    return {false, iterations,
            "step diverged: a node moved " + std::to_string(std::sqrt(worst)) +
                " mm from rest, more than " + std::to_string(limit) +
                " mm (divergence distance + largest endplate displacement; state kept)"};
  Vector6d q;
  if (space.has_plate_dofs()) {
    q = y.tail<6>();
    s.plate_qdot = un.tail<6>();
  } else {
    q = plate_motion(bc.superior, bc.plate_center_mm);
    s.plate_qdot = (q - s.plate_q) / dt;
  }
  s.plate_q = q;
  s.x_mm.swap(x);
  s.v_mm_s.swap(v);
  s.time_s += dt;
  return {true, iterations, ""};
}

Simulator::Simulator(const MssModel& model, const DynamicsOptions& options)
    : impl_(std::make_unique<Impl>()) {
  validate_options(options);
  Impl& d = *impl_;
  d.model = &model;
  d.opt = options;
  d.kd = model.damping_n_s_per_mm();
  const Eigen::VectorXd& X = model.rest_positions_mm();
  model.rest_tangent(d.H_rest);  // fibre elements from their tension side (frozen factor)
  d.H = d.H_rest;
  d.probe_k_default = detail::default_probe_stiffness(model, d.H_rest);
  const Eigen::MatrixX3d& V = model.mesh().V;
  const double diag = (V.colwise().maxCoeff() - V.colwise().minCoeff()).norm();
  d.divergence_mm = options.divergence_distance_mm > 0 ? options.divergence_distance_mm : diag;
  d.floor_n = 100.0 * std::numeric_limits<double>::epsilon() *
              d.H_rest.diagonal().cwiseAbs().mean() * std::max(1.0, X.cwiseAbs().maxCoeff()) *
              std::sqrt(double(model.num_dofs()));
  d.x.resize(model.num_dofs());
  d.v.resize(model.num_dofs());
}

Simulator::~Simulator() = default;
Simulator::Simulator(Simulator&&) noexcept = default;
Simulator& Simulator::operator=(Simulator&&) noexcept = default;

const DynamicsOptions& Simulator::options() const { return impl_->opt; }

State Simulator::rest_state() const {
  State s;
  s.x_mm = impl_->model->rest_positions_mm();
  s.v_mm_s = Eigen::VectorXd::Zero(s.x_mm.size());
  return s;
}

StepReport Simulator::step(State& s, const Boundary& bc) {
  Impl& d = *impl_;
  const MssModel& model = *d.model;
  validate(bc, model.num_nodes());
  require(s.x_mm.size() == model.num_dofs() && s.v_mm_s.size() == model.num_dofs(),
          "mss: state vectors must have 3 x #nodes entries");
  if (!s.x_mm.allFinite() || !s.v_mm_s.allFinite() || !s.plate_q.allFinite() ||
      !s.plate_qdot.allFinite())
    return {false, 0, "state is not finite"};
  d.ensure_space(bc.plate_mode, bc.plate_center_mm);
  const ExternalLoads loads(bc, d.probe_k_default, &model.mesh().surface);
  d.space.gather(s.x_mm, s.plate_q, d.yn);
  d.space.gather(s.v_mm_s, s.plate_qdot, d.un);
  switch (d.opt.integrator) {
    case Integrator::explicit_euler:
      return d.explicit_step(s, bc, loads, false);
    case Integrator::symplectic_euler:
      return d.explicit_step(s, bc, loads, true);
    default:
      return d.implicit_step(s, bc, loads);
  }
}

Eigen::Matrix3d Simulator::probe_stiffness(int probe) const {
  const Impl& d = *impl_;
  if (probe < 0 || std::size_t(probe) >= d.probe_K.size()) return Eigen::Matrix3d::Zero();
  return d.probe_K[std::size_t(probe)];
}

bool Simulator::prepare(const Boundary& bc) {
  Impl& d = *impl_;
  validate(bc, d.model->num_nodes());
  d.ensure_space(bc.plate_mode, bc.plate_center_mm);
  if (d.opt.integrator != Integrator::implicit_euler) return true;
  return d.opt.matrix_update == MatrixUpdate::frozen ? d.factor_frozen() : true;
}

double Simulator::predicted_stable_dt_s(Integrator integrator) const {
  return detail::predicted_stable_dt(*impl_->model, impl_->H_rest, integrator);
}

}  // namespace spinesim::mss

// The pressed linear FEM disc (contact_disc.hpp).
#include "spinesim/fem/contact_disc.hpp"

#include "spinesim/fem/assembly.hpp"
#include "spinesim/fem/cholmod_solver.hpp"
#include "spinesim/fem/fe_space.hpp"
#include "spinesim/fem/fibres.hpp"

#include <Eigen/Cholesky>
#include <Eigen/LU>

#include <algorithm>
#include <cmath>
#include <set>
#include <stdexcept>
#include <unordered_map>
#include <utility>
#include <vector>

namespace spinesim::fem {

namespace {

void require(bool ok, const char* what) {
  if (!ok) throw std::invalid_argument(std::string("FEM contact disc: ") + what);
}

double mesh_volume(const mesh::TetMesh& m, const Eigen::VectorXd& x) {
  double v = 0;
  for (Eigen::Index t = 0; t < m.num_tets(); ++t) {
    const Eigen::Vector3d a = x.segment<3>(3 * m.T(t, 0));
    Eigen::Matrix3d E;
    for (int k = 1; k < 4; ++k) E.col(k - 1) = x.segment<3>(3 * m.T(t, k)) - a;
    v += E.determinant() / 6;
  }
  return v;
}

}  // namespace

struct ContactDisc::Impl {
  mesh::TetMesh mesh;
  ContactDiscOptions options;
  FreeBlockPattern pattern;
  CholmodSolver solver;
  double trace = 0, edges = 0, k_p = 0, volume0 = 0, volume_change = 0;
  std::vector<Eigen::Index> wall;  ///< free outer-wall nodes: the probe's contact candidates
  Eigen::VectorXd X, x;            ///< rest and current positions, 3 #V
  Eigen::VectorXd u_free;          ///< 3 #free
  struct Columns {
    Eigen::MatrixXd G;  ///< K_ff^-1 of the node's three unit vectors, 3 #free × 3
    std::uint64_t used = 0;
  };
  std::unordered_map<Eigen::Index, Columns> cache;
  std::uint64_t clock = 0;
  std::int64_t column_solves = 0;
  // The last equilibrium's contact: candidate nodes, their forces, the sphere's stiffness.
  std::vector<Eigen::Index> S;
  Eigen::VectorXd f_S;
  Eigen::Vector3d force = Eigen::Vector3d::Zero();
  Eigen::Matrix3d stiffness = Eigen::Matrix3d::Zero(), stiffness_gn = Eigen::Matrix3d::Zero();

  Eigen::Index dof(Eigen::Index node) const { return 3 * pattern.free_index[std::size_t(node)]; }
  /// Solves the columns of every node of S not cached (one multi-column solve), drops the least
  /// recently used beyond the cap (never a node of S). Returns how many were solved.
  int ensure_columns(const std::vector<Eigen::Index>& nodes);
  /// Gauss-Newton on Phi over S from the current positions; fills f_S, the force and stiffness.
  bool equilibrium(const Eigen::Vector3d& c, int* iterations);
  /// Penalty forces on S's nodes at u_S (3 #S) with the sphere at c; the energy. D: the
  /// penalty's Hessian blocks, Gauss-Newton's k_p n n^T, or (exact) with its curvature term
  /// -k_p (pen / dist) (I - n n^T), negative across the normal.
  double penalty(const Eigen::Vector3d& c, const Eigen::VectorXd& u_S, Eigen::VectorXd* f,
                 Eigen::MatrixXd* D, bool exact = false) const;
};

ContactDisc::ContactDisc(const mesh::TetMesh& m, const mesh::RegionMaterials& materials,
                         const ContactDiscOptions& o)
    : impl_(std::make_unique<Impl>()) {
  Impl& d = *impl_;
  require(std::isfinite(o.probe_radius_mm) && o.probe_radius_mm > 0,
          "the probe radius must be > 0 mm");
  require(std::isfinite(o.penalty_n_per_mm) && o.penalty_n_per_mm >= 0,
          "the penalty must be >= 0 N/mm (0: the default)");
  require(std::isfinite(o.margin_mm) && o.margin_mm >= 0, "the margin must be >= 0 mm");
  require(o.max_iterations >= 1 && o.relative_tolerance > 0 && o.max_cache_mb > 0,
          "bad solver options");
  mesh::require_endplate_labels(m);
  d.mesh = m;
  d.options = o;
  if (!(d.options.margin_mm > 0)) d.options.margin_mm = 0.5 * o.probe_radius_mm;
  const FeSpace space = make_fe_space(m, 1);
  std::vector<NodeRole> roles(std::size_t(m.num_vertices()), NodeRole::free);
  for (Eigen::Index i = 0; i < m.num_vertices(); ++i) {
    const int s = m.surface(i);
    if (s == int(mesh::Surface::inferior_endplate) || s == int(mesh::Surface::superior_endplate))
      roles[std::size_t(i)] = NodeRole::fixed;
    else if (s == int(mesh::Surface::outer_wall))
      d.wall.push_back(i);
  }
  d.pattern = build_free_block_pattern(space, roles, FreeNodeOrder::node);
  const ElementFibres fibres = fibre_field(m, materials);
  assemble_constrained(space, m.region, materials, roles, Eigen::Vector3d::Zero(), d.pattern,
                       fibres.empty() ? nullptr : &fibres);
  d.solver.compute(d.pattern.lower);  // throws if not positive definite
  d.trace = d.pattern.lower.diagonal().sum();
  std::set<std::pair<int, int>> edges;
  for (Eigen::Index t = 0; t < m.num_tets(); ++t)
    for (int a = 0; a < 4; ++a)
      for (int b = a + 1; b < 4; ++b)
        edges.emplace(std::min(m.T(t, a), m.T(t, b)), std::max(m.T(t, a), m.T(t, b)));
  d.edges = double(edges.size());
  d.k_p = o.penalty_n_per_mm > 0 ? o.penalty_n_per_mm : 100 * d.trace / (2 * d.edges);
  d.X.resize(3 * m.num_vertices());
  for (Eigen::Index i = 0; i < m.num_vertices(); ++i) d.X.segment<3>(3 * i) = m.V.row(i);
  d.x = d.X;
  d.u_free = Eigen::VectorXd::Zero(d.pattern.lower.rows());
  d.volume0 = mesh_volume(m, d.X);
}

ContactDisc::~ContactDisc() = default;
ContactDisc::ContactDisc(ContactDisc&&) noexcept = default;
ContactDisc& ContactDisc::operator=(ContactDisc&&) noexcept = default;

int ContactDisc::Impl::ensure_columns(const std::vector<Eigen::Index>& nodes) {
  ++clock;
  std::vector<Eigen::Index> missing;
  for (const Eigen::Index i : nodes) {
    auto it = cache.find(i);
    if (it == cache.end())
      missing.push_back(i);
    else
      it->second.used = clock;
  }
  if (missing.empty()) return 0;
  const Eigen::Index n = pattern.lower.rows();
  Eigen::MatrixXd rhs = Eigen::MatrixXd::Zero(n, 3 * Eigen::Index(missing.size()));
  for (std::size_t k = 0; k < missing.size(); ++k)
    for (int c = 0; c < 3; ++c) rhs(dof(missing[k]) + c, 3 * Eigen::Index(k) + c) = 1;
  const Eigen::MatrixXd G = solver.solve(rhs);
  // Least recently used out first, never one of `nodes` (they carry this clock).
  const double node_mb = 3.0 * double(n) * sizeof(double) / 1e6;
  const std::size_t cap =
      std::max<std::size_t>(16, std::size_t(options.max_cache_mb / std::max(node_mb, 1e-12)));
  while (cache.size() + missing.size() > cap) {
    auto oldest = cache.end();
    for (auto it = cache.begin(); it != cache.end(); ++it)
      if (it->second.used < clock &&
          (oldest == cache.end() || it->second.used < oldest->second.used))
        oldest = it;
    if (oldest == cache.end()) break;
    cache.erase(oldest);
  }
  for (std::size_t k = 0; k < missing.size(); ++k)
    cache[missing[k]] = Columns{G.middleCols(3 * Eigen::Index(k), 3), clock};
  column_solves += Eigen::Index(missing.size());
  return int(missing.size());
}

double ContactDisc::Impl::penalty(const Eigen::Vector3d& c, const Eigen::VectorXd& u_S,
                                  Eigen::VectorXd* f, Eigen::MatrixXd* D, bool exact) const {
  const double r = options.probe_radius_mm;
  double e = 0;
  if (f) f->setZero(u_S.size());
  if (D) D->setZero(u_S.size(), u_S.size());
  for (std::size_t a = 0; a < S.size(); ++a) {
    const Eigen::Index A = 3 * Eigen::Index(a);
    const Eigen::Vector3d xi = X.segment<3>(3 * S[a]) + u_S.segment<3>(A);
    const Eigen::Vector3d to_c = c - xi;
    const double dist = to_c.norm(), pen = r - dist;
    if (!(pen > 0)) continue;
    e += 0.5 * k_p * pen * pen;
    if (dist < 1e-12) continue;  // no direction to push along
    const Eigen::Vector3d n = to_c / dist;
    if (f) f->segment<3>(A) = -k_p * pen * n;
    if (D) D->block<3, 3>(A, A) = k_p * n * n.transpose();
    if (D && exact)
      D->block<3, 3>(A, A) -= k_p * pen / dist * (Eigen::Matrix3d::Identity() - n * n.transpose());
  }
  return e;
}

bool ContactDisc::Impl::equilibrium(const Eigen::Vector3d& c, int* iterations) {
  const Eigen::Index m = 3 * Eigen::Index(S.size());
  Eigen::MatrixXd W(m, m);
  for (std::size_t b = 0; b < S.size(); ++b) {
    const Eigen::MatrixXd& G = cache.at(S[b]).G;
    for (std::size_t a = 0; a < S.size(); ++a)
      W.block<3, 3>(3 * Eigen::Index(a), 3 * Eigen::Index(b)) = G.middleRows<3>(dof(S[a]));
  }
  W = 0.5 * (W + W.transpose()).eval();
  const Eigen::LLT<Eigen::MatrixXd> llt(W);
  if (llt.info() != Eigen::Success) return false;
  const Eigen::MatrixXd Winv = llt.solve(Eigen::MatrixXd::Identity(m, m));
  Eigen::VectorXd u(m), f, g, step, trial;
  for (std::size_t a = 0; a < S.size(); ++a)
    u.segment<3>(3 * Eigen::Index(a)) = x.segment<3>(3 * S[a]) - X.segment<3>(3 * S[a]);
  Eigen::MatrixXd D, H;
  auto phi = [&](const Eigen::VectorXd& v) {
    return 0.5 * v.dot(Winv * v) + penalty(c, v, nullptr, nullptr);
  };
  double e = 0.5 * u.dot(Winv * u) + penalty(c, u, &f, &D);
  bool converged = false;
  int it = 0;
  for (; it < options.max_iterations; ++it) {
    const Eigen::VectorXd Wu = Winv * u;
    g = Wu - f;
    if (g.norm() <= options.relative_tolerance * (Wu.norm() + f.norm() + 1e-12)) {
      converged = true;
      break;
    }
    H = Winv + D;
    step = -H.ldlt().solve(g);
    double alpha = 1, slope = g.dot(step);
    trial = u + step;
    double e_trial = phi(trial);
    while (e_trial > e + 1e-4 * alpha * slope && alpha > 1e-8) {
      alpha *= 0.5;
      trial = u + alpha * step;
      e_trial = phi(trial);
    }
    if (alpha * step.norm() < 1e-13 * (1 + u.norm())) {  // round-off: no descent left
      converged = true;
      break;
    }
    u = trial;
    e = 0.5 * u.dot(Winv * u) + penalty(c, u, &f, &D);
  }
  *iterations = it;
  if (!u.allFinite() || !f.allFinite()) return false;
  // The full field from the contact forces, the sphere's force and stiffness.
  u_free.setZero();
  for (std::size_t a = 0; a < S.size(); ++a)
    u_free.noalias() += cache.at(S[a]).G * f.segment<3>(3 * Eigen::Index(a));
  x = X;
  for (Eigen::Index i = 0; i < mesh.num_vertices(); ++i)
    if (pattern.free_index[std::size_t(i)] >= 0) x.segment<3>(3 * i) += u_free.segment<3>(dof(i));
  f_S = f;
  force.setZero();
  for (std::size_t a = 0; a < S.size(); ++a) force -= f.segment<3>(3 * Eigen::Index(a));
  // K_c = B^T (D - D H^-1 D) B at the solution: with the exact penalty Hessian (the second
  // derivative of the condensed energy in c: Phi_cc - Phi_cu Phi_uu^-1 Phi_uc), and with its
  // Gauss-Newton part.
  for (const bool exact : {true, false}) {
    penalty(c, u, nullptr, &D, exact);
    H = Winv + D;
    const Eigen::MatrixXd DHD = D - D * H.ldlt().solve(D);
    Eigen::Matrix3d& k = exact ? stiffness : stiffness_gn;
    k.setZero();
    for (std::size_t a = 0; a < S.size(); ++a)
      for (std::size_t b = 0; b < S.size(); ++b)
        k += DHD.block<3, 3>(3 * Eigen::Index(a), 3 * Eigen::Index(b));
    k = 0.5 * (k + k.transpose()).eval();
  }
  return converged;
}

ContactSolveReport ContactDisc::solve(const Eigen::Vector3d& c) {
  Impl& d = *impl_;
  ContactSolveReport report;
  const double r = d.options.probe_radius_mm, reach = r + d.options.margin_mm;
  // The last equilibrium, kept if this one fails.
  const Eigen::VectorXd x_before = d.x, u_before = d.u_free, f_before = d.f_S;
  const std::vector<Eigen::Index> S_before = d.S;
  const Eigen::Vector3d force_before = d.force;
  const Eigen::Matrix3d stiffness_before = d.stiffness, gn_before = d.stiffness_gn;
  // Candidates: wall nodes within reach of the centre, where the disc is now or at rest.
  std::vector<Eigen::Index> S;
  for (const Eigen::Index i : d.wall)
    if ((d.x.segment<3>(3 * i) - c).norm() < reach || (d.X.segment<3>(3 * i) - c).norm() < reach)
      S.push_back(i);
  for (int round = 0; round < 5; ++round) {
    d.S = S;
    if (S.empty()) {
      d.x = d.X, d.u_free.setZero(), d.f_S.resize(0);
      d.force.setZero(), d.stiffness.setZero(), d.stiffness_gn.setZero();
      break;
    }
    report.new_nodes += d.ensure_columns(S);
    int iterations = 0;
    report.ok = d.equilibrium(c, &iterations);
    report.iterations += iterations;
    if (!report.ok) break;
    // Wall nodes the deformed disc brought into the sphere join the candidates.
    bool grew = false;
    for (const Eigen::Index i : d.wall)
      if ((d.x.segment<3>(3 * i) - c).norm() < r && std::find(S.begin(), S.end(), i) == S.end())
        S.push_back(i), grew = true;
    if (!grew) break;
    report.ok = round < 4;  // still growing after five rounds: not an equilibrium
  }
  if (!report.ok || !d.x.allFinite()) {
    report.ok = false;
    d.x = x_before, d.u_free = u_before, d.f_S = f_before, d.S = S_before;
    d.force = force_before, d.stiffness = stiffness_before, d.stiffness_gn = gn_before;
    return report;
  }
  report.candidates = int(S.size());
  for (Eigen::Index a = 0; a < d.f_S.size() / 3; ++a)
    report.in_contact += d.f_S.segment<3>(3 * a).squaredNorm() > 0;
  d.volume_change = (mesh_volume(d.mesh, d.x) - d.volume0) / d.volume0;
  return report;
}

int ContactDisc::prefetch(const Eigen::Vector3d& c, double reach_mm, int max_nodes) {
  Impl& d = *impl_;
  std::vector<std::pair<double, Eigen::Index>> near;
  for (const Eigen::Index i : d.wall) {
    const double dist = (d.x.segment<3>(3 * i) - c).norm();
    if (dist < reach_mm && d.cache.find(i) == d.cache.end()) near.emplace_back(dist, i);
  }
  if (near.empty() || max_nodes < 1) return 0;
  const std::size_t k = std::min(near.size(), std::size_t(max_nodes));
  std::partial_sort(near.begin(), near.begin() + std::ptrdiff_t(k), near.end());
  std::vector<Eigen::Index> nodes = d.S;  // the contact's own nodes stay cached
  for (std::size_t a = 0; a < k; ++a) nodes.push_back(near[a].second);
  return d.ensure_columns(nodes);
}

const mesh::TetMesh& ContactDisc::mesh() const { return impl_->mesh; }
const Eigen::VectorXd& ContactDisc::rest_positions_mm() const { return impl_->X; }
const Eigen::VectorXd& ContactDisc::positions_mm() const { return impl_->x; }
Eigen::Vector3d ContactDisc::probe_force_n() const { return impl_->force; }
const Eigen::Matrix3d& ContactDisc::probe_stiffness() const { return impl_->stiffness; }
const Eigen::Matrix3d& ContactDisc::probe_stiffness_gauss_newton() const {
  return impl_->stiffness_gn;
}
double ContactDisc::volume_change() const { return impl_->volume_change; }
double ContactDisc::penalty_n_per_mm() const { return impl_->k_p; }
double ContactDisc::default_penalty() const { return 100 * impl_->trace / (2 * impl_->edges); }
Eigen::Index ContactDisc::num_free_dofs() const { return impl_->pattern.lower.rows(); }
std::int64_t ContactDisc::column_solves() const { return impl_->column_solves; }
std::size_t ContactDisc::cached_nodes() const { return impl_->cache.size(); }

}  // namespace spinesim::fem

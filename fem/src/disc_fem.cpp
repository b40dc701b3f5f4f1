#include "spinesim/fem/disc_fem.hpp"

#include "spinesim/common/timer.hpp"

#include "spinesim/fem/assembly.hpp"
#include "spinesim/fem/cholmod_solver.hpp"
#include "spinesim/fem/fe_space.hpp"
#include "spinesim/fem/p2_multigrid.hpp"

#include "mixed_constrained.hpp"

#include <Eigen/Cholesky>

#include <set>
#include <stdexcept>
#include <string>

namespace spinesim::fem {

namespace {

void validate_inputs(const mesh::TetMesh& m, const mesh::RegionMaterials& materials, int order,
                     const Eigen::Vector3d& c, const SolverOptions& options) {
  if (order != 1 && order != 2)
    throw std::invalid_argument("FEM order must be 1 (P1) or 2 (P2), got " + std::to_string(order));
  if (options.formulation == Formulation::mixed && order != 2)
    throw std::invalid_argument("the mixed (Taylor-Hood P2-P1) formulation needs order 2");
  if (options.formulation == Formulation::mixed && options.solver == LinearSolver::p_multigrid_cg)
    throw std::invalid_argument("the mixed formulation is solved directly, not by p-multigrid CG");
  mesh::validate(m);
  mesh::require_endplate_labels(m);
  const std::set<int> regions(m.region.data(), m.region.data() + m.region.size());
  for (int r : regions) mesh::validate(materials.at(r), "material of region " + std::to_string(r));
  for (const auto& [r, f] : materials.fibres)
    mesh::validate(f, "fibres of region " + std::to_string(r));
  if (!c.allFinite()) throw std::invalid_argument("plate centre has non-finite coordinates");
}

std::vector<NodeRole> node_roles(const Eigen::VectorXi& labels) {
  std::vector<NodeRole> roles(std::size_t(labels.size()), NodeRole::free);
  for (Eigen::Index i = 0; i < labels.size(); ++i) {
    if (labels(i) == int(mesh::Surface::inferior_endplate)) roles[std::size_t(i)] = NodeRole::fixed;
    if (labels(i) == int(mesh::Surface::superior_endplate)) roles[std::size_t(i)] = NodeRole::plate;
  }
  return roles;
}

P1ToP2Embedding p1_embedding(const FeSpace& p2, const FreeBlockPattern& fine,
                             const FreeBlockPattern& coarse) {
  P1ToP2Embedding e;
  e.num_coarse_nodes = coarse.num_free_nodes;
  e.parent.assign(std::size_t(fine.num_free_nodes), {-1, -1});
  e.weight.assign(std::size_t(fine.num_free_nodes), {0.0, 0.0});
  for (Eigen::Index i = 0; i < p2.num_nodes(); ++i) {
    const int f = fine.free_index[std::size_t(i)];
    if (f < 0) continue;
    auto& par = e.parent[std::size_t(f)];
    auto& w = e.weight[std::size_t(f)];
    if (i < p2.num_vertices) {
      par = {coarse.free_index[std::size_t(i)], -1};
      w = {1.0, 0.0};
    } else {
      const Eigen::Index edge = i - p2.num_vertices;
      par = {coarse.free_index[std::size_t(p2.edge_vertices(edge, 0))],
             coarse.free_index[std::size_t(p2.edge_vertices(edge, 1))]};
      w = {0.5, 0.5};
    }
  }
  return e;
}

}  // namespace

struct DiscFem::Impl {
  FeSpace space;
  Eigen::MatrixX4i T;
  Eigen::VectorXi region;
  ElementFibres fibres;
  bool mixed = false;
  PressureSpace pressure;  ///< mixed only
  std::vector<NodeRole> roles;
  FreeBlockPattern pattern;
  PlateCoupling coupling;
  CholmodSolver solver;
  Eigen::MatrixXd Z;  ///< 3nf×6: K_ff^-1 K_fp
  Matrix6d K6;
  Eigen::LLT<Matrix6d> K6_llt;
  double asymmetry = 0;
  Eigen::Vector3d center;
  Timings timings;

  PlateSolution solution_for(const Vector6d& q) const;
  /// Vertex pressures and the nucleus pressure from the mean stresses (MPa, tension > 0).
  void pressures_for(const Eigen::VectorXd& mean_stress, PlateSolution& s) const;
  void factorize_mixed(const mesh::TetMesh& mesh, const mesh::RegionMaterials& materials,
                       const ElementFibres* fibres);
  void factorize_displacement(const mesh::TetMesh& mesh, const mesh::RegionMaterials& materials,
                              const ElementFibres* fibres, const SolverOptions& options);
};

void DiscFem::Impl::pressures_for(const Eigen::VectorXd& p, PlateSolution& s) const {
  s.pressure_mpa.setZero(space.num_vertices);
  Eigen::VectorXd count = Eigen::VectorXd::Zero(space.num_vertices);
  for (Eigen::Index i = 0; i < pressure.size(); ++i) {
    s.pressure_mpa(pressure.vertex(i)) -= p(i);
    count(pressure.vertex(i)) += 1;
  }
  s.pressure_mpa = s.pressure_mpa.cwiseQuotient(count.cwiseMax(1.0));
  s.element_mean_stress_mpa.resize(T.rows(), 4);
  for (Eigen::Index t = 0; t < T.rows(); ++t)
    for (int a = 0; a < 4; ++a) s.element_mean_stress_mpa(t, a) = p(pressure.elements(t, a));
  double sum = 0, volume = 0;
  TetVertices X;
  for (Eigen::Index t = 0; t < T.rows(); ++t) {
    if (region(t) != int(mesh::Region::nucleus)) continue;
    for (int a = 0; a < 4; ++a) X.row(a) = space.X.row(T(t, a));
    double vol = 0;
    barycentric_gradients(X, vol);
    for (int a = 0; a < 4; ++a) sum -= 0.25 * vol * p(pressure.elements(t, a));
    volume += vol;
  }
  if (volume > 0) s.nucleus_pressure_mpa = sum / volume;
}

PlateSolution DiscFem::Impl::solution_for(const Vector6d& q) const {
  PlateSolution s;
  s.plate_motion = q;
  Eigen::VectorXd uf = Eigen::VectorXd::Zero(coupling.K_fp.rows());
  if (Z.rows() > 0) uf.noalias() = -Z * q;
  s.node_displacement_mm.setZero(space.num_nodes(), 3);
  for (Eigen::Index i = 0; i < space.num_nodes(); ++i) {
    const int f = pattern.free_index[std::size_t(i)];
    if (f >= 0)
      s.node_displacement_mm.row(i) = uf.segment<3>(3 * f).transpose();
    else if (roles[std::size_t(i)] == NodeRole::plate)
      s.node_displacement_mm.row(i) =
          (plate_map(space.X.row(i).transpose() - center) * q).transpose();
  }
  s.displacement_mm = s.node_displacement_mm.topRows(space.num_vertices);
  if (mixed) pressures_for(uf.tail(pressure.size()), s);
  // Generalised force the plate applies to the disc is K_pf u_f + K_pp q; the disc pushes back.
  s.reaction_wrench = -(coupling.K_fp.transpose() * uf + coupling.K_pp * q);
  return s;
}

DiscFem::DiscFem(const mesh::TetMesh& mesh, const mesh::RegionMaterials& materials, int order,
                 const Eigen::Vector3d& plate_center_mm, const SolverOptions& options)
    : impl_(std::make_unique<Impl>()) {
  Impl& d = *impl_;
  // 1. Validate and set up the node set, boundary roles and the K_ff sparsity.
  Timer t0;
  validate_inputs(mesh, materials, order, plate_center_mm, options);
  d.center = plate_center_mm;
  d.space = make_fe_space(mesh, order);
  d.T = mesh.T;
  d.region = mesh.region;
  d.mixed = options.formulation == Formulation::mixed;
  d.fibres = fibre_field(mesh, materials);
  d.roles = node_roles(node_surface_labels(d.space, mesh));
  d.pattern = build_free_block_pattern(d.space, d.roles);
  d.timings.setup_s = t0.seconds();
  const ElementFibres* fibres = d.fibres.empty() ? nullptr : &d.fibres;

  if (d.mixed) {
    d.factorize_mixed(mesh, materials, fibres);
  } else {
    d.factorize_displacement(mesh, materials, fibres, options);
  }
  const double norm = d.K6.norm();
  d.asymmetry = norm > 0 ? (d.K6 - d.K6.transpose()).norm() / norm : 0.0;
  d.K6 = 0.5 * (d.K6 + d.K6.transpose()).eval();
  d.K6_llt.compute(d.K6);
  if (!d.K6.allFinite() || d.K6_llt.info() != Eigen::Success || !(norm > 0))
    throw std::runtime_error("condensed 6x6 plate stiffness is not positive definite");
}

void DiscFem::Impl::factorize_mixed(const mesh::TetMesh& mesh,
                                    const mesh::RegionMaterials& materials,
                                    const ElementFibres* fibres) {
  Impl& d = *this;
  Timer t0;
  MixedConstrained sys = assemble_mixed_constrained(d.space, mesh.T, mesh.region, materials,
                                                    d.roles, d.pattern, d.center, fibres);
  d.pressure = std::move(sys.pressure);
  d.coupling = std::move(sys.coupling);
  d.timings.assembly_s = t0.seconds();
  d.K6 = d.coupling.K_pp;
  d.solver = CholmodSolver(Ordering::automatic, Factorization::ldlt);
  t0.restart();
  d.solver.analyze(sys.lower);
  d.timings.analyse_s = t0.seconds();
  t0.restart();
  d.solver.factorize(sys.lower);
  d.timings.factorise_s = t0.seconds();
  t0.restart();
  d.Z = d.solver.solve(d.coupling.K_fp);
  d.K6.noalias() -= d.coupling.K_fp.transpose() * d.Z;
  d.timings.solve_s = t0.seconds();
}

void DiscFem::Impl::factorize_displacement(const mesh::TetMesh& mesh,
                                           const mesh::RegionMaterials& materials,
                                           const ElementFibres* fibres,
                                           const SolverOptions& options) {
  Impl& d = *this;
  const int order = d.space.order;
  // 2. Assemble K_ff, K_fp, K_pp.
  Timer t0;
  d.coupling =
      assemble_constrained(d.space, mesh.region, materials, d.roles, d.center, d.pattern, fibres);
  d.timings.assembly_s = t0.seconds();

  // 3. Factorise K_ff and condense onto the plate: K6 = K_pp - K_fp^T K_ff^-1 K_fp.
  d.K6 = d.coupling.K_pp;
  const Eigen::Index nf = 3 * d.pattern.num_free_nodes;
  const bool use_cg = order == 2 && nf > 0 &&
                      (options.solver == LinearSolver::p_multigrid_cg ||
                       (options.solver == LinearSolver::automatic && nf >= options.cg_min_dofs));
  if (use_cg) {
    // P1 block on the same mesh and roles (vertex labels are the same), factorised directly.
    t0.restart();
    const FeSpace p1 = make_fe_space(mesh, 1);
    const std::vector<NodeRole> p1_roles(d.roles.begin(), d.roles.begin() + p1.num_nodes());
    FreeBlockPattern coarse = build_free_block_pattern(p1, p1_roles);
    assemble_constrained(p1, mesh.region, materials, p1_roles, d.center, coarse, fibres);
    d.timings.assembly_s += t0.seconds();
    t0.restart();
    P2MultigridCg cg(d.pattern.lower, coarse.lower, p1_embedding(d.space, d.pattern, coarse));
    d.timings.factorise_s = t0.seconds();
    t0.restart();
    d.Z = cg.solve(d.coupling.K_fp, options.cg_relative_tolerance, options.cg_max_iterations);
    d.timings.cg_iterations = cg.last_iterations();
    // Energy form: exact Z gives K_pp - K_fp^T Z; an approximate Z errs only quadratically.
    const Eigen::MatrixXd KZ = d.pattern.lower.selfadjointView<Eigen::Lower>() * d.Z;
    const Matrix6d cross = d.coupling.K_fp.transpose() * d.Z;
    d.K6 += -cross - cross.transpose() + d.Z.transpose() * KZ;
    d.timings.solve_s = t0.seconds();
  } else if (nf > 0) {
    t0.restart();
    d.solver.analyze(d.pattern.lower);
    d.timings.analyse_s = t0.seconds();
    t0.restart();
    d.solver.factorize(d.pattern.lower);
    d.timings.factorise_s = t0.seconds();
    t0.restart();
    d.Z = d.solver.solve(d.coupling.K_fp);
    d.K6.noalias() -= d.coupling.K_fp.transpose() * d.Z;
    d.timings.solve_s = t0.seconds();
  }
}

DiscFem::~DiscFem() = default;
DiscFem::DiscFem(DiscFem&&) noexcept = default;
DiscFem& DiscFem::operator=(DiscFem&&) noexcept = default;

Eigen::Vector3d DiscFem::default_plate_center(const mesh::TetMesh& mesh) {
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  Eigen::Index n = 0;
  for (Eigen::Index i = 0; i < mesh.num_vertices(); ++i)
    if (i < mesh.surface.size() && mesh.surface(i) == int(mesh::Surface::superior_endplate)) {
      sum += mesh.V.row(i).transpose();
      ++n;
    }
  if (n == 0)
    throw std::invalid_argument(
        "mesh has no superior endplate nodes (surface = 2) for the plate centre");
  return sum / double(n);
}

namespace {

/// A linear solve of finite data can still overflow (a wrench of 1e308 N): a solution that is not
/// finite is an error, never a result.
PlateSolution finite_or_refused(PlateSolution s, const char* load) {
  if (!s.plate_motion.allFinite() || !s.reaction_wrench.allFinite() ||
      !s.displacement_mm.allFinite())
    throw std::invalid_argument(std::string("the ") + load +
                                " is too large: the solution overflows double precision");
  return s;
}

}  // namespace

PlateSolution DiscFem::solve_motion(const Vector6d& motion) const {
  if (!motion.allFinite()) throw std::invalid_argument("plate motion has non-finite components");
  return finite_or_refused(impl_->solution_for(motion), "plate motion");
}

PlateSolution DiscFem::solve_wrench(const Vector6d& wrench) const {
  if (!wrench.allFinite()) throw std::invalid_argument("plate wrench has non-finite components");
  const Vector6d q = impl_->K6_llt.solve(wrench);
  return finite_or_refused(impl_->solution_for(q), "plate wrench");
}

const Matrix6d& DiscFem::stiffness_6x6() const { return impl_->K6; }
double DiscFem::stiffness_asymmetry() const { return impl_->asymmetry; }
const Eigen::Vector3d& DiscFem::plate_center() const { return impl_->center; }
int DiscFem::order() const { return impl_->space.order; }
Formulation DiscFem::formulation() const {
  return impl_->mixed ? Formulation::mixed : Formulation::displacement;
}
const ElementFibres& DiscFem::fibres() const { return impl_->fibres; }
Eigen::Index DiscFem::num_dofs() const { return impl_->coupling.K_fp.rows(); }
Eigen::Index DiscFem::num_nodes() const { return impl_->space.num_nodes(); }
const Timings& DiscFem::timings() const { return impl_->timings; }

}  // namespace spinesim::fem

#include "spinesim/fem/hyperelastic_body.hpp"

#include "spinesim/common/timer.hpp"
#include "spinesim/fem/cholmod_solver.hpp"
#include "spinesim/fem/hyperelastic_element.hpp"

#include "newton_steps.hpp"

#include <Eigen/LU>

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>
#include <utility>

namespace spinesim::fem {

namespace {

using Triplets = std::vector<Eigen::Triplet<double>>;

/// Σ over the tets of `element_at(t, X, u_e)`: energy, inverted points, nodal forces, and the
/// tangent's lower-triangle entries appended to `triplets` (with_tangent).
template <class ElementAt>
HyperelasticBody::Evaluation assemble(const FeSpace& space, const Eigen::VectorXd& u,
                                      bool with_tangent, Triplets& triplets,
                                      ElementAt&& element_at) {
  const int npe = space.nodes_per_element();
  HyperelasticBody::Evaluation out;
  out.force = Eigen::VectorXd::Zero(3 * space.num_nodes());
  if (with_tangent) triplets.reserve(std::size_t(space.elements.rows()) * 9 * npe * (npe + 1) / 2);
  Eigen::MatrixX3d ue(npe, 3);
  for (Eigen::Index t = 0; t < space.elements.rows(); ++t) {
    TetVertices X;
    for (int a = 0; a < 4; ++a) X.row(a) = space.X.row(space.elements(t, a));
    for (int a = 0; a < npe; ++a) ue.row(a) = u.segment<3>(3 * space.elements(t, a)).transpose();
    const HyperelasticElement e = element_at(t, X, ue);
    out.energy += e.energy;
    out.inverted += e.inverted_points;
    for (int a = 0; a < npe; ++a) {
      const Eigen::Index A = space.elements(t, a);
      out.force.segment<3>(3 * A) += e.force.segment<3>(3 * a);
      if (!with_tangent) continue;
      for (int b = 0; b < npe; ++b) {
        const Eigen::Index B = space.elements(t, b);
        for (int i = 0; i < 3; ++i)
          for (int j = 0; j < 3; ++j)
            if (3 * A + i >= 3 * B + j)
              triplets.emplace_back(3 * A + i, 3 * B + j, e.tangent(3 * a + i, 3 * b + j));
      }
    }
  }
  return out;
}

}  // namespace

/// The nodal-average volumetric form on P1 (hyperelastic_element.hpp, VolumetricForm): nodes
/// carry one volume per bulk modulus met around them, so that a region interface (nucleus and
/// annulus) does not average an incompressible region with a compressible one. The volumes come
/// from J = det(I + ∇u) of each tet, not from the moved vertices: differences of positions tens
/// of millimetres from the origin lose ~|X|/h of the digits of J − 1, and with a bulk modulus
/// thousands of times the shear modulus that rounding becomes a residual Newton cannot remove.
namespace detail {

class NodalVolumes {
 public:
  NodalVolumes(const FeSpace& space, const std::vector<FibreHyperelastic>& materials)
      : group_(materials.size()) {
    if (space.order != 1)
      throw std::invalid_argument("hyperelastic body: the nodal-average volume needs P1 elements");
    std::vector<double> d1s;
    for (std::size_t t = 0; t < materials.size(); ++t) {
      const auto it = std::find(d1s.begin(), d1s.end(), materials[t].d1_per_mpa);
      group_[t] = int(it - d1s.begin());
      if (it == d1s.end()) d1s.push_back(materials[t].d1_per_mpa);
    }
    groups_ = int(d1s.size());
    slots_.resize(space.elements.rows(), 4);
    gradients_.resize(materials.size());
    tet_volume_.resize(space.elements.rows());
    reference_ = Eigen::VectorXd::Zero(space.num_nodes() * groups_);
    group_material_.resize(d1s.size());
    for (std::size_t g = 0; g < d1s.size(); ++g) group_material_[g].d1_per_mpa = d1s[g];
    for (Eigen::Index t = 0; t < space.elements.rows(); ++t) {
      TetVertices X;
      for (int a = 0; a < 4; ++a) X.row(a) = space.X.row(space.elements(t, a));
      gradients_[std::size_t(t)] = barycentric_gradients(X, tet_volume_(t));
      for (int a = 0; a < 4; ++a) {
        slots_(t, a) = space.elements(t, a) * groups_ + group_[std::size_t(t)];
        reference_(slots_(t, a)) += tet_volume_(t) / 4.0;
      }
    }
  }

  /// Per tet, minus the mean of its four nodal pressures U'(v_n / V_n).
  Eigen::VectorXd element_pressures(const FeSpace& space, const Eigen::VectorXd& u) const {
    const Eigen::VectorXd v = volumes(space, u);
    Eigen::VectorXd out = Eigen::VectorXd::Zero(space.elements.rows());
    for (Eigen::Index t = 0; t < space.elements.rows(); ++t)
      for (int a = 0; a < 4; ++a) {
        const Eigen::Index k = slots_(t, a);
        out(t) -= 0.25 * volumetric_energy(v(k) / reference_(k), material(k)).first;
      }
    return out;
  }

  HyperelasticBody::Evaluation evaluate(const FeSpace& space,
                                        const std::vector<FibreHyperelastic>& materials,
                                        const Eigen::VectorXd& u, bool with_tangent) const {
    const Eigen::VectorXd v = volumes(space, u);
    // Nodal pressures p = U'(v/V), and per tet the mean of its four.
    Eigen::VectorXd p = Eigen::VectorXd::Zero(v.size());
    double volumetric_energy_mj = 0;
    for (Eigen::Index k = 0; k < v.size(); ++k) {
      if (reference_(k) == 0) continue;  // no tet of this group at this node
      const VolumetricEnergy U = volumetric_energy(v(k) / reference_(k), material(k));
      p(k) = U.first;
      volumetric_energy_mj += reference_(k) * U.value;
    }
    Triplets triplets;
    std::vector<Eigen::VectorXd> gradient(materials.size());
    HyperelasticBody::Evaluation out =
        assemble(space, u, with_tangent, triplets,
                 [&](Eigen::Index t, const TetVertices& X, const Eigen::MatrixX3d& ue) {
                   double mean = 0;
                   for (int a = 0; a < 4; ++a) mean += 0.25 * p(slots_(t, a));
                   HyperelasticElement e = hyperelastic_element_at_pressure(
                       1, X, ue, materials[std::size_t(t)], mean, with_tangent);
                   gradient[std::size_t(t)] = std::move(e.volume_gradient);
                   return e;
                 });
    out.energy += volumetric_energy_mj;
    if (with_tangent) {
      const Eigen::Index n = 3 * space.num_nodes();
      out.tangent_lower.resize(n, n);
      out.tangent_lower.setFromTriplets(triplets.begin(), triplets.end());
      if (out.inverted == 0) out.tangent_lower += volume_stiffness(space, v, gradient);
    }
    return out;
  }

 private:
  std::vector<int> group_;  ///< per tet: its bulk-modulus group
  int groups_ = 0;
  Eigen::MatrixX4i slots_;  ///< per tet and vertex: the (node, group) slot
  std::vector<Eigen::Matrix<double, 4, 3>> gradients_;
  Eigen::VectorXd tet_volume_;
  Eigen::VectorXd reference_;                      ///< V per slot
  std::vector<FibreHyperelastic> group_material_;  ///< per group: its D1 (the rest unused)

  const FibreHyperelastic& material(Eigen::Index slot) const {
    return group_material_[std::size_t(slot % groups_)];
  }

  /// A quarter of each tet's current volume V J, summed per slot.
  Eigen::VectorXd volumes(const FeSpace& space, const Eigen::VectorXd& u) const {
    Eigen::VectorXd v = Eigen::VectorXd::Zero(reference_.size());
    for (Eigen::Index t = 0; t < space.elements.rows(); ++t) {
      Eigen::Matrix3d F = Eigen::Matrix3d::Identity();
      for (int a = 0; a < 4; ++a)
        F += u.segment<3>(3 * space.elements(t, a)) * gradients_[std::size_t(t)].row(a);
      for (int a = 0; a < 4; ++a) v(slots_(t, a)) += tet_volume_(t) * F.determinant() / 4.0;
    }
    return v;
  }

  /// Σ_n U''(J_n)/V_n g_n g_nᵀ = Gᵀ diag(U''/V) G, with the rows of G the slots' volume
  /// gradients g_n = ∂v_n/∂u = Σ over the tets at n of ¼ ∂v_e/∂u; lower triangle.
  Eigen::SparseMatrix<double> volume_stiffness(const FeSpace& space, const Eigen::VectorXd& v,
                                               const std::vector<Eigen::VectorXd>& gradient) const {
    Triplets t;
    t.reserve(std::size_t(space.elements.rows()) * 48);
    for (Eigen::Index e = 0; e < space.elements.rows(); ++e)
      for (int a = 0; a < 4; ++a)
        for (int b = 0; b < 4; ++b)
          for (int i = 0; i < 3; ++i)
            t.emplace_back(slots_(e, a), 3 * space.elements(e, b) + i,
                           0.25 * gradient[std::size_t(e)](3 * b + i));
    Eigen::SparseMatrix<double> G(v.size(), 3 * space.num_nodes());
    G.setFromTriplets(t.begin(), t.end());
    Eigen::VectorXd scale = Eigen::VectorXd::Zero(v.size());
    for (Eigen::Index k = 0; k < v.size(); ++k)
      if (reference_(k) > 0)
        scale(k) = volumetric_energy(v(k) / reference_(k), material(k)).second / reference_(k);
    const Eigen::SparseMatrix<double> H = G.transpose() * scale.asDiagonal() * G;
    return H.triangularView<Eigen::Lower>();
  }
};

}  // namespace detail

HyperelasticBody::HyperelasticBody(FeSpace space, std::vector<FibreHyperelastic> element_materials,
                                   VolumetricForm form)
    : space_(std::move(space)), materials_(std::move(element_materials)), form_(form) {
  if (Eigen::Index(materials_.size()) != space_.elements.rows())
    throw std::invalid_argument("hyperelastic body: " + std::to_string(materials_.size()) +
                                " materials for " + std::to_string(space_.elements.rows()) +
                                " elements");
  for (const FibreHyperelastic& m : materials_) validate(m, "hyperelastic body");
  if (form_ == VolumetricForm::nodal_average)
    nodal_ = std::make_shared<const detail::NodalVolumes>(space_, materials_);
}

HyperelasticBody::Evaluation HyperelasticBody::evaluate(const Eigen::VectorXd& u,
                                                        bool with_tangent) const {
  const Eigen::Index n = space_.num_nodes();
  if (u.size() != 3 * n) throw std::invalid_argument("hyperelastic body: wrong displacement size");
  if (nodal_) return nodal_->evaluate(space_, materials_, u, with_tangent);
  Triplets triplets;
  Evaluation out =
      assemble(space_, u, with_tangent, triplets,
               [&](Eigen::Index t, const TetVertices& X, const Eigen::MatrixX3d& ue) {
                 return hyperelastic_element(space_.order, X, ue, materials_[std::size_t(t)],
                                             with_tangent, form_);
               });
  if (with_tangent) {
    out.tangent_lower.resize(3 * n, 3 * n);
    out.tangent_lower.setFromTriplets(triplets.begin(), triplets.end());
  }
  return out;
}

Eigen::VectorXd HyperelasticBody::element_pressures_mpa(const Eigen::VectorXd& u) const {
  if (u.size() != 3 * space_.num_nodes())
    throw std::invalid_argument("hyperelastic body: wrong displacement size");
  if (nodal_) return nodal_->element_pressures(space_, u);
  const int npe = space_.nodes_per_element();
  Eigen::VectorXd out(space_.elements.rows());
  Eigen::MatrixX3d ue(npe, 3);
  for (Eigen::Index t = 0; t < space_.elements.rows(); ++t) {
    TetVertices X;
    for (int a = 0; a < 4; ++a) X.row(a) = space_.X.row(space_.elements(t, a));
    for (int a = 0; a < npe; ++a) ue.row(a) = u.segment<3>(3 * space_.elements(t, a)).transpose();
    double volume = 0;
    barycentric_gradients(X, volume);
    const HyperelasticElement e =
        hyperelastic_element(space_.order, X, ue, materials_[std::size_t(t)], false, form_);
    out(t) = -volumetric_energy(e.volume_mm3 / volume, materials_[std::size_t(t)]).first;
  }
  return out;
}

namespace {

/// The free/prescribed split of the DOF and the blocks of a lower-triangular tangent.
struct Split {
  std::vector<Eigen::Index> free_index;  ///< per DOF: index among the free DOF, −1 if prescribed
  std::vector<Eigen::Index> free_dofs, prescribed_dofs;
  Eigen::VectorXd prescribed_values;  ///< per prescribed DOF, the full value

  Eigen::VectorXd free_part(const Eigen::VectorXd& v) const {
    Eigen::VectorXd out(Eigen::Index(free_dofs.size()));
    for (std::size_t k = 0; k < free_dofs.size(); ++k) out(Eigen::Index(k)) = v(free_dofs[k]);
    return out;
  }
  /// K_ff (lower) and K_fp d_p (d_p: a change of the prescribed DOF, full-size vector).
  Eigen::SparseMatrix<double> free_block(const Eigen::SparseMatrix<double>& lower) const {
    std::vector<Eigen::Triplet<double>> t;
    t.reserve(std::size_t(lower.nonZeros()));
    for (Eigen::Index c = 0; c < lower.outerSize(); ++c)
      for (Eigen::SparseMatrix<double>::InnerIterator it(lower, c); it; ++it) {
        const Eigen::Index fr = free_index[std::size_t(it.row())],
                           fc = free_index[std::size_t(it.col())];
        if (fr >= 0 && fc >= 0) t.emplace_back(fr, fc, it.value());
      }
    const auto nf = Eigen::Index(free_dofs.size());
    Eigen::SparseMatrix<double> K(nf, nf);
    K.setFromTriplets(t.begin(), t.end());
    return K;
  }
};

Split split_dofs(Eigen::Index num_dofs, const std::vector<PrescribedDisplacement>& prescribed) {
  Split s;
  s.free_index.assign(std::size_t(num_dofs), 0);
  std::vector<double> value(std::size_t(num_dofs), 0.0);
  for (const PrescribedDisplacement& p : prescribed) {
    if (p.node < 0 || 3 * p.node >= num_dofs || p.dof < 0 || p.dof > 2)
      throw std::invalid_argument("prescribed displacement: node " + std::to_string(p.node) +
                                  " dof " + std::to_string(p.dof) + " is not in the body");
    if (!std::isfinite(p.value_mm))
      throw std::invalid_argument("prescribed displacement: not a finite number");
    const std::size_t d = std::size_t(3 * p.node + p.dof);
    if (s.free_index[d] < 0)
      throw std::invalid_argument("prescribed displacement: node " + std::to_string(p.node) +
                                  " dof " + std::to_string(p.dof) + " given twice");
    s.free_index[d] = -1;
    value[d] = p.value_mm;
  }
  for (Eigen::Index d = 0; d < num_dofs; ++d) {
    if (s.free_index[std::size_t(d)] < 0) {
      s.prescribed_dofs.push_back(d);
      continue;
    }
    s.free_index[std::size_t(d)] = Eigen::Index(s.free_dofs.size());
    s.free_dofs.push_back(d);
  }
  s.prescribed_values.resize(Eigen::Index(s.prescribed_dofs.size()));
  for (std::size_t k = 0; k < s.prescribed_dofs.size(); ++k)
    s.prescribed_values(Eigen::Index(k)) = value[std::size_t(s.prescribed_dofs[k])];
  return s;
}

/// K d for a symmetric K stored as its lower triangle.
Eigen::VectorXd symmetric_product(const Eigen::SparseMatrix<double>& lower,
                                  const Eigen::VectorXd& d) {
  return lower * d + lower.transpose() * d - lower.diagonal().cwiseProduct(d);
}

}  // namespace

namespace {

/// One solve's Newton state: the converged displacement, the factorisation (pattern analysed
/// once) and the counts.
struct NewtonRun {
  const HyperelasticBody& body;
  const Split& split;
  const NewtonOptions& options;
  HyperelasticSolution& sol;
  Eigen::VectorXd u;  ///< the last converged state
  CholmodSolver cholesky;
  bool analysed = false;

  /// Factorises K_ff of `ev`; false when it is not positive definite.
  bool factorize(const HyperelasticBody::Evaluation& ev) {
    const Eigen::SparseMatrix<double> Kff = split.free_block(ev.tangent_lower);
    if (!analysed) cholesky.analyze(Kff), analysed = true;
    try {
      cholesky.factorize(Kff);
    } catch (const std::runtime_error&) {
      return false;
    }
    ++sol.factorisations;
    return true;
  }

  Eigen::VectorXd moved(const Eigen::VectorXd& x, const Eigen::VectorXd& step, double alpha) const {
    Eigen::VectorXd y = x;
    for (std::size_t k = 0; k < split.free_dofs.size(); ++k)
      y(split.free_dofs[k]) += alpha * step(Eigen::Index(k));
    return y;
  }

  /// The prescribed DOF set to fraction `to`, the free DOF carried along by the last tangent
  /// (halved until no element inverts); false when no such state is found.
  bool predict(double to, Eigen::VectorXd& trial) {
    trial = u;
    for (std::size_t k = 0; k < split.prescribed_dofs.size(); ++k)
      trial(split.prescribed_dofs[k]) = to * split.prescribed_values(Eigen::Index(k));
    const HyperelasticBody::Evaluation ev = body.evaluate(u, true);
    if (!factorize(ev)) return false;
    const Eigen::VectorXd du =
        cholesky.solve(-split.free_part(ev.force) -
                       split.free_part(symmetric_product(ev.tangent_lower, trial - u)));
    for (double alpha = 1.0; alpha >= 1e-6; alpha *= 0.5) {
      const Eigen::VectorXd x = moved(trial, du, alpha);
      if (body.evaluate(x, false).inverted == 0) {
        trial = x;
        return true;
      }
    }
    return false;
  }

  /// Newton iterations from `trial` with an Armijo line search on the energy; on convergence
  /// the state becomes u.
  bool correct(Eigen::VectorXd trial) {
    for (int it = 0; it < options.max_iterations; ++it) {
      const HyperelasticBody::Evaluation ev = body.evaluate(trial, true);
      ++sol.newton_iterations;
      const Eigen::VectorXd r = split.free_part(ev.force);
      double reaction = 0;
      for (const Eigen::Index d : split.prescribed_dofs) reaction += ev.force(d) * ev.force(d);
      if (!factorize(ev)) return false;
      const Eigen::VectorXd step = cholesky.solve(-r);
      sol.residual_n = r.norm();
      if (detail::increment_converged(r.norm(), std::sqrt(reaction), step.cwiseAbs().maxCoeff(),
                                      trial.cwiseAbs().maxCoeff(), options.tolerance)) {
        u = trial;
        return true;
      }
      const double slope = r.dot(step);  // dE/dα at α = 0 (< 0 for a descent direction)
      const double alpha =
          detail::backtrack({ev.energy, r.norm()}, slope, ev.energy, [&](double a) {
            const HyperelasticBody::Evaluation e = body.evaluate(moved(trial, step, a), false);
            return detail::TrialPoint{e.energy, split.free_part(e.force).norm()};
          });
      if (alpha == 0) return false;
      trial = moved(trial, step, alpha);
    }
    return false;
  }
};

}  // namespace

HyperelasticSolution HyperelasticBody::solve(const std::vector<PrescribedDisplacement>& prescribed,
                                             const NewtonOptions& options) const {
  if (options.load_increments < 1 || options.max_iterations < 1 || !(options.tolerance > 0))
    throw std::invalid_argument("Newton options: increments, iterations >= 1, tolerance > 0");
  Timer timer;
  const Eigen::Index ndof = 3 * space_.num_nodes();
  const Split split = split_dofs(ndof, prescribed);
  HyperelasticSolution sol;
  NewtonRun run{*this, split, options, sol, Eigen::VectorXd::Zero(ndof), CholmodSolver(), false};
  sol.failure = detail::ramp(options, sol, "the load", [&](double to) {
    Eigen::VectorXd trial;
    return run.predict(to, trial) && run.correct(trial);
  });
  sol.converged = sol.failure.empty();
  const Evaluation last = evaluate(run.u, false);
  sol.energy_mj = last.energy;
  sol.displacement_mm = Eigen::Map<const Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor>>(
      run.u.data(), space_.num_nodes(), 3);
  sol.reaction_n = Eigen::MatrixX3d::Zero(space_.num_nodes(), 3);
  for (const Eigen::Index d : split.prescribed_dofs) sol.reaction_n(d / 3, d % 3) = last.force(d);
  sol.seconds = timer.seconds();
  return sol;
}

}  // namespace spinesim::fem

#include "spinesim/calibration/objective.hpp"

#include <cmath>
#include <stdexcept>

namespace spinesim::calibration {

double plate_rms_radius(const mesh::TetMesh& m, const Eigen::Vector3d& c) {
  double sum = 0;
  Eigen::Index n = 0;
  for (Eigen::Index i = 0; i < m.num_vertices(); ++i)
    if (m.surface(i) == int(mesh::Surface::superior_endplate)) {
      sum += (m.V.row(i).transpose() - c).squaredNorm();
      ++n;
    }
  return n ? std::sqrt(sum / double(n)) : 1.0;
}

FemReference make_reference(const fem::DiscFem& fem, const mesh::TetMesh& mesh,
                            const std::vector<fem::LoadCase>& cases) {
  FemReference ref;
  ref.order = fem.order();
  ref.plate_center_mm = fem.plate_center();
  ref.plate_rms_radius_mm = plate_rms_radius(mesh, ref.plate_center_mm);
  ref.k6 = fem.stiffness_6x6();
  for (const fem::LoadCase& lc : cases) {
    CaseReference c;
    c.name = lc.name;
    c.wrench = fem::global_wrench(lc, mesh.frame);
    const fem::PlateSolution s = fem.solve_wrench(c.wrench);
    c.displacement_mm.resize(3 * s.displacement_mm.rows());
    for (Eigen::Index i = 0; i < s.displacement_mm.rows(); ++i)
      c.displacement_mm.segment<3>(3 * i) = s.displacement_mm.row(i).transpose();
    c.plate_motion = s.plate_motion;
    ref.cases.push_back(std::move(c));
  }
  return ref;
}

Objective::Objective(LinearMss& model, FemReference reference,
                     const std::vector<std::string>& train, Weights weights)
    : model_(model), ref_(std::move(reference)), w_(weights) {
  if (!(w_.reaction >= 0) || !(w_.stiffness >= 0) || !(w_.regularisation >= 0) ||
      !std::isfinite(w_.reaction) || !std::isfinite(w_.stiffness) ||
      !std::isfinite(w_.regularisation))
    throw std::invalid_argument("calibration: objective weights must be finite and >= 0");
  if (train.empty()) throw std::invalid_argument("calibration: no training load cases");
  for (const std::string& name : train) {
    int found = -1;
    for (std::size_t c = 0; c < ref_.cases.size(); ++c)
      if (ref_.cases[c].name == name) found = int(c);
    if (found < 0)
      throw std::invalid_argument("calibration: training case '" + name + "' has no FEM reference");
    train_.push_back(found);
  }
  for (const CaseReference& c : ref_.cases) {
    if (c.displacement_mm.size() != model_.num_dofs())
      throw std::invalid_argument("calibration: the FEM reference was computed on another mesh");
    if (c.displacement_mm.norm() <= 0)
      throw std::invalid_argument("calibration: case '" + c.name + "' has a zero FEM displacement");
  }
}

namespace {

/// S = diag(1, 1, 1, 1/rho, 1/rho, 1/rho): moments in N·mm / rho add to forces in N.
Vector6d plate_weights(const FemReference& ref) {
  Vector6d S = Vector6d::Ones();
  S.tail<3>() /= ref.plate_rms_radius_mm;
  return S;
}

/// |S K6* q*|^2, the size of a case's reference reaction.
double reaction_size2(const FemReference& ref, const CaseReference& c) {
  return plate_weights(ref).cwiseProduct(ref.k6 * c.plate_motion).squaredNorm();
}

}  // namespace

Evaluation Objective::measure(const LinearState& st, Adjoint* adjoint) const {
  Evaluation ev;
  ev.k6 = st.k6;
  const Vector6d S = plate_weights(ref_);
  const double n_train = double(train_.size());

  // Every case's errors; training cases also fill the adjoint right-hand sides and dJ_r/dK6.
  const Eigen::Index nc = Eigen::Index(ref_.cases.size());
  Eigen::MatrixXd z(model_.num_unknowns(), nc), g(model_.num_unknowns(), nc);
  g.setZero();
  Matrix6d g6_reaction = Matrix6d::Zero();
  std::vector<bool> is_train(std::size_t(nc), false);
  for (int c : train_) is_train[std::size_t(c)] = true;
  for (Eigen::Index c = 0; c < nc; ++c) {
    const CaseReference& r = ref_.cases[std::size_t(c)];
    z.col(c) = st.Z * r.wrench;
    const Eigen::VectorXd diff = model_.displacement(z.col(c)) - r.displacement_mm;
    const double u2 = r.displacement_mm.squaredNorm();
    const Vector6d d = S.cwiseProduct((st.k6 - ref_.k6) * r.plate_motion);
    const double size2 = reaction_size2(ref_, r);
    ev.cases.push_back(
        {r.name, std::sqrt(diff.squaredNorm() / u2), std::sqrt(d.squaredNorm() / size2)});
    if (is_train[std::size_t(c)]) {
      ev.displacement += diff.squaredNorm() / u2 / n_train;
      ev.reaction += d.squaredNorm() / size2 / n_train;
      g.col(c) = model_.restrict(diff) * (2.0 / (n_train * u2));
      g6_reaction +=
          (2.0 / (n_train * size2)) * S.cwiseProduct(d) * r.plate_motion.transpose();  // d|d|^2/dK6
    }
  }
  Vector6d log_ratio;
  for (int i = 0; i < 6; ++i) log_ratio(i) = std::log(st.k6(i, i) / ref_.k6(i, i));
  ev.stiffness = log_ratio.squaredNorm() / 6.0;
  ev.value = ev.displacement + w_.reaction * ev.reaction + w_.stiffness * ev.stiffness;
  if (!adjoint) return ev;

  adjoint->z = std::move(z);
  adjoint->lambda = model_.solve_again(g);
  adjoint->Phi = st.Phi;
  Matrix6d g6 = w_.reaction * g6_reaction;
  for (int i = 0; i < 6; ++i) g6(i, i) += w_.stiffness * 2.0 * log_ratio(i) / st.k6(i, i) / 6.0;
  adjoint->g6 = 0.5 * (g6 + g6.transpose());  // it meets only symmetric dK6
  return ev;
}

Evaluation Objective::evaluate(const Eigen::VectorXd& p, bool with_gradient, bool with_hessian) {
  const Eigen::Index nk = Eigen::Index(model_.knobs().size());
  if (p.size() != nk) throw std::invalid_argument("calibration: wrong number of parameters");
  const Eigen::VectorXd s = p.array().exp();
  const LinearState st = model_.solve(s);
  Adjoint adj;
  Evaluation ev = measure(st, with_gradient || with_hessian ? &adj : nullptr);
  ev.regularisation = p.squaredNorm() / double(nk);
  ev.value += w_.regularisation * ev.regularisation;
  if (!with_gradient && !with_hessian) return ev;

  // Every knob's bilinear forms: dJ/ds_j = -sum_c lambda_c^T K_j z_c + <G6, Phi^T K_j Phi>.
  const std::vector<Eigen::MatrixXd> disp =
      model_.knob_gram(adj.lambda, adj.z);                                    // nc × nc per knob
  const std::vector<Eigen::MatrixXd> dk6 = model_.knob_gram(st.Phi, st.Phi);  // 6 × 6 per knob
  ev.gradient.resize(nk);
  for (Eigen::Index j = 0; j < nk; ++j) {
    const double d_s =
        -disp[std::size_t(j)].trace() + adj.g6.cwiseProduct(dk6[std::size_t(j)]).sum();
    ev.gradient(j) = s(j) * d_s + w_.regularisation * 2.0 * p(j) / double(nk);
  }
  if (!with_hessian) return ev;

  // Gauss–Newton: rows of dr/dp stacked per residual group, then 2 sum w D^T D.
  const Vector6d S = plate_weights(ref_);
  const double n_train = double(train_.size());
  const Eigen::Index nt = Eigen::Index(train_.size());
  Eigen::MatrixXd kz(model_.num_unknowns(), nk * nt);
  for (Eigen::Index j = 0; j < nk; ++j)
    for (Eigen::Index t = 0; t < nt; ++t)
      kz.col(j * nt + t) = model_.knob_product(int(j), adj.z.col(train_[std::size_t(t)]));
  const Eigen::MatrixXd dz = model_.solve_again(kz);  // K^-1 K_j z_c = -dz_c/ds_j
  Eigen::MatrixXd gn = Eigen::MatrixXd::Zero(nk, nk);
  for (Eigen::Index t = 0; t < nt; ++t) {
    const CaseReference& r = ref_.cases[std::size_t(train_[std::size_t(t)])];
    const double scale = 1.0 / std::sqrt(r.displacement_mm.squaredNorm() * n_train);
    Eigen::MatrixXd du(model_.num_dofs(), nk);
    for (Eigen::Index j = 0; j < nk; ++j)
      du.col(j) = model_.displacement(dz.col(j * nt + t)) * (-s(j) * scale);
    gn += 2.0 * du.transpose() * du;
    Eigen::MatrixXd dr(6, nk);
    for (Eigen::Index j = 0; j < nk; ++j)
      dr.col(j) = S.cwiseProduct(dk6[std::size_t(j)] * r.plate_motion) *
                  (s(j) / std::sqrt(reaction_size2(ref_, r) * n_train));
    gn += 2.0 * w_.reaction * dr.transpose() * dr;
  }
  Eigen::MatrixXd dk(6, nk);
  for (Eigen::Index j = 0; j < nk; ++j)
    for (int i = 0; i < 6; ++i)
      dk(i, j) = s(j) * dk6[std::size_t(j)](i, i) / st.k6(i, i) / std::sqrt(6.0);
  gn += 2.0 * w_.stiffness * dk.transpose() * dk;
  gn.diagonal().array() += 2.0 * w_.regularisation / double(nk);
  ev.gauss_newton = gn;
  return ev;
}

}  // namespace spinesim::calibration

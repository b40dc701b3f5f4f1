#include "spinesim/calibration/linear_mss.hpp"

#include "spinesim/fem/cholmod_solver.hpp"

#include <Eigen/LU>

#include <stdexcept>
#include <string>

namespace spinesim::calibration {

namespace {

const char* term_name(mss::Term t) {
  switch (t) {
    case mss::Term::main: return "main";
    case mss::Term::radial: return "radial";
    case mss::Term::torsion: return "torsion";
    case mss::Term::volume: return "volume";
    case mss::Term::disc_volume: return "disc_volume";
  }
  return "?";
}

bool term_on(const mss::MssOptions& o, mss::Term t) {
  switch (t) {
    case mss::Term::main: return true;
    case mss::Term::radial: return o.radial_springs;
    case mss::Term::torsion: return o.torsion_springs;
    case mss::Term::volume: return o.volume_term;
    case mss::Term::disc_volume: return o.disc_volume_term;
  }
  return false;
}

}  // namespace

std::string knob_name(const Knob& k) {
  if (k.term == mss::Term::disc_volume) return "disc_volume";
  return std::string(term_name(k.term)) + (k.region == 0 ? ".annulus" : ".nucleus");
}

Knob knob_from_name(const std::string& name) {
  for (int t = 0; t < mss::kNumTerms; ++t)
    for (int r = 0; r < 2; ++r) {
      const Knob k{static_cast<mss::Term>(t), r};
      if (k.term == mss::Term::disc_volume && r == 1) continue;
      if (knob_name(k) == name) return k;
    }
  throw std::invalid_argument("unknown stiffness knob '" + name +
                              "' (main|radial|torsion|volume .annulus|.nucleus, disc_volume)");
}

std::vector<Knob> available_knobs(const mss::MssOptions& o) {
  std::vector<Knob> out;
  for (int t = 0; t < mss::kNumTerms; ++t) {
    const auto term = static_cast<mss::Term>(t);
    if (!term_on(o, term)) continue;
    out.push_back({term, 0});
    if (term != mss::Term::disc_volume) out.push_back({term, 1});
  }
  return out;
}

struct LinearMss::Impl {
  std::vector<Knob> knobs;
  Eigen::Index ndof = 0, nz = 0;
  Eigen::SparseMatrix<double> R;                // ndof × nz
  std::vector<Eigen::SparseMatrix<double>> K;   // per knob, on one shared pattern
  int rank_one_knob = -1;                       // knob index of disc_volume, or -1
  Eigen::VectorXd u_red;                        // R^T dV/dx (nz)
  double kg_unscaled = 0;                       // k_g at scale 1, N/mm^5
  Eigen::SparseMatrix<double> assembled;        // K(s) on the shared pattern
  fem::CholmodSolver cholesky;
  bool analysed = false;
  // Sherman–Morrison for the rank-one part: K_total^-1 b = A^-1 b - a_u (k u.A^-1 b)/(1 + k u.a_u).
  double kg = 0;
  Eigen::VectorXd a_u;

  Eigen::MatrixXd solve(const Eigen::MatrixXd& b) const {
    Eigen::MatrixXd x = cholesky.solve(b);
    if (kg != 0.0) {
      const double denom = 1.0 + kg * u_red.dot(a_u);
      x -= a_u * ((kg / denom) * (u_red.transpose() * x));
    }
    return x;
  }
};

LinearMss::LinearMss(const mss::MssModel& model, std::vector<Knob> knobs, const Eigen::Vector3d& c)
    : impl_(std::make_unique<Impl>()) {
  Impl& m = *impl_;
  const mesh::TetMesh& mesh = model.mesh();
  const Eigen::VectorXd& X = model.rest_positions_mm();
  if (knobs.empty()) throw std::invalid_argument("calibration: no stiffness knobs to tune");
  for (const Knob& k : knobs)
    if (!term_on(model.options(), k.term))
      throw std::invalid_argument("calibration: knob " + knob_name(k) + " belongs to a term that is switched off");
  m.knobs = std::move(knobs);
  m.ndof = model.num_dofs();

  // R: free DOF are the identity, plate DOF follow the rigid map, fixed DOF are zero.
  std::vector<Eigen::Triplet<double>> r;
  Eigen::Index nf = 0, n_sup = 0, n_inf = 0;
  std::vector<Eigen::Index> plate_nodes;
  for (Eigen::Index i = 0; i < mesh.num_vertices(); ++i) {
    const int s = mesh.surface(i);
    if (s == int(mesh::Surface::superior_endplate)) plate_nodes.push_back(i), ++n_sup;
    else if (s == int(mesh::Surface::inferior_endplate)) ++n_inf;
    else
      for (int a = 0; a < 3; ++a) r.emplace_back(3 * i + a, nf++, 1.0);
  }
  if (n_sup == 0 || n_inf == 0)
    throw std::invalid_argument("calibration: the mesh needs superior (2) and inferior (1) endplate labels");
  m.nz = nf + 6;
  for (Eigen::Index i : plate_nodes) {
    const Eigen::Vector3d d = X.segment<3>(3 * i) - c;
    // u = t + theta x d:  row a of [I, -[d]x].
    for (int a = 0; a < 3; ++a) r.emplace_back(3 * i + a, nf + a, 1.0);
    r.emplace_back(3 * i + 0, nf + 4, d.z()), r.emplace_back(3 * i + 0, nf + 5, -d.y());
    r.emplace_back(3 * i + 1, nf + 3, -d.z()), r.emplace_back(3 * i + 1, nf + 5, d.x());
    r.emplace_back(3 * i + 2, nf + 3, d.y()), r.emplace_back(3 * i + 2, nf + 4, -d.x());
  }
  m.R.resize(m.ndof, m.nz);
  m.R.setFromTriplets(r.begin(), r.end());

  // K_j = R^T H_j R, then all of them on the union pattern so K(s) is a sum of value arrays.
  Eigen::SparseMatrix<double> H;
  const Eigen::SparseMatrix<double> Rt = m.R.transpose();
  for (std::size_t j = 0; j < m.knobs.size(); ++j) {
    const Knob& k = m.knobs[j];
    model.term_hessian(X, k.term, k.region, mss::HessianMode::exact, H);
    m.K.push_back(Eigen::SparseMatrix<double>(Rt * H * m.R));
    if (k.term == mss::Term::disc_volume) {
      Eigen::VectorXd u;
      const double kg_scaled = model.disc_volume_rank_one(X, u);
      const double scale = model.options().scales[int(mss::Term::disc_volume)].by_region[0];
      m.kg_unscaled = kg_scaled / scale;
      m.u_red = Rt * u;
      m.rank_one_knob = int(j);
    }
  }
  Eigen::SparseMatrix<double> pattern = m.K[0];
  for (std::size_t j = 1; j < m.K.size(); ++j) pattern = pattern + m.K[j];
  pattern.makeCompressed();
  for (auto& Kj : m.K) {
    Kj = Eigen::SparseMatrix<double>(0.0 * pattern + Kj);
    Kj.makeCompressed();
    if (Kj.nonZeros() != pattern.nonZeros())
      throw std::logic_error("calibration: knob Hessians do not share one pattern");
  }
  m.assembled = pattern;
}

LinearMss::~LinearMss() = default;
LinearMss::LinearMss(LinearMss&&) noexcept = default;
LinearMss& LinearMss::operator=(LinearMss&&) noexcept = default;

const std::vector<Knob>& LinearMss::knobs() const { return impl_->knobs; }
Eigen::Index LinearMss::num_unknowns() const { return impl_->nz; }
Eigen::Index LinearMss::num_dofs() const { return impl_->ndof; }

LinearState LinearMss::solve(const Eigen::VectorXd& s) {
  Impl& m = *impl_;
  if (s.size() != Eigen::Index(m.knobs.size()))
    throw std::invalid_argument("calibration: " + std::to_string(s.size()) + " scales for " +
                                std::to_string(m.knobs.size()) + " knobs");
  if (!s.allFinite() || (s.array() <= 0).any())
    throw std::invalid_argument("calibration: stiffness scales must be finite and > 0");
  const Eigen::Index nnz = m.assembled.nonZeros();
  double* v = m.assembled.valuePtr();
  std::fill(v, v + nnz, 0.0);
  for (std::size_t j = 0; j < m.knobs.size(); ++j) {
    const double* kj = m.K[j].valuePtr();
    const double sj = s(Eigen::Index(j));
    for (Eigen::Index e = 0; e < nnz; ++e) v[e] += sj * kj[e];
  }
  if (!m.analysed) {
    m.cholesky.analyze(m.assembled);
    m.analysed = true;
  }
  m.cholesky.factorize(m.assembled);  // throws std::runtime_error if not positive definite
  m.kg = m.rank_one_knob >= 0 ? s(m.rank_one_knob) * m.kg_unscaled : 0.0;
  if (m.kg != 0.0) m.a_u = m.cholesky.solve(m.u_red);

  LinearState out;
  Eigen::MatrixXd Ep = Eigen::MatrixXd::Zero(m.nz, 6);
  Ep.bottomRows<6>().setIdentity();
  out.Z = m.solve(Ep);
  const Matrix6d C = 0.5 * (out.Z.bottomRows<6>() + out.Z.bottomRows<6>().transpose());
  out.k6 = C.inverse();
  out.k6 = 0.5 * (out.k6 + out.k6.transpose()).eval();
  out.Phi = out.Z * out.k6;
  if (!out.k6.allFinite()) throw std::runtime_error("calibration: non-finite plate stiffness");
  return out;
}

Eigen::MatrixXd LinearMss::solve_again(const Eigen::MatrixXd& rhs) const { return impl_->solve(rhs); }

Eigen::VectorXd LinearMss::displacement(const Eigen::VectorXd& z) const { return impl_->R * z; }
Eigen::VectorXd LinearMss::restrict(const Eigen::VectorXd& v) const { return impl_->R.transpose() * v; }

std::vector<Eigen::MatrixXd> LinearMss::knob_gram(const Eigen::MatrixXd& A, const Eigen::MatrixXd& B) const {
  const Impl& m = *impl_;
  std::vector<Eigen::MatrixXd> out(m.knobs.size());
  for (std::size_t j = 0; j < m.knobs.size(); ++j) {
    if (int(j) == m.rank_one_knob)
      out[j] = m.kg_unscaled * (A.transpose() * m.u_red) * (m.u_red.transpose() * B);
    else
      out[j] = A.transpose() * (m.K[j] * B);
  }
  return out;
}

Eigen::VectorXd LinearMss::knob_product(int j, const Eigen::VectorXd& b) const {
  const Impl& m = *impl_;
  Eigen::VectorXd y = m.K[std::size_t(j)] * b;
  if (j == m.rank_one_knob) y += m.kg_unscaled * m.u_red.dot(b) * m.u_red;
  return y;
}

}  // namespace spinesim::calibration

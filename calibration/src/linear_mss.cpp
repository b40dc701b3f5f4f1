#include "spinesim/calibration/linear_mss.hpp"

#include "spinesim/fem/cholmod_solver.hpp"
#include "spinesim/mesh/rigid_plate.hpp"

#include <Eigen/LU>

#include <algorithm>
#include <stdexcept>
#include <string>

namespace spinesim::calibration {

namespace {

const char* term_name(mss::Term t) {
  switch (t) {
    case mss::Term::main:
      return "main";
    case mss::Term::radial:
      return "radial";
    case mss::Term::torsion:
      return "torsion";
    case mss::Term::volume:
      return "volume";
    case mss::Term::disc_volume:
      return "disc_volume";
    case mss::Term::fibre:
      return "fibre";
  }
  return "?";
}

/// Terms with one knob (region index 0): the whole-disc volume and the annulus's fibres.
bool single_knob(mss::Term t) { return t == mss::Term::disc_volume || t == mss::Term::fibre; }

}  // namespace

std::string knob_name(const Knob& k) {
  if (single_knob(k.term)) return term_name(k.term);
  return std::string(term_name(k.term)) + (k.region == 0 ? ".annulus" : ".nucleus");
}

Knob knob_from_name(const std::string& name) {
  for (int t = 0; t < mss::kNumTerms; ++t)
    for (int r = 0; r < 2; ++r) {
      const Knob k{static_cast<mss::Term>(t), r};
      if (single_knob(k.term) && r == 1) continue;
      if (knob_name(k) == name) return k;
    }
  throw std::invalid_argument(
      "unknown stiffness knob '" + name +
      "' (main|radial|torsion|volume .annulus|.nucleus, disc_volume, fibre)");
}

std::vector<Knob> available_knobs(const mss::MssOptions& o) {
  std::vector<Knob> out;
  for (int t = 0; t < mss::kNumTerms; ++t) {
    const auto term = static_cast<mss::Term>(t);
    if (!mss::term_enabled(o, term)) continue;
    out.push_back({term, 0});
    if (!single_knob(term)) out.push_back({term, 1});
  }
  return out;
}

struct LinearMss::Impl {
  std::vector<Knob> knobs;
  Eigen::Index ndof = 0, nz = 0;
  Eigen::SparseMatrix<double> R;               // ndof × nz
  std::vector<Eigen::SparseMatrix<double>> K;  // per knob, on one shared pattern
  int rank_one_knob = -1;                      // knob index of disc_volume, or -1
  Eigen::VectorXd u_red;                       // R^T dV/dx (nz)
  double kg_unscaled = 0;                      // k_g at scale 1, N/mm^5
  Eigen::SparseMatrix<double> assembled;       // K(s) on the shared pattern
  fem::CholmodSolver cholesky;
  bool analysed = false;
  // Sherman–Morrison for the rank-one part: K_total^-1 b = A^-1 b - a_u (k u.A^-1 b)/(1 + k u.a_u).
  double kg = 0;
  Eigen::VectorXd a_u;

  // Per-spring mode: every edge spring's data, and (built on first use) the entries of its
  // k_e r_e r_e^T in `assembled`: edge e owns entries [entry_begin[e], entry_begin[e + 1]).
  struct Edge {
    int i, j;
    Eigen::Vector3d n;  // unit rest direction i -> j
    double k_part[2];   // N/mm, unscaled
    double mu_model;    // the multiplier baked into the main knobs' K_j
  };
  std::vector<Edge> edges;
  int main_knob[2] = {-1, -1};
  std::vector<std::size_t> entry_begin;
  std::vector<Eigen::Index> entry_slot;
  std::vector<double> entry_coeff;

  void check_scales(const Eigen::VectorXd& s) const;
  void require_main_knobs() const {
    if (main_knob[0] < 0 || main_knob[1] < 0)
      throw std::invalid_argument(
          "calibration: per-spring multipliers need both main-spring knobs");
  }
  /// assembled = sum_j s_j K_j (values only).
  void assemble(const Eigen::VectorXd& s);
  /// Adds sum_e (mu_e - mu_model,e) k_e(s) r_e r_e^T to `assembled`.
  void add_edge_multipliers(const Eigen::VectorXd& s, const Eigen::VectorXd& mu);
  void build_edge_entries();
  /// Factorises `assembled` (+ the rank-one part at s) and returns Z, K6, Phi.
  LinearState factorise_and_respond(const Eigen::VectorXd& s);

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
  // A fibre element at rest sits at its tension-only kink: its Hessian there is zero, and a
  // linear response would silently leave the fibres out (a disc far too soft).
  if (model.num_fibre_springs() > 0)
    throw std::invalid_argument(
        "calibration: the network has fibre elements, which have no stiffness at rest "
        "(tension only): it has no linear response at rest; use its nonlinear responses");
  for (const Knob& k : knobs)
    if (!mss::term_enabled(model.options(), k.term))
      throw std::invalid_argument("calibration: knob " + knob_name(k) +
                                  " belongs to a term that is switched off");
  m.knobs = std::move(knobs);
  m.ndof = model.num_dofs();

  // R: free DOF are the identity, plate DOF follow the rigid map, fixed DOF are zero.
  std::vector<Eigen::Triplet<double>> r;
  Eigen::Index nf = 0, n_sup = 0, n_inf = 0;
  std::vector<Eigen::Index> plate_nodes;
  for (Eigen::Index i = 0; i < mesh.num_vertices(); ++i) {
    const int s = mesh.surface(i);
    if (s == int(mesh::Surface::superior_endplate))
      plate_nodes.push_back(i), ++n_sup;
    else if (s == int(mesh::Surface::inferior_endplate))
      ++n_inf;
    else
      for (int a = 0; a < 3; ++a) r.emplace_back(3 * i + a, nf++, 1.0);
  }
  if (n_sup == 0 || n_inf == 0)
    throw std::invalid_argument(
        "calibration: the mesh needs superior (2) and inferior (1) endplate labels");
  m.nz = nf + 6;
  for (Eigen::Index i : plate_nodes) {
    // u = t + theta x (X - c): the entries of mesh::plate_map that are not structurally zero
    // (an arm component that happens to be 0 keeps its slot, so the pattern is the mesh's).
    const mesh::PlateMap P = mesh::plate_map(X.segment<3>(3 * i) - c);
    for (int a = 0; a < 3; ++a)
      for (int b = 0; b < 6; ++b)
        if (b == a || (b >= 3 && b - 3 != a)) r.emplace_back(3 * i + a, nf + b, P(a, b));
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

  // Edge springs, for per-spring multipliers.
  for (const mss::EdgeSpringInfo& e : model.edge_springs()) {
    const Eigen::Vector3d d = X.segment<3>(3 * e.j) - X.segment<3>(3 * e.i);
    m.edges.push_back({e.i, e.j, d / d.norm(), {e.k_part[0], e.k_part[1]}, e.multiplier});
  }
  for (std::size_t j = 0; j < m.knobs.size(); ++j)
    if (m.knobs[j].term == mss::Term::main) m.main_knob[m.knobs[j].region] = int(j);
}

void LinearMss::Impl::build_edge_entries() {
  const Eigen::SparseMatrix<double, Eigen::RowMajor> Rr = R;
  const auto* outer = assembled.outerIndexPtr();
  const auto* inner = assembled.innerIndexPtr();
  entry_begin.assign(1, 0);
  std::vector<std::pair<Eigen::Index, double>> r;  // r_e = R^T b_e, sparse
  for (const Edge& e : edges) {
    r.clear();
    for (int end = 0; end < 2; ++end)
      for (int a = 0; a < 3; ++a) {
        const double b = (end == 0 ? -1.0 : 1.0) * e.n(a);
        for (Eigen::SparseMatrix<double, Eigen::RowMajor>::InnerIterator it(
                 Rr, 3 * (end == 0 ? e.i : e.j) + a);
             it; ++it)
          r.emplace_back(it.col(), b * it.value());
      }
    std::sort(r.begin(), r.end());
    std::size_t w = 0;  // merge repeated z indices (both ends on the plate)
    for (std::size_t k = 0; k < r.size(); ++k)
      if (w > 0 && r[w - 1].first == r[k].first)
        r[w - 1].second += r[k].second;
      else
        r[w++] = r[k];
    r.resize(w);
    for (const auto& [col, vc] : r)
      for (const auto& [row, vr] : r) {
        if (vr * vc == 0.0) continue;
        const auto* first = inner + outer[col];
        const auto* last = inner + outer[col + 1];
        const auto* hit = std::lower_bound(first, last, row);
        if (hit == last || *hit != row)
          throw std::logic_error(
              "calibration: an edge spring's entry is missing from the stiffness pattern");
        entry_slot.push_back(hit - inner);
        entry_coeff.push_back(vr * vc);
      }
    entry_begin.push_back(entry_slot.size());
  }
}

LinearMss::~LinearMss() = default;
LinearMss::LinearMss(LinearMss&&) noexcept = default;
LinearMss& LinearMss::operator=(LinearMss&&) noexcept = default;

const std::vector<Knob>& LinearMss::knobs() const { return impl_->knobs; }
Eigen::Index LinearMss::num_unknowns() const { return impl_->nz; }
Eigen::Index LinearMss::num_dofs() const { return impl_->ndof; }

void LinearMss::Impl::check_scales(const Eigen::VectorXd& s) const {
  if (s.size() != Eigen::Index(knobs.size()))
    throw std::invalid_argument("calibration: " + std::to_string(s.size()) + " scales for " +
                                std::to_string(knobs.size()) + " knobs");
  if (!s.allFinite() || (s.array() <= 0).any())
    throw std::invalid_argument("calibration: stiffness scales must be finite and > 0");
}

void LinearMss::Impl::assemble(const Eigen::VectorXd& s) {
  const Eigen::Index nnz = assembled.nonZeros();
  double* v = assembled.valuePtr();
  std::fill(v, v + nnz, 0.0);
  for (std::size_t j = 0; j < knobs.size(); ++j) {
    const double* kj = K[j].valuePtr();
    const double sj = s(Eigen::Index(j));
    for (Eigen::Index e = 0; e < nnz; ++e) v[e] += sj * kj[e];
  }
}

void LinearMss::Impl::add_edge_multipliers(const Eigen::VectorXd& s, const Eigen::VectorXd& mu) {
  if (entry_begin.empty()) build_edge_entries();
  const double sa = s(main_knob[0]), sn = s(main_knob[1]);
  double* v = assembled.valuePtr();
  for (std::size_t e = 0; e < edges.size(); ++e) {
    const Edge& ed = edges[e];
    const double d = (mu(Eigen::Index(e)) - ed.mu_model) * (sa * ed.k_part[0] + sn * ed.k_part[1]);
    if (d == 0.0) continue;
    for (std::size_t k = entry_begin[e]; k < entry_begin[e + 1]; ++k)
      v[entry_slot[k]] += d * entry_coeff[k];
  }
}

LinearState LinearMss::Impl::factorise_and_respond(const Eigen::VectorXd& s) {
  if (!analysed) {
    cholesky.analyze(assembled);
    analysed = true;
  }
  cholesky.factorize(assembled);  // throws std::runtime_error if not positive definite
  kg = rank_one_knob >= 0 ? s(rank_one_knob) * kg_unscaled : 0.0;
  if (kg != 0.0) a_u = cholesky.solve(u_red);

  LinearState out;
  Eigen::MatrixXd Ep = Eigen::MatrixXd::Zero(nz, 6);
  Ep.bottomRows<6>().setIdentity();
  out.Z = solve(Ep);
  const Matrix6d C = 0.5 * (out.Z.bottomRows<6>() + out.Z.bottomRows<6>().transpose());
  out.k6 = C.inverse();
  out.k6 = 0.5 * (out.k6 + out.k6.transpose()).eval();
  out.Phi = out.Z * out.k6;
  if (!out.k6.allFinite()) throw std::runtime_error("calibration: non-finite plate stiffness");
  return out;
}

LinearState LinearMss::solve(const Eigen::VectorXd& s) {
  impl_->check_scales(s);
  impl_->assemble(s);
  return impl_->factorise_and_respond(s);
}

LinearState LinearMss::solve(const Eigen::VectorXd& s, const Eigen::VectorXd& mu) {
  Impl& m = *impl_;
  m.check_scales(s);
  m.require_main_knobs();
  if (mu.size() != Eigen::Index(m.edges.size()))
    throw std::invalid_argument("calibration: " + std::to_string(mu.size()) +
                                " edge multipliers for " + std::to_string(m.edges.size()) +
                                " edge springs");
  if (!mu.allFinite() || (mu.array() <= 0).any())
    throw std::invalid_argument("calibration: edge multipliers must be finite and > 0");
  m.assemble(s);
  m.add_edge_multipliers(s, mu);
  return m.factorise_and_respond(s);
}

Eigen::Index LinearMss::num_edge_springs() const { return Eigen::Index(impl_->edges.size()); }

Eigen::VectorXd LinearMss::edge_stiffness(const Eigen::VectorXd& s) const {
  const Impl& m = *impl_;
  m.check_scales(s);
  m.require_main_knobs();
  const double sa = s(m.main_knob[0]), sn = s(m.main_knob[1]);
  Eigen::VectorXd k(Eigen::Index(m.edges.size()));
  for (std::size_t e = 0; e < m.edges.size(); ++e)
    k(Eigen::Index(e)) = sa * m.edges[e].k_part[0] + sn * m.edges[e].k_part[1];
  return k;
}

Eigen::MatrixXd LinearMss::edge_extensions(const Eigen::MatrixXd& A) const {
  const Impl& m = *impl_;
  const Eigen::MatrixXd U = m.R * A;  // 3#nodes × k
  Eigen::MatrixXd out(Eigen::Index(m.edges.size()), A.cols());
  for (std::size_t e = 0; e < m.edges.size(); ++e) {
    const Impl::Edge& ed = m.edges[e];
    out.row(Eigen::Index(e)) =
        ed.n.transpose() * (U.middleRows<3>(3 * ed.j) - U.middleRows<3>(3 * ed.i));
  }
  return out;
}

Eigen::MatrixXd LinearMss::solve_again(const Eigen::MatrixXd& rhs) const {
  return impl_->solve(rhs);
}

Eigen::VectorXd LinearMss::displacement(const Eigen::VectorXd& z) const { return impl_->R * z; }
Eigen::VectorXd LinearMss::restrict(const Eigen::VectorXd& v) const {
  return impl_->R.transpose() * v;
}

std::vector<Eigen::MatrixXd> LinearMss::knob_gram(const Eigen::MatrixXd& A,
                                                  const Eigen::MatrixXd& B) const {
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

#include "sparse_cholesky.hpp"

#include <Eigen/CholmodSupport>
#include <Eigen/SparseCholesky>

#include <cstring>
#include <stdexcept>

namespace spinesim::mss::detail {

// The backend for the MSS step: the two CHOLMOD solves are alike per step and Eigen's is
// slower; supernodal CHOLMOD factorises fastest, which the refreshed matrix and the frozen
// refactorisation on a probe-contact change need. Hence supernodal (measured by
// bench/bench_mss_cholesky; docs/benchmarks.md, "Cholesky backends").
CholeskyBackend default_cholesky_backend() { return CholeskyBackend::cholmod_supernodal; }

struct SparseCholesky::Impl {
  CholeskyBackend backend;
  Eigen::Index n = 0;
  bool analyzed = false, factorized = false;
  // CHOLMOD
  cholmod_common common;
  cholmod_factor* L = nullptr;
  cholmod_dense* X = nullptr;
  cholmod_dense* Y = nullptr;
  cholmod_dense* E = nullptr;
  // Eigen
  Eigen::SimplicialLLT<Eigen::SparseMatrix<double>, Eigen::Lower, Eigen::AMDOrdering<int>> llt;
  Eigen::VectorXd tmp;

  explicit Impl(CholeskyBackend b) : backend(b) {
    cholmod_start(&common);
    common.print = 0;  // failures are reported by return values, not on stderr
    common.supernodal =
        b == CholeskyBackend::cholmod_supernodal ? CHOLMOD_SUPERNODAL : CHOLMOD_SIMPLICIAL;
    common.final_ll = 1;
  }
  ~Impl() {
    if (L) cholmod_free_factor(&L, &common);
    if (X) cholmod_free_dense(&X, &common);
    if (Y) cholmod_free_dense(&Y, &common);
    if (E) cholmod_free_dense(&E, &common);
    cholmod_finish(&common);
  }
  Impl(const Impl&) = delete;
  Impl& operator=(const Impl&) = delete;

  bool cholmod() const { return backend != CholeskyBackend::eigen_simplicial; }
  cholmod_sparse view(const Eigen::SparseMatrix<double>& A) {
    cholmod_sparse s = Eigen::viewAsCholmod(
        Eigen::Ref<Eigen::SparseMatrix<double>>(const_cast<Eigen::SparseMatrix<double>&>(A)));
    s.stype = -1;  // lower triangle stored
    return s;
  }
};

SparseCholesky::SparseCholesky(CholeskyBackend backend) : impl_(std::make_unique<Impl>(backend)) {}
SparseCholesky::~SparseCholesky() = default;
SparseCholesky::SparseCholesky(SparseCholesky&&) noexcept = default;
SparseCholesky& SparseCholesky::operator=(SparseCholesky&&) noexcept = default;

void SparseCholesky::analyze(const Eigen::SparseMatrix<double>& A) {
  Impl& d = *impl_;
  if (A.rows() != A.cols() || A.rows() == 0)
    throw std::invalid_argument("mss: sparse Cholesky needs a non-empty square matrix");
  d.n = A.rows();
  d.analyzed = d.factorized = false;
  if (d.cholmod()) {
    if (d.L) cholmod_free_factor(&d.L, &d.common);
    cholmod_sparse s = d.view(A);
    d.L = cholmod_analyze(&s, &d.common);
    if (!d.L) throw std::runtime_error("mss: CHOLMOD symbolic analysis failed (out of memory?)");
  } else {
    d.llt.analyzePattern(A);
    d.tmp.resize(d.n);
  }
  d.analyzed = true;
}

bool SparseCholesky::analyzed() const { return impl_->analyzed; }
bool SparseCholesky::factorized() const { return impl_->factorized; }

bool SparseCholesky::factorize(const Eigen::SparseMatrix<double>& A) {
  Impl& d = *impl_;
  if (!d.analyzed || A.rows() != d.n) throw std::logic_error("mss: factorize() before analyze()");
  d.factorized = false;
  const Eigen::Map<const Eigen::VectorXd> values(A.valuePtr(), A.nonZeros());
  if (!values.allFinite()) return false;
  if (d.cholmod()) {
    cholmod_sparse s = d.view(A);
    cholmod_factorize(&s, d.L, &d.common);
    if (d.common.status != CHOLMOD_OK || d.L->minor < d.L->n) return false;
  } else {
    d.llt.factorize(A);
    if (d.llt.info() != Eigen::Success) return false;
  }
  d.factorized = true;
  return true;
}

void SparseCholesky::solve_in_place(Eigen::VectorXd& b) {
  Impl& d = *impl_;
  if (!d.factorized) throw std::logic_error("mss: solve before a successful factorisation");
  if (b.size() != d.n) throw std::logic_error("mss: right-hand side has the wrong size");
  if (d.cholmod()) {
    cholmod_dense B;
    std::memset(&B, 0, sizeof(B));
    B.nrow = B.nzmax = B.d = std::size_t(d.n);
    B.ncol = 1;
    B.x = b.data();
    B.xtype = CHOLMOD_REAL;
    B.dtype = CHOLMOD_DOUBLE;
    if (!cholmod_solve2(CHOLMOD_A, d.L, &B, nullptr, &d.X, nullptr, &d.Y, &d.E, &d.common))
      throw std::runtime_error("mss: CHOLMOD solve failed");
    std::memcpy(b.data(), d.X->x, std::size_t(d.n) * sizeof(double));
  } else {
    d.tmp = d.llt.solve(b);
    b.swap(d.tmp);
  }
}

void SparseCholesky::solve_in_place(Eigen::MatrixXd& B) {
  Impl& d = *impl_;
  if (!d.factorized) throw std::logic_error("mss: solve before a successful factorisation");
  if (B.rows() != d.n) throw std::logic_error("mss: right-hand side has the wrong size");
  if (B.cols() == 0) return;
  if (!d.cholmod()) {
    B = d.llt.solve(B).eval();
    return;
  }
  cholmod_dense b;
  std::memset(&b, 0, sizeof(b));
  b.nrow = b.d = std::size_t(d.n);
  b.ncol = std::size_t(B.cols());
  b.nzmax = b.nrow * b.ncol;
  b.x = B.data();
  b.xtype = CHOLMOD_REAL;
  b.dtype = CHOLMOD_DOUBLE;
  cholmod_dense* X = nullptr;
  cholmod_dense *Y = nullptr, *E = nullptr;
  const bool ok = cholmod_solve2(CHOLMOD_A, d.L, &b, nullptr, &X, nullptr, &Y, &E, &d.common);
  if (ok) std::memcpy(B.data(), X->x, std::size_t(B.size()) * sizeof(double));
  cholmod_free_dense(&X, &d.common);
  cholmod_free_dense(&Y, &d.common);
  cholmod_free_dense(&E, &d.common);
  if (!ok) throw std::runtime_error("mss: CHOLMOD solve failed");
}

double SparseCholesky::factor_nonzeros() const {
  const Impl& d = *impl_;
  if (!d.factorized) return 0;
  if (d.cholmod()) return d.common.lnz;
  return double(d.llt.matrixL().nestedExpression().nonZeros());
}

}  // namespace spinesim::mss::detail

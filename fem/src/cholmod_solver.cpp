#include "spinesim/fem/cholmod_solver.hpp"

#include <Eigen/CholmodSupport>

#include <stdexcept>
#include <string>

namespace spinesim::fem {

struct CholmodSolver::Impl {
  Eigen::CholmodSupernodalLLT<Eigen::SparseMatrix<double>, Eigen::Lower> llt;
  Eigen::CholmodSimplicialLDLT<Eigen::SparseMatrix<double>, Eigen::Lower> ldlt;
  bool use_ldlt = false;

  Impl(Ordering ordering, Factorization factorization)
      : use_ldlt(factorization == Factorization::ldlt) {
    for (cholmod_common* c : {&llt.cholmod(), &ldlt.cholmod()}) {
      c->print = 0;  // errors are reported by our exceptions, not on stderr
      if (ordering != Ordering::automatic) {
        c->nmethods = 1;
        c->method[0].ordering = ordering == Ordering::amd     ? CHOLMOD_AMD
                                : ordering == Ordering::metis ? CHOLMOD_METIS
                                                              : CHOLMOD_NESDIS;
        c->postorder = 1;
      }
    }
  }
  /// Calls fn with the factorisation in use.
  template <class Fn>
  decltype(auto) with(Fn&& fn) {
    return use_ldlt ? fn(ldlt) : fn(llt);
  }
  cholmod_common& common() { return use_ldlt ? ldlt.cholmod() : llt.cholmod(); }
};

CholmodSolver::CholmodSolver(Ordering ordering, Factorization factorization)
    : impl_(std::make_unique<Impl>(ordering, factorization)), factorization_(factorization) {}
CholmodSolver::~CholmodSolver() = default;
CholmodSolver::CholmodSolver(CholmodSolver&&) noexcept = default;
CholmodSolver& CholmodSolver::operator=(CholmodSolver&&) noexcept = default;

void CholmodSolver::analyze(const Eigen::SparseMatrix<double>& lower) {
  if (lower.rows() != lower.cols()) throw std::invalid_argument("CHOLMOD: matrix is not square");
  if (lower.rows() == 0) throw std::invalid_argument("CHOLMOD: matrix is empty (no free unknowns)");
  rows_ = lower.rows();
  factorized_ = false;
  const bool ok = impl_->with([&](auto& f) {
    f.analyzePattern(lower);
    return f.info() == Eigen::Success;
  });
  if (!ok) throw std::runtime_error("CHOLMOD: symbolic analysis failed (out of memory?)");
}

void CholmodSolver::factorize(const Eigen::SparseMatrix<double>& lower) {
  if (lower.rows() != rows_) throw std::logic_error("CHOLMOD: factorize() before analyze()");
  const Eigen::Map<const Eigen::VectorXd> values(lower.valuePtr(), lower.nonZeros());
  if (!values.allFinite()) throw std::runtime_error("CHOLMOD: matrix has non-finite entries");
  factorized_ = false;
  const bool ok = impl_->with([&](auto& f) {
    f.factorize(lower);
    return f.info() == Eigen::Success;
  });
  if (!ok && factorization_ == Factorization::ldlt)
    throw std::runtime_error(
        "CHOLMOD: LDL^T factorisation met a zero pivot (is the body constrained against rigid "
        "motion, and the pressure block definite?)");
  if (!ok)
    throw std::runtime_error(
        "CHOLMOD: matrix is not positive definite (Cholesky factorisation "
        "failed; is the body constrained against rigid motion?)");
  factorized_ = true;
}

double CholmodSolver::factor_nonzeros() const { return impl_->common().lnz; }
double CholmodSolver::factor_flops() const { return impl_->common().fl; }

const char* CholmodSolver::ordering_used() const {
  const cholmod_common& c = impl_->common();
  if (c.selected < 0 || c.selected >= CHOLMOD_MAXMETHODS) return "none";
  switch (c.method[c.selected].ordering) {
    case CHOLMOD_NATURAL:
      return "natural";
    case CHOLMOD_GIVEN:
      return "given";
    case CHOLMOD_AMD:
      return "amd";
    case CHOLMOD_METIS:
      return "metis";
    case CHOLMOD_NESDIS:
      return "nesdis";
    case CHOLMOD_COLAMD:
      return "colamd";
    default:
      return "other";
  }
}

Eigen::MatrixXd CholmodSolver::solve(const Eigen::MatrixXd& rhs) const {
  if (!factorized_) throw std::logic_error("CHOLMOD: solve() before a successful factorize()");
  if (rhs.rows() != rows_) throw std::invalid_argument("CHOLMOD: right-hand side has wrong size");
  if (!rhs.allFinite()) throw std::runtime_error("CHOLMOD: right-hand side is not finite");
  bool ok = false;
  Eigen::MatrixXd x = impl_->with([&](auto& f) {
    Eigen::MatrixXd y = f.solve(rhs);
    ok = f.info() == Eigen::Success;
    return y;
  });
  if (!ok || !x.allFinite())
    throw std::runtime_error(
        "CHOLMOD: solve failed or gave non-finite values (matrix is not "
        "positive definite or is too ill-conditioned)");
  return x;
}

}  // namespace spinesim::fem

#include "spinesim/fem/p2_multigrid.hpp"

#include <algorithm>
#include <cmath>
#include <mutex>
#include <stdexcept>
#include <string>
#include <thread>

namespace spinesim::fem {

namespace {

// Kernels on row-major n×6 blocks (the 6 plate right-hand sides side by side) and a symmetric
// matrix stored as its lower triangle in CSC with the diagonal first in every column. The
// default build targets baseline x86-64 (SSE2); target_clones adds an AVX2+FMA version picked
// at load time, which roughly doubles the throughput of these loops where available. Not under
// ThreadSanitizer: the clones' resolvers run while the dynamic loader relocates the program,
// before the sanitizer's runtime is up, and the instrumented resolver crashed it at start.
constexpr int kCols = 6;
#if defined(__GNUC__) && !defined(__clang__) && defined(__x86_64__) && !defined(__SANITIZE_THREAD__)
#define SPINESIM_KERNEL __attribute__((target_clones("arch=haswell", "default")))
#else
#define SPINESIM_KERNEL
#endif

// y = K x
SPINESIM_KERNEL void sym_multiply(const int* outer, const int* inner, const double* val,
                                  Eigen::Index n, const double* x, double* y) {
  std::fill_n(y, n * kCols, 0.0);
  for (Eigen::Index j = 0; j < n; ++j) {
    const double* xj = x + j * kCols;
    double acc[kCols];
    const double d = val[outer[j]];
    for (int c = 0; c < kCols; ++c) acc[c] = d * xj[c];
    for (int p = outer[j] + 1; p < outer[j + 1]; ++p) {
      const double a = val[p];
      const Eigen::Index i = inner[p];
      double* yi = y + i * kCols;
      const double* xi = x + i * kCols;
      for (int c = 0; c < kCols; ++c) {
        yi[c] += a * xj[c];
        acc[c] += a * xi[c];
      }
    }
    double* yj = y + j * kCols;
    for (int c = 0; c < kCols; ++c) yj[c] += acc[c];
  }
}

// x = (D + L)^-1 b; r is scratch.
SPINESIM_KERNEL void forward_gs(const int* outer, const int* inner, const double* val,
                                const double* inv_diag, Eigen::Index n, const double* b, double* x,
                                double* r) {
  std::copy_n(b, n * kCols, r);
  for (Eigen::Index j = 0; j < n; ++j) {
    double* xj = x + j * kCols;
    for (int c = 0; c < kCols; ++c) xj[c] = r[j * kCols + c] * inv_diag[j];
    for (int p = outer[j] + 1; p < outer[j + 1]; ++p) {
      double* ri = r + Eigen::Index(inner[p]) * kCols;
      const double a = val[p];
      for (int c = 0; c < kCols; ++c) ri[c] -= a * xj[c];
    }
  }
}

// r <- (D + U)^-1 r, in place (rows > j already hold the solution when row j is done).
SPINESIM_KERNEL void backward_gs(const int* outer, const int* inner, const double* val,
                                 const double* inv_diag, Eigen::Index n, double* r) {
  for (Eigen::Index j = n - 1; j >= 0; --j) {
    double s[kCols];
    for (int c = 0; c < kCols; ++c) s[c] = r[j * kCols + c];
    for (int p = outer[j] + 1; p < outer[j + 1]; ++p) {
      const double* ei = r + Eigen::Index(inner[p]) * kCols;
      const double a = val[p];
      for (int c = 0; c < kCols; ++c) s[c] -= a * ei[c];
    }
    for (int c = 0; c < kCols; ++c) r[j * kCols + c] = s[c] * inv_diag[j];
  }
}

template <int NC>
struct Kernels {
  static_assert(NC == kCols, "kernels are written for 6 columns");
  const int* outer;
  const int* inner;
  const double* val;
  const double* inv_diag;
  Eigen::Index n;
  void multiply(const double* x, double* y) const { sym_multiply(outer, inner, val, n, x, y); }
  void forward_gs(const double* b, double* x, double* r) const {
    ::spinesim::fem::forward_gs(outer, inner, val, inv_diag, n, b, x, r);
  }
  void backward_gs(double* r) const {
    ::spinesim::fem::backward_gs(outer, inner, val, inv_diag, n, r);
  }
};

}  // namespace

struct P2MultigridCg::Group {
  // Solves NC columns with independent CGs; the coarse solve is shared under a mutex because
  // a CHOLMOD factor's solve uses its common workspace.
  template <int NC>
  static int run(const P2MultigridCg& self, const Kernels<NC>& K, const double* B, double* X,
                 double rel_tol, int max_it, std::mutex& coarse_mutex) {
    const Eigen::Index n = K.n;
    std::vector<double> r(B, B + n * NC), z(std::size_t(n * NC)), p, q(std::size_t(n * NC)),
        w(std::size_t(n * NC)), t(std::size_t(n * NC));
    std::fill_n(X, n * NC, 0.0);
    double bnorm[NC] = {}, rz[NC] = {};
    for (Eigen::Index i = 0; i < n * NC; ++i) bnorm[i % NC] += B[i] * B[i];
    for (double& v : bnorm) v = std::sqrt(v);

    const auto precondition = [&](const double* res, double* out) {
      K.forward_gs(res, out, w.data());
      K.multiply(out, t.data());
      for (Eigen::Index i = 0; i < n * NC; ++i) w[std::size_t(i)] = res[i] - t[std::size_t(i)];
      Eigen::MatrixXd rc = Eigen::MatrixXd::Zero(3 * self.embed_.num_coarse_nodes, NC);
      const auto& par = self.embed_.parent;
      const auto& wt = self.embed_.weight;
      for (std::size_t i = 0; i < par.size(); ++i)
        for (int k = 0; k < 2; ++k)
          if (par[i][std::size_t(k)] >= 0)
            for (int d = 0; d < 3; ++d)
              for (int c = 0; c < NC; ++c)
                rc(3 * par[i][std::size_t(k)] + d, c) +=
                    wt[i][std::size_t(k)] * w[(3 * i + d) * NC + c];
      Eigen::MatrixXd ec;
      {
        std::lock_guard<std::mutex> lock(coarse_mutex);
        ec = self.coarse_.solve(rc);
      }
      for (std::size_t i = 0; i < par.size(); ++i)
        for (int k = 0; k < 2; ++k)
          if (par[i][std::size_t(k)] >= 0)
            for (int d = 0; d < 3; ++d)
              for (int c = 0; c < NC; ++c)
                out[(3 * i + d) * NC + c] +=
                    wt[i][std::size_t(k)] * ec(3 * par[i][std::size_t(k)] + d, c);
      K.multiply(out, t.data());
      for (Eigen::Index i = 0; i < n * NC; ++i) w[std::size_t(i)] = res[i] - t[std::size_t(i)];
      K.backward_gs(w.data());
      for (Eigen::Index i = 0; i < n * NC; ++i) out[i] += w[std::size_t(i)];
    };
    const auto column_dots = [&](const std::vector<double>& a, const std::vector<double>& b,
                                 double* out) {
      for (int c = 0; c < NC; ++c) out[c] = 0;
      for (Eigen::Index i = 0; i < n * NC; ++i)
        out[i % NC] += a[std::size_t(i)] * b[std::size_t(i)];
    };

    precondition(r.data(), z.data());
    p = z;
    column_dots(r, z, rz);
    for (int it = 1; it <= max_it; ++it) {
      K.multiply(p.data(), q.data());
      double pq[NC], alpha[NC], rr[NC];
      column_dots(p, q, pq);
      for (int c = 0; c < NC; ++c) alpha[c] = pq[c] > 0 ? rz[c] / pq[c] : 0.0;
      for (Eigen::Index i = 0; i < n; ++i)
        for (int c = 0; c < NC; ++c) {
          X[i * NC + c] += alpha[c] * p[std::size_t(i * NC + c)];
          r[std::size_t(i * NC + c)] -= alpha[c] * q[std::size_t(i * NC + c)];
        }
      column_dots(r, r, rr);
      bool done = true;
      for (int c = 0; c < NC; ++c) done = done && std::sqrt(rr[c]) <= rel_tol * bnorm[c];
      if (done) return it;
      precondition(r.data(), z.data());
      double rz_new[NC], beta[NC];
      column_dots(r, z, rz_new);
      for (int c = 0; c < NC; ++c) {
        beta[c] = rz[c] > 0 ? rz_new[c] / rz[c] : 0.0;
        rz[c] = rz_new[c];
      }
      for (Eigen::Index i = 0; i < n; ++i)
        for (int c = 0; c < NC; ++c)
          p[std::size_t(i * NC + c)] =
              z[std::size_t(i * NC + c)] + beta[c] * p[std::size_t(i * NC + c)];
    }
    return -1;
  }
};

P2MultigridCg::P2MultigridCg(const Eigen::SparseMatrix<double>& fine_lower,
                             const Eigen::SparseMatrix<double>& coarse_lower,
                             P1ToP2Embedding embedding)
    : K_(fine_lower), Kc_(coarse_lower), embed_(std::move(embedding)) {
  if (Eigen::Index(3 * embed_.parent.size()) != K_.rows() ||
      3 * embed_.num_coarse_nodes != Kc_.rows())
    throw std::invalid_argument("P2MultigridCg: embedding does not match the matrices");
  coarse_.compute(Kc_);
  inv_diag_.resize(K_.rows());
  for (Eigen::Index j = 0; j < K_.outerSize(); ++j) {
    const int first = K_.outerIndexPtr()[j];
    if (K_.innerIndexPtr()[first] != j || !(K_.valuePtr()[first] > 0))
      throw std::runtime_error("P2 multigrid: matrix is not positive definite (bad diagonal)");
    inv_diag_(j) = 1.0 / K_.valuePtr()[first];
  }
}

Eigen::MatrixXd P2MultigridCg::solve(const Eigen::MatrixXd& B, double rel_tol, int max_iterations) {
  if (B.rows() != K_.rows())
    throw std::invalid_argument("P2MultigridCg: right-hand side has wrong size");
  if (!B.allFinite()) throw std::runtime_error("P2MultigridCg: right-hand side is not finite");
  constexpr int NC = 6;  // columns per thread (one pass over the matrix serves all six)
  const Eigen::Index n = K_.rows();
  const Kernels<NC> kernels{K_.outerIndexPtr(), K_.innerIndexPtr(), K_.valuePtr(), inv_diag_.data(),
                            n};
  const Eigen::Index groups = (B.cols() + NC - 1) / NC;
  std::vector<std::vector<double>> b(std::size_t(groups),
                                     std::vector<double>(std::size_t(n * NC), 0.0));
  std::vector<std::vector<double>> x(std::size_t(groups),
                                     std::vector<double>(std::size_t(n * NC), 0.0));
  for (Eigen::Index c = 0; c < B.cols(); ++c)
    for (Eigen::Index i = 0; i < n; ++i)
      b[std::size_t(c / NC)][std::size_t(i * NC + c % NC)] = B(i, c);
  std::vector<int> iterations(std::size_t(groups), 0);
  std::mutex coarse_mutex;
  std::vector<std::thread> threads;
  std::exception_ptr error;
  std::mutex error_mutex;
  // One group (the usual 6 plate columns) runs on this thread: measured faster than splitting
  // columns over both cores, where the coarse CHOLMOD solve's BLAS threads compete with ours.
  const auto run_group = [&](Eigen::Index g) {
    try {
      iterations[std::size_t(g)] =
          Group::run<NC>(*this, kernels, b[std::size_t(g)].data(), x[std::size_t(g)].data(),
                         rel_tol, max_iterations, coarse_mutex);
    } catch (...) {
      std::lock_guard<std::mutex> lock(error_mutex);
      error = std::current_exception();
    }
  };
  if (groups == 1) {
    run_group(0);
  } else {
    for (Eigen::Index g = 0; g < groups; ++g) threads.emplace_back(run_group, g);
    for (auto& t : threads) t.join();
  }
  if (error) std::rethrow_exception(error);
  last_iterations_ = 0;
  for (int it : iterations) {
    if (it < 0)
      throw std::runtime_error("P2 multigrid CG did not converge in " +
                               std::to_string(max_iterations) +
                               " iterations (matrix not positive definite or badly conditioned)");
    last_iterations_ = std::max(last_iterations_, it);
  }
  Eigen::MatrixXd X(n, B.cols());
  for (Eigen::Index c = 0; c < B.cols(); ++c)
    for (Eigen::Index i = 0; i < n; ++i)
      X(i, c) = x[std::size_t(c / NC)][std::size_t(i * NC + c % NC)];
  if (!X.allFinite()) throw std::runtime_error("P2 multigrid CG produced non-finite values");
  return X;
}

}  // namespace spinesim::fem

// The per-step solve of the implicit MSS step with each sparse Cholesky backend (the measurement
// behind mss's default_cholesky_backend()): one forward/back substitution pair with the
// factorisation of M/dt² + K_d/dt + K_rest (dt = 1 ms) on CGAL L4-L5 discs, and the
// factorisation itself. This benchmark times private kernels of mss/ (its CMake lines say so).
//   build/release/bench/bench_mss_cholesky
#include "spinesim/mesh/disc_geometry.hpp"
#include "spinesim/mesh/material.hpp"
#include "spinesim/mesh/mesher.hpp"
#include "spinesim/mss/model.hpp"

#include "reduced_space.hpp"
#include "sparse_cholesky.hpp"

#include <benchmark/benchmark.h>

#include <cmath>
#include <map>

using namespace spinesim;
using namespace spinesim::mss;

namespace {

/// The reduced step matrix of the L4-L5 disc at `cell_mm` (cached).
const Eigen::SparseMatrix<double>& step_matrix(double cell_mm) {
  static std::map<long, Eigen::SparseMatrix<double>> cache;
  auto& A = cache[std::lround(cell_mm * 1000)];
  if (A.rows() == 0) {
    mesh::MeshOptions opt;
    opt.cell_size_mm = cell_mm;
    const mesh::TetMesh m =
        mesh::mesh_parametric_disc(mesh::disc_dimensions("L4-L5", SPINESIM_DATA_DIR), opt);
    const MssModel model(m, mesh::load_material("real-disc", SPINESIM_DATA_DIR));
    Eigen::SparseMatrix<double> H;
    model.hessian(model.rest_positions_mm(), HessianMode::exact, H);
    const detail::ReducedSpace space(model, H, PlateMode::pose, Eigen::Vector3d::Zero());
    A = space.pattern();
    space.reduce_matrix(H, A);
    space.add_lumped(space.lumped(model.node_masses_t()), 1e6, A);  // dt = 1 ms
  }
  return A;
}

const detail::CholeskyBackend kBackends[] = {detail::CholeskyBackend::cholmod_simplicial,
                                             detail::CholeskyBackend::cholmod_supernodal,
                                             detail::CholeskyBackend::eigen_simplicial};
const char* kNames[] = {"cholmod-simplicial", "cholmod-supernodal", "eigen-simplicial"};

void Solve(benchmark::State& state) {
  const double cell = state.range(0) / 10.0;
  const auto& A = step_matrix(cell);
  detail::SparseCholesky c(kBackends[state.range(1)]);
  c.analyze(A);
  if (!c.factorize(A)) state.SkipWithError("factorisation failed");
  Eigen::VectorXd x(A.rows());
  for (auto _ : state) {
    x.setOnes();
    c.solve_in_place(x);
    benchmark::DoNotOptimize(x.data());
  }
  state.SetLabel(kNames[state.range(1)]);
  state.counters["dofs"] = double(A.rows());
  state.counters["nnz_L"] = double(c.factor_nonzeros());
}

void Factorise(benchmark::State& state) {
  const auto& A = step_matrix(state.range(0) / 10.0);
  detail::SparseCholesky c(kBackends[state.range(1)]);
  c.analyze(A);
  for (auto _ : state) benchmark::DoNotOptimize(c.factorize(A));
  state.SetLabel(kNames[state.range(1)]);
  state.counters["dofs"] = double(A.rows());
}

void cases(benchmark::internal::Benchmark* b) {
  for (int cell : {35, 25, 20, 16})  // cell size, 0.1 mm
    for (int backend = 0; backend < 3; ++backend) b->Args({cell, backend});
}

}  // namespace

BENCHMARK(Solve)->Apply(cases)->Unit(benchmark::kMicrosecond);
BENCHMARK(Factorise)->Apply(cases)->Unit(benchmark::kMillisecond);
BENCHMARK_MAIN();

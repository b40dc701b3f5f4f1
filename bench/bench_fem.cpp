// FEM reference benchmarks: where the time of a 6×6 disc stiffness goes, by stage and size.
//
// Meshes: structured Kuhn boxes with lumbar-disc proportions, 46 (x) × 11 (y, height) × 35 (z)
// mm, cell size h (benchmark argument in µm), P1 or P2. Stages, each timed separately:
//   Pattern    — P1/P2 node set, boundary roles, K_ff sparsity (DiscFem "setup")
//   Assembly   — element stiffness + scatter into K_ff, K_fp, K_pp
//   Analyse    — CHOLMOD fill-reducing ordering + symbolic factorisation
//   Factorise  — CHOLMOD supernodal numeric factorisation
//   Solve      — the 6 solves K_ff^-1 K_fp
//   Full6x6    — the whole DiscFem constructor (validation .. K6); third argument 0: direct
//                CHOLMOD on K_ff, 1: P2 p-multigrid CG (P1 block factorised instead)
// Counters: DOF (free unknowns), peak_rss_MB (process peak resident set, getrusage; it only
// grows, so read it in the order the benchmarks run: smaller meshes first).
// Run: build/h-fem/bench/bench_fem [--benchmark_filter=Full6x6]
#include "spinesim/common/memory.hpp"
#include "spinesim/fem/assembly.hpp"
#include "spinesim/fem/cholmod_solver.hpp"
#include "spinesim/fem/disc_fem.hpp"
#include "spinesim/fem/fe_space.hpp"
#include "spinesim/fem/nonlinear_disc.hpp"
#include "spinesim/mesh/box_mesh.hpp"
#include "spinesim/mesh/disc_level.hpp"
#include "spinesim/mesh/material.hpp"
#include "spinesim/mesh/mesher.hpp"

#include <benchmark/benchmark.h>

#include <sys/resource.h>

#include <cmath>
#include <map>
#include <memory>

using namespace spinesim;
using namespace spinesim::fem;

namespace {

double peak_rss_mb() {
  rusage ru{};
  getrusage(RUSAGE_SELF, &ru);
  return double(ru.ru_maxrss) / 1024.0;  // Linux: kilobytes
}

mesh::TetMesh disc_box(double h_mm) {
  const double lx = 46, ly = 11, lz = 35;
  const auto cells = [&](double l) { return std::max(1, int(std::lround(l / h_mm))); };
  return spinesim::mesh::box_mesh(cells(lx), cells(ly), cells(lz), lx, ly, lz,
                                  Eigen::Vector3d(-0.5 * lx, 0, -0.5 * lz));
}

mesh::RegionMaterials disc_material() {
  mesh::RegionMaterials m;
  m.name = "real-disc-like";
  m.fallback = {3.22, 0.45, 1038.0};
  return m;
}

// One prepared problem per (order, h): mesh, node set, roles, pattern, assembled blocks.
struct Problem {
  mesh::TetMesh mesh;
  FeSpace space;
  std::vector<NodeRole> roles;
  FreeBlockPattern pattern;
  PlateCoupling coupling;
  Eigen::Vector3d center;
};

Problem& problem(int order, double h_mm) {
  static std::map<std::pair<int, long>, std::unique_ptr<Problem>> cache;
  auto& slot = cache[{order, std::lround(h_mm * 1000)}];
  if (!slot) {
    cache.clear();  // keep one problem in memory at a time
    auto p = std::make_unique<Problem>();
    p->mesh = disc_box(h_mm);
    p->center = DiscFem::default_plate_center(p->mesh);
    p->space = make_fe_space(p->mesh, order);
    const Eigen::VectorXi labels = node_surface_labels(p->space, p->mesh);
    p->roles.assign(std::size_t(labels.size()), NodeRole::free);
    for (Eigen::Index i = 0; i < labels.size(); ++i)
      p->roles[std::size_t(i)] = labels(i) == 1   ? NodeRole::fixed
                                 : labels(i) == 2 ? NodeRole::plate
                                                  : NodeRole::free;
    p->pattern = build_free_block_pattern(p->space, p->roles);
    p->coupling = assemble_constrained(p->space, p->mesh.region, disc_material(), p->roles,
                                       p->center, p->pattern);
    cache[{order, std::lround(h_mm * 1000)}] = std::move(p);
    return *cache[{order, std::lround(h_mm * 1000)}];
  }
  return *slot;
}

void set_counters(benchmark::State& st, const Problem& p) {
  st.counters["DOF"] = double(p.pattern.lower.rows());
  st.counters["tets"] = double(p.mesh.num_tets());
  st.counters["nnz_K"] = double(p.pattern.lower.nonZeros());
  st.counters["peak_rss_MB"] = peak_rss_mb();
}

double h_of(const benchmark::State& st) { return double(st.range(1)) * 1e-3; }

void BM_Pattern(benchmark::State& st) {
  Problem& p = problem(int(st.range(0)), h_of(st));
  for (auto _ : st) {
    FeSpace s = make_fe_space(p.mesh, int(st.range(0)));
    FreeBlockPattern pat = build_free_block_pattern(s, p.roles);
    benchmark::DoNotOptimize(pat.lower.nonZeros());
  }
  set_counters(st, p);
}

void BM_Assembly(benchmark::State& st) {
  Problem& p = problem(int(st.range(0)), h_of(st));
  for (auto _ : st) {
    PlateCoupling c =
        assemble_constrained(p.space, p.mesh.region, disc_material(), p.roles, p.center, p.pattern);
    benchmark::DoNotOptimize(c.K_pp(0, 0));
  }
  set_counters(st, p);
}

void BM_Analyse(benchmark::State& st) {
  Problem& p = problem(int(st.range(0)), h_of(st));
  for (auto _ : st) {
    CholmodSolver s;
    s.analyze(p.pattern.lower);
  }
  set_counters(st, p);
}

void BM_Factorise(benchmark::State& st) {
  Problem& p = problem(int(st.range(0)), h_of(st));
  CholmodSolver s(Ordering(st.range(2)));
  s.analyze(p.pattern.lower);
  for (auto _ : st) s.factorize(p.pattern.lower);
  set_counters(st, p);
  st.SetLabel(s.ordering_used());
  st.counters["nnz_L"] = s.factor_nonzeros();
  st.counters["GFlop"] = s.factor_flops() * 1e-9;
  st.counters["GFlop/s"] = benchmark::Counter(s.factor_flops() * 1e-9 * double(st.iterations()),
                                              benchmark::Counter::kIsRate);
}

void BM_Solve6(benchmark::State& st) {
  Problem& p = problem(int(st.range(0)), h_of(st));
  CholmodSolver s;
  s.compute(p.pattern.lower);
  for (auto _ : st) {
    Eigen::MatrixXd Z = s.solve(p.coupling.K_fp);
    benchmark::DoNotOptimize(Z(0, 0));
  }
  set_counters(st, p);
}

void BM_Full6x6(benchmark::State& st) {
  Problem& p = problem(int(st.range(0)), h_of(st));
  Timings t;
  SolverOptions opt;
  opt.solver = st.range(2) ? LinearSolver::p_multigrid_cg : LinearSolver::direct;
  for (auto _ : st) {
    DiscFem fem(p.mesh, disc_material(), int(st.range(0)), p.center, opt);
    benchmark::DoNotOptimize(fem.stiffness_6x6()(0, 0));
    t = fem.timings();
  }
  set_counters(st, p);
  st.counters["setup_s"] = t.setup_s;
  st.counters["assembly_s"] = t.assembly_s;
  st.counters["analyse_s"] = t.analyse_s;
  st.counters["factorise_s"] = t.factorise_s;
  st.counters["solve_s"] = t.solve_s;
  st.counters["cg_iterations"] = t.cg_iterations;
  st.SetLabel(st.range(2) ? "p-multigrid CG" : "direct");
}

// The real case: the parametric L4-L5 disc (Twomey/Panjabi dimensions as in tests/mesh),
// CGAL-meshed at cell size (µm), annulus/nucleus regions; arguments (order, cell µm, solver).
void BM_L4L5Disc(benchmark::State& st) {
  static std::map<long, mesh::TetMesh> meshes;
  auto it = meshes.find(st.range(1));
  if (it == meshes.end()) {
    mesh::MeshOptions opt;
    opt.cell_size_mm = double(st.range(1)) * 1e-3;
    it = meshes
             .emplace(st.range(1),
                      mesh::mesh_parametric_disc({"L4-L5", 47.3, 35.5, 46.6, 35.0, 11.3}, opt))
             .first;
  }
  const mesh::TetMesh& m = it->second;
  mesh::RegionMaterials mat;
  mat.name = "annulus-nucleus-like";
  mat.fallback = {4.2, 0.45, 1038.0};
  mat.by_region[2] = {1.0, 0.49, 1038.0};
  SolverOptions opt;
  opt.solver = st.range(2) ? LinearSolver::p_multigrid_cg : LinearSolver::direct;
  Timings t;
  Eigen::Index dofs = 0;
  for (auto _ : st) {
    DiscFem fem(m, mat, int(st.range(0)), DiscFem::default_plate_center(m), opt);
    benchmark::DoNotOptimize(fem.stiffness_6x6()(0, 0));
    t = fem.timings();
    dofs = fem.num_dofs();
  }
  st.counters["vertices"] = double(m.num_vertices());
  st.counters["tets"] = double(m.num_tets());
  st.counters["DOF"] = double(dofs);
  st.counters["assembly_s"] = t.assembly_s;
  st.counters["analyse_s"] = t.analyse_s;
  st.counters["factorise_s"] = t.factorise_s;
  st.counters["solve_s"] = t.solve_s;
  st.counters["cg_iterations"] = t.cg_iterations;
  st.counters["peak_rss_MB"] = peak_rss_mb();
  st.SetLabel(st.range(2) ? "p-multigrid CG" : "direct");
}
BENCHMARK(BM_L4L5Disc)
    ->Args({1, 1500, 0})
    ->Args({1, 1000, 0})
    ->Args({2, 1500, 0})
    ->Args({2, 1500, 1})
    ->Args({2, 1000, 1})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->Iterations(1);

// (order, h in µm): P1 from ~6k to ~200k DOF, P2 from ~6k to ~210k DOF.
// Orderings (third argument: 0 CHOLMOD's automatic choice, 1 AMD, 3 NESDIS): all sizes with
// the automatic choice, the alternatives at one mid size each.
void sizes_orderings(benchmark::internal::Benchmark* b) {
  for (long h : {2000, 1400, 1000, 800, 640}) b->Args({1, h, 0});
  for (long h : {4000, 2800, 2000, 1600, 1300}) b->Args({2, h, 0});
  for (long o : {1, 3}) b->Args({1, 1000, o}), b->Args({2, 2000, o});
  b->Unit(benchmark::kMillisecond)->UseRealTime();
}

void sizes(benchmark::internal::Benchmark* b) {
  for (long h : {2000, 1400, 1000, 800, 640}) b->Args({1, h});
  for (long h : {4000, 2800, 2000, 1600, 1300}) b->Args({2, h});
  b->Unit(benchmark::kMillisecond)->UseRealTime();
}

}  // namespace

BENCHMARK(BM_Pattern)->Apply(sizes);
BENCHMARK(BM_Assembly)->Apply(sizes);
BENCHMARK(BM_Analyse)->Apply(sizes)->Iterations(1);
BENCHMARK(BM_Factorise)->Apply(sizes_orderings);
BENCHMARK(BM_Solve6)->Apply(sizes);
void sizes_solvers(benchmark::internal::Benchmark* b) {
  for (long h : {2000, 1400, 1000, 800, 640}) b->Args({1, h, 0});
  for (long s : {0, 1})
    for (long h : {4000, 2800, 2000, 1600, 1300}) b->Args({2, h, s});
  b->Unit(benchmark::kMillisecond)->UseRealTime();
}

BENCHMARK(BM_Full6x6)->Apply(sizes_solvers)->Iterations(1);

// One nonlinear load case of the fibre-reinforced L4-L5 disc (fem/nonlinear_disc.hpp): the plate
// turned 3° about the disc axis and pressed 0.2 mm, four load increments, Newton to 1e-10.
// Args: order, CGAL cell size in µm.
void BM_NonlinearDisc(benchmark::State& st) {
  mesh::MeshOptions opt;
  opt.cell_size_mm = double(st.range(1)) / 1000.0;
  const mesh::TetMesh m = mesh::mesh_disc_level("L4-L5", opt, SPINESIM_DATA_DIR);
  const auto materials =
      disc_element_materials(m, mesh::load_material("fibre-reinforced", SPINESIM_DATA_DIR), 10.0);
  Eigen::Matrix<double, 6, 1> q = Eigen::Matrix<double, 6, 1>::Zero();
  q(1) = -0.2;
  q(4) = 3.0 * M_PI / 180.0;
  NonlinearPlateSolution s;
  for (auto _ : st) {
    const NonlinearDisc d(m, materials, int(st.range(0)), DiscFem::default_plate_center(m));
    s = d.solve_motion(q);
    // A const copy: DoNotOptimize on a non-const lvalue may write it back (it did, as 0).
    const double moment = s.reaction_wrench(4);
    benchmark::DoNotOptimize(moment);
  }
  st.counters["tets"] = double(m.num_tets());
  st.counters["DOF"] = 3.0 * double(s.body.displacement_mm.rows());
  st.counters["newton"] = s.body.newton_iterations;
  st.counters["factorisations"] = s.body.factorisations;
  st.counters["increments"] = s.body.increments;
  st.counters["converged"] = s.body.converged ? 1 : 0;
  st.counters["resisting_Nmm"] = -s.reaction_wrench(4);  // counters print negatives badly
  st.counters["peak_rss_MB"] = peak_rss_mb();
}
BENCHMARK(BM_NonlinearDisc)
    ->Args({1, 2000})
    ->Args({2, 2000})
    ->Unit(benchmark::kSecond)
    ->Iterations(1);

// The nearly incompressible nucleus (ν 0.4999, K/μ = 5000) with each formulation: the
// fibre-reinforced preset's regions without the fibres, so that the nonlinear disc at a small
// motion is the linear one up to its volumetric form. The plate pressed 0.01 mm; Fy against the
// linear Taylor–Hood mixed form (LDLᵀ), per formulation the time of one load case.
// Args: formulation (0 linear P2 mixed, 1 linear P2 displacement, 2 nonlinear P1 pointwise,
// 3 nonlinear P1 nodal average, 4 nonlinear P2 pointwise, 5 nonlinear P2 mean dilatation),
// CGAL cell size in µm.
void BM_NearlyIncompressibleDisc(benchmark::State& st) {
  static std::map<long, mesh::TetMesh> meshes;
  auto it = meshes.find(st.range(1));
  if (it == meshes.end()) {
    mesh::MeshOptions opt;
    opt.cell_size_mm = double(st.range(1)) / 1000.0;
    it = meshes.emplace(st.range(1), mesh::mesh_disc_level("L4-L5", opt, SPINESIM_DATA_DIR)).first;
  }
  const mesh::TetMesh& m = it->second;
  mesh::RegionMaterials mat = mesh::load_material("fibre-reinforced", SPINESIM_DATA_DIR);
  mat.fibres.clear();
  const Eigen::Vector3d c = DiscFem::default_plate_center(m);
  Eigen::Matrix<double, 6, 1> q = Eigen::Matrix<double, 6, 1>::Zero();
  q(1) = -0.01;
  const long kind = st.range(0);
  static const char* names[] = {"linear P2 mixed",        "linear P2 displacement",
                                "nonlinear P1 pointwise", "nonlinear P1 nodal average",
                                "nonlinear P2 pointwise", "nonlinear P2 mean dilatation"};
  double fy = 0, dofs = 0, newton = 0, factorisations = 1;
  for (auto _ : st) {
    if (kind < 2) {
      SolverOptions o;
      o.solver = LinearSolver::direct;
      o.formulation = kind == 0 ? Formulation::mixed : Formulation::displacement;
      const DiscFem fem(m, mat, 2, c, o);
      fy = (-fem.stiffness_6x6() * q)(1);
      dofs = double(fem.num_dofs());
    } else {
      static const VolumetricForm forms[] = {
          VolumetricForm::pointwise, VolumetricForm::nodal_average, VolumetricForm::pointwise,
          VolumetricForm::mean_dilatation};
      const NonlinearDisc d(m, disc_element_materials(m, mat, 10.0), kind < 4 ? 1 : 2, c,
                            forms[kind - 2]);
      const NonlinearPlateSolution s = d.solve_motion(q);
      fy = s.reaction_wrench(1);
      dofs = 3.0 * double(s.body.displacement_mm.rows());
      newton = s.body.newton_iterations;
      factorisations = s.body.factorisations;
    }
    const double copy = fy;
    benchmark::DoNotOptimize(copy);
  }
  st.counters["tets"] = double(m.num_tets());
  st.counters["DOF"] = dofs;
  st.counters["Fy_N"] = fy;
  st.counters["newton"] = newton;
  st.counters["factorisations"] = factorisations;
  st.counters["peak_rss_MB"] = peak_rss_mb();
  st.SetLabel(names[kind]);
}
BENCHMARK(BM_NearlyIncompressibleDisc)
    ->ArgsProduct({{0, 1, 2, 3, 4, 5}, {2000}})
    ->Args({0, 1500})
    ->Args({3, 1500})
    ->Args({3, 1000})
    ->Unit(benchmark::kSecond)
    ->UseRealTime()
    ->Iterations(1);

// As the spinesim program runs: freed memory kept in the process (common/memory.hpp).
int main(int argc, char** argv) {
  spinesim::keep_freed_memory();
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}

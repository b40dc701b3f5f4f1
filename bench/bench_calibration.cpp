// Calibration cost on the parametric L4-L5 disc (real-disc material) by CGAL cell size:
//   Setup        K_j for every knob (term Hessians at rest, reduced) — once per disc
//   Evaluate     one objective + adjoint gradient (one factorisation, 6 + #train solves)
//   EvaluateGN   the same plus the Gauss–Newton Hessian Ipopt uses (#knobs x #train more solves)
//   Calibrate    the whole Ipopt run from Van Gelder (FEM reference precomputed)
// The FEM P2 reference is built once per mesh outside the timed loops (its cost: bench_fem).
#include "spinesim/calibration/calibrate.hpp"
#include "spinesim/mesh/disc_geometry.hpp"
#include "spinesim/mesh/material.hpp"
#include "spinesim/mesh/mesher.hpp"
#include "spinesim/mss/boundary.hpp"

#include <benchmark/benchmark.h>

#include <map>
#include <memory>

namespace {

using namespace spinesim;

const std::vector<std::string> kTrain = {"compression", "shear-ap", "flexion", "torsion"};

struct Disc {
  mesh::TetMesh mesh;
  mesh::RegionMaterials materials;
  std::unique_ptr<mss::MssModel> model;
  calibration::FemReference reference;
};

/// Cell size in tenths of a mm -> meshed disc with its FEM P2 reference (cached per process).
Disc& disc(int cell_tenths) {
  static std::map<int, std::unique_ptr<Disc>> cache;
  auto& d = cache[cell_tenths];
  if (!d) {
    d = std::make_unique<Disc>();
    mesh::MeshOptions opt;
    opt.cell_size_mm = 0.1 * cell_tenths;
    d->mesh = mesh::mesh_parametric_disc(mesh::disc_dimensions("L4-L5", SPINESIM_DATA_DIR), opt);
    d->materials = mesh::load_material("real-disc", SPINESIM_DATA_DIR);
    mss::MssOptions o;
    o.volume_term = true;
    d->model = std::make_unique<mss::MssModel>(d->mesh, d->materials, o);
    const Eigen::Vector3d c = fem::DiscFem::default_plate_center(d->mesh);
    const fem::DiscFem fem(d->mesh, d->materials, 2, c);
    d->reference = calibration::make_reference(fem, d->mesh, fem::standard_load_cases());
  }
  return *d;
}

void label(benchmark::State& state, const Disc& d) {
  state.counters["tets"] = double(d.mesh.num_tets());
  state.counters["nodes"] = double(d.mesh.num_vertices());
}

void Setup(benchmark::State& state) {
  Disc& d = disc(int(state.range(0)));
  for (auto _ : state) {
    calibration::LinearMss lin(*d.model, calibration::available_knobs(d.model->options()),
                               d.reference.plate_center_mm);
    benchmark::DoNotOptimize(lin.num_unknowns());
  }
  label(state, d);
}

void Evaluate(benchmark::State& state) {
  Disc& d = disc(int(state.range(0)));
  const bool hessian = state.range(1) != 0;
  calibration::LinearMss lin(*d.model, calibration::available_knobs(d.model->options()),
                             d.reference.plate_center_mm);
  calibration::Objective obj(lin, d.reference, kTrain);
  const Eigen::VectorXd p = Eigen::VectorXd::Constant(Eigen::Index(lin.knobs().size()), -0.3);
  for (auto _ : state) benchmark::DoNotOptimize(obj.evaluate(p, true, hessian).value);
  label(state, d);
}

void Calibrate(benchmark::State& state) {
  Disc& d = disc(int(state.range(0)));
  int iterations = 0;
  for (auto _ : state) {
    calibration::LinearMss lin(*d.model, calibration::available_knobs(d.model->options()),
                               d.reference.plate_center_mm);
    calibration::Objective obj(lin, d.reference, kTrain);
    const auto r =
        calibration::calibrate(obj, Eigen::VectorXd::Zero(Eigen::Index(lin.knobs().size())));
    if (!r.success) state.SkipWithError(r.status.c_str());
    iterations = r.iterations;
  }
  label(state, d);
  state.counters["ipopt_iterations"] = iterations;
}

// Cell sizes 3, 2 (the default mesh) and 1.5 mm.
BENCHMARK(Setup)->Arg(30)->Arg(20)->Arg(15)->Unit(benchmark::kMillisecond);
BENCHMARK(Evaluate)->ArgsProduct({{30, 20, 15}, {0, 1}})->Unit(benchmark::kMillisecond);
BENCHMARK(Calibrate)->Arg(30)->Arg(20)->Arg(15)->Unit(benchmark::kSecond)->Iterations(1);

}  // namespace

BENCHMARK_MAIN();

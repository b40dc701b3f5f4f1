#include "spinesim/studies/mss_verbs.hpp"

#include "spinesim/calibration/compare.hpp"
#include "spinesim/calibration/tuned_set.hpp"
#include "spinesim/common/timer.hpp"
#include "spinesim/fem/disc_fem.hpp"
#include "spinesim/mesh/io.hpp"
#include "spinesim/mss/quantities.hpp"
#include "spinesim/studies/calibration_summary.hpp"
#include "spinesim/studies/toolkit.hpp"

#include <filesystem>
#include <ostream>
#include <stdexcept>

namespace spinesim::studies {
namespace fs = std::filesystem;

MssModelChoice choose_mss_model(const MssModelRequest& rq, const std::string& data_dir) {
  MssModelChoice c;
  c.params = rq.params;
  if (rq.params.empty()) {
    c.options = rq.options;
    c.materials = mesh::load_material(rq.material, data_dir);
    c.variant = rq.variant;
    return c;
  }
  const calibration::TunedDisc tuned = calibration::read_tuned_for_mesh(rq.params, nullptr);
  c.options = tuned.mss_options();
  c.options.damping_n_s_per_mm = rq.options.damping_n_s_per_mm;  // --damping still applies
  // Not the preset of that name: the file may have been fitted with a material JSON file.
  c.materials = rq.material_given ? mesh::load_material(rq.material, data_dir) : tuned.materials();
  c.constants = "tuned (" + rq.params + ")";
  c.variant = "tuned " + std::string(c.options.volume_term ? "thesis+volume" : "thesis") +
              (c.options.disc_volume_term ? "+disc-volume" : "") +
              (tuned.per_spring() ? ", per-spring" : "");
  return c;
}

mss::MssModel build_mss_model(const mesh::TetMesh& m, const MssModelChoice& c, bool quiet) {
  if (c.params.empty()) return mss::MssModel(m, c.materials, c.options);
  const calibration::TunedDisc tuned = calibration::read_tuned_for_mesh(c.params, &m);
  mss::MssModel model = tuned_model(tuned, m, c.materials, quiet);
  if (c.options.damping_n_s_per_mm >= 0) {
    mss::MssOptions o = model.options();
    o.damping_n_s_per_mm = c.options.damping_n_s_per_mm;
    return mss::MssModel(m, c.materials, o);
  }
  return model;
}

namespace {

/// --out: a .vtu, or a .pvd series for a dynamic run, in a folder that exists; true for a series.
bool check_output(const MssFileRunRequest& rq) {
  if (rq.out.empty()) return false;
  const bool series = fs::path(rq.out).extension() == ".pvd";
  if (fs::path(rq.out).extension() != ".vtu" && !series)
    throw std::invalid_argument("--out " + rq.out +
                                ": give a .vtu file (or a .pvd time series for a dynamic run)");
  if (series && !rq.run.dynamic)
    throw std::invalid_argument("--out " + rq.out +
                                ": a .pvd time series needs a dynamic run (--dt/--steps)");
  require_output_folder(rq.out, "--out");
  return series;
}

/// The mesh, with its endplates labelled.
mesh::TetMesh read_disc(const std::string& path, const StageHooks& hooks) {
  hooks.begin_stage("reading " + path);
  mesh::TetMesh m = mesh::read_tet_mesh(path);
  mesh::require_endplate_labels(m);
  hooks.end_stage(std::to_string(m.num_tets()) + " tets");
  return m;
}

}  // namespace

int mss_file_run_stages(const MssFileRunRequest& rq) { return 3 + int(!rq.out.empty()); }

MssFileRunResult run_mss_file(const MssFileRunRequest& rq, const std::string& data_dir,
                              const StageHooks& hooks) {
  // 1. Everything checked before any work: bad input fails fast, writes nothing.
  if (rq.mesh_path.empty()) throw std::invalid_argument("--mesh is required");
  MssFileRunResult out;
  out.choice = choose_mss_model(rq.model, data_dir);
  const bool series = check_output(rq);

  // 2. Mesh and model; the load about the plate centre (a named case in the disc's frame).
  const Timer t_read;
  const mesh::TetMesh m = read_disc(rq.mesh_path, hooks);
  const double read_s = t_read.seconds();
  MssRunRequest run = rq.run;
  run.load.center = rq.center ? *rq.center : fem::DiscFem::default_plate_center(m);
  if (rq.load_case) {
    run.load.is_wrench = true;
    run.load.value = fem::global_wrench(*rq.load_case, m.frame);
  }
  hooks.begin_stage("building the mass-spring model");
  const Timer t_build;
  out.model = std::make_shared<const mss::MssModel>(build_mss_model(m, out.choice, rq.quiet));
  const mss::MssModel& model = *out.model;
  const double build_s = t_build.seconds();
  hooks.end_stage(std::to_string(model.num_edge_springs()) + " edge springs");

  // 3. Solve or step.
  std::unique_ptr<VtuSeries> frames = series ? std::make_unique<VtuSeries>(rq.out) : nullptr;
  out.run = run_mss_load(model, run, frames.get(), hooks);
  const MssRunResult& r = out.run;
  nlohmann::json& j = out.json;
  j = mss_run_json(r);
  j["timings"]["read_s"] = read_s;
  j["timings"]["build_s"] = build_s;
  j.update({{"mesh", rq.mesh_path},
            {"nodes", m.num_vertices()},
            {"tets", m.num_tets()},
            {"material", out.choice.materials.name},
            {"plate_center", to_json(Eigen::VectorXd(run.load.center))},
            {"load", run.load.is_wrench ? "wrench" : "motion"},
            {"mss_constants", out.choice.constants}});
  j.update(mss_model_json(model, out.choice.materials));
  if (!rq.model.params.empty()) j["params"] = rq.model.params;
  if (rq.load_case) j["case"] = rq.load_case->name;
  if (!r.failed && r.inverted_tets > 0)
    out.warning = std::to_string(r.inverted_tets) +
                  " tetrahedra are inside out at the result: the load is beyond what the spring "
                  "network holds (try --volume-term or --disc-volume-term)";

  // 4. Output files, only for a run that succeeded: no NaN, no half series.
  if (r.failed && frames) frames->discard();
  if (!r.failed && !rq.out.empty()) {
    hooks.begin_stage("writing " + rq.out);
    if (frames) {
      frames->finish();
      j["frames"] = frames->num_frames();
    } else {
      const mss::StateFields f = mss::state_fields(model, r.x_mm);
      mesh::write_vtu(rq.out, m, f.point, f.cell);
    }
    hooks.end_stage();
    j["out"] = rq.out;
  }
  return out;
}

MssCompareResult run_mss_compare(const MssCompareRequest& rq, const std::string& data_dir,
                                 const StageHooks& hooks) {
  // 1. Options.
  if (rq.cases.empty()) throw std::invalid_argument("--cases: give at least one load case");
  if (!std::isfinite(rq.load_scale) || rq.load_scale <= 0)
    throw std::invalid_argument("--load-scale must be a finite number > 0");
  if (rq.order != 1 && rq.order != 2) throw std::invalid_argument("--order must be 1 or 2");
  MssCompareResult out;
  out.choice = choose_mss_model(rq.model, data_dir);
  if (!rq.csv.empty()) require_output_folder(rq.csv, "--csv");
  const auto& materials = out.choice.materials;

  // 2. Mesh, FEM reference and MSS on the same mesh.
  const mesh::TetMesh m = read_disc(rq.mesh_path, hooks);
  out.nodes = m.num_vertices();
  out.tets = m.num_tets();
  // First: a tuned file that does not apply is refused here.
  hooks.begin_stage("building the mass-spring model");
  const mss::MssModel model = build_mss_model(m, out.choice, rq.quiet);
  hooks.end_stage();
  hooks.begin_stage("FEM P" + std::to_string(rq.order) + " assembly and factorisation");
  const fem::DiscFem solver(m, materials, rq.order, fem::DiscFem::default_plate_center(m));
  hooks.end_stage(std::to_string(solver.num_dofs()) + " DOF");

  // 3. The protocol (calibration/compare.hpp).
  hooks.begin_stage("comparing " + std::to_string(rq.cases.size()) + " load cases");
  out.comparison = calibration::compare_mss_fem(solver, model, rq.cases, materials.name,
                                                mss::StaticOptions(), rq.load_scale);
  out.comparison.constants = out.choice.constants;
  hooks.end_stage();

  if (!rq.csv.empty()) write_csv_file(rq.csv, comparison_csv(out.comparison));
  out.json = comparison_json(out.comparison);
  out.json["mesh"] = rq.mesh_path;
  out.json["model_variant"] = out.choice.variant;
  if (!rq.model.params.empty()) out.json["params"] = rq.model.params;
  if (!rq.csv.empty()) out.json["csv"] = rq.csv;
  return out;
}

void print_mss_compare(std::ostream& os, const MssCompareRequest& rq, const MssCompareResult& r) {
  os << "MSS (" << r.choice.constants << ", " << r.choice.variant << ") vs FEM P" << rq.order
     << " on " << rq.mesh_path << " (" << r.nodes << " nodes, " << r.tets << " tets), material "
     << r.choice.materials.name
     << (rq.load_scale != 1.0 ? ", loads x " + std::to_string(rq.load_scale) : std::string())
     << "\n\n";
  print_comparison(os, r.comparison, false);
}

}  // namespace spinesim::studies

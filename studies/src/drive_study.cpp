#include "spinesim/studies/drive_study.hpp"
#include "spinesim/common/constants.hpp"
#include "spinesim/mss/simulator.hpp"

#include "spinesim/fem/disc_fem.hpp"
#include "spinesim/mss/boundary.hpp"
#include "spinesim/mss/quantities.hpp"
#include "spinesim/studies/fem_reference.hpp"
#include "spinesim/studies/toolkit.hpp"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <sstream>
#include <stdexcept>

namespace spinesim::studies {
namespace fs = std::filesystem;

std::vector<Keyframe> drive_schedule(double compression_mm, double flexion_deg, double time_scale) {
  const double c = -compression_mm, f = flexion_deg;
  std::vector<Keyframe> keys = {{0.0, 0, 0}, {0.2, c, 0}, {0.3, c, 0}, {0.5, c, f}, {0.6, c, f},
                                {0.8, c, 0}, {0.9, c, 0}, {1.1, 0, 0}, {1.2, 0, 0}};
  for (auto& k : keys) k.time_s *= time_scale;
  return keys;
}

mss::Vector6d schedule_motion(const std::vector<Keyframe>& keys, double t) {
  std::size_t i = 1;
  while (i + 1 < keys.size() && keys[i].time_s < t) ++i;
  const Keyframe &k0 = keys[i - 1], &k1 = keys[i];
  const double w = std::clamp((t - k0.time_s) / (k1.time_s - k0.time_s), 0.0, 1.0);
  mss::Vector6d q = mss::Vector6d::Zero();
  q(1) = k0.axial_mm + w * (k1.axial_mm - k0.axial_mm);
  q(3) = (k0.flexion_deg + w * (k1.flexion_deg - k0.flexion_deg)) * kRadPerDeg;
  return q;
}

void check(const DriveStudyRequest& rq) {
  check(rq.stepping);
  if (!std::isfinite(rq.compression_mm) || !std::isfinite(rq.flexion_deg))
    throw std::invalid_argument("--compression and --flexion must be finite numbers");
  if (!std::isfinite(rq.time_scale) || rq.time_scale <= 0)
    throw std::invalid_argument("--time-scale must be finite and > 0");
  if (rq.materials.empty()) throw std::invalid_argument("--materials: give at least one material");
}

std::string DriveStudyResult::diverged() const {
  std::string list;
  for (const auto& r : runs)
    if (r.stats.diverged) list += (list.empty() ? "" : ", ") + r.material;
  return list;
}

namespace {

/// Rotates a 6-vector of two 3-vectors by `r` (local -> global) or, given r^T, back.
mss::Vector6d rotate6(const Eigen::Matrix3d& r, const mss::Vector6d& v) {
  mss::Vector6d out;
  out << r * v.head<3>(), r * v.tail<3>();
  return out;
}

/// One material through the schedule; writes drive-<name>.pvd, its frames and drive-<name>.csv.
DriveRun drive_one(const mesh::TetMesh& m, const mesh::RegionMaterials& materials,
                   const SteppedStudyOptions& o, const std::vector<Keyframe>& keys) {
  const mss::MssModel model(m, materials, o.model);
  const Eigen::Vector3d center = fem::DiscFem::default_plate_center(m);
  const Eigen::Matrix3d& axes = m.frame.axes;
  DriveRun r;
  r.material = materials.name;
  r.e_annulus_mpa = materials.at(int(mesh::Region::annulus)).youngs_modulus_mpa;
  r.e_nucleus_mpa = materials.at(int(mesh::Region::nucleus)).youngs_modulus_mpa;
  r.damping_n_s_per_mm = model.damping_n_s_per_mm();
  r.steps = int(std::ceil(keys.back().time_s / o.dynamics.dt_s - 1e-6));

  SteppedRun run(model, o, "drive-" + file_stem(materials.name),
                 "time_s,tx_mm,ty_mm,tz_mm,rx_deg,ry_deg,rz_deg,Fx_n,Fy_n,Fz_n,Mx_nmm,My_nmm,"
                 "Mz_nmm,volume_mm3,volume_change,max_displacement_mm",
                 r.steps);
  for (int k = 1; k <= r.steps; ++k) {
    const mss::Vector6d q_local = schedule_motion(keys, k * o.dynamics.dt_s);
    const mss::Vector6d q = rotate6(axes, q_local);
    mss::Boundary bc;  // inferior (L3) fixed
    bc.superior = mss::plate_pose(q, center);
    bc.plate_center_mm = center;
    if (!run.step(k, bc)) break;
    const mss::State& s = run.state();
    const mss::Vector6d w =
        rotate6(axes.transpose(), mss::plate_reaction(model, s.x_mm, center + q.head<3>()));
    const double dv = mss::volume_change(model, s.x_mm);
    r.peak_force_n = std::max(r.peak_force_n, w.head<3>().norm());
    r.peak_axial_n = std::max(r.peak_axial_n, w(1));
    r.peak_moment_nmm = std::max(r.peak_moment_nmm, w.tail<3>().norm());
    r.volume_change.add(dv);
    const mss::Vector6d qd = motion_rad_to_deg(q_local);
    std::ostream& csv = run.csv();
    csv << s.time_s;
    for (int i = 0; i < 6; ++i) csv << "," << qd(i);
    for (int i = 0; i < 6; ++i) csv << "," << w(i);
    csv << "," << model.volume_mm3(s.x_mm) << "," << dv << ","
        << mss::max_displacement_mm(model, s.x_mm) << "\n";
  }
  run.finish();
  r.stats = run.stats();
  r.pvd_path = run.pvd_path();
  r.csv_path = run.csv_path();
  r.frames = run.num_frames();
  return r;
}

nlohmann::json run_json(const DriveRun& r) {
  nlohmann::json j = {{"material", r.material},
                      {"E_mpa_annulus", r.e_annulus_mpa},
                      {"E_mpa_nucleus", r.e_nucleus_mpa},
                      {"peak_force_n", r.peak_force_n},
                      {"peak_axial_force_n", r.peak_axial_n},
                      {"peak_moment_nmm", r.peak_moment_nmm},
                      {"max_volume_change", r.volume_change.extreme_or_zero()},
                      {"K_d_n_s_per_mm", r.damping_n_s_per_mm},
                      {"steps", r.steps},
                      {"files", {{"pvd", r.pvd_path}, {"csv", r.csv_path}}},
                      {"frames", r.frames}};
  r.stats.add_to(j);
  return j;
}

nlohmann::json drive_summary(const mesh::TetMesh& m, const DriveStudyResult& r) {
  const SteppedStudyOptions& o = r.request.stepping;
  nlohmann::json schedule = nlohmann::json::array();
  for (const auto& k : r.schedule)
    schedule.push_back(
        {{"time_s", k.time_s}, {"axial_mm", k.axial_mm}, {"flexion_deg", k.flexion_deg}});
  nlohmann::json runs = nlohmann::json::array();
  for (const auto& run : r.runs) runs.push_back(run_json(run));
  return {{"study", "drive"},
          {"thesis", "5.3 test 2, fig. 5.9"},
          {"mesh", study_mesh_json(m)},
          {"model_variant", o.model_variant},
          {"integrator", o.integrator_name},
          {"dt_s", o.dynamics.dt_s},
          {"frame", "disc (x lateral, y axial, z anterior); reaction about the moved plate centre"},
          {"schedule", schedule},
          {"materials", runs},
          {"diverged", !r.diverged().empty()},
          {"json", r.json_path}};
}

}  // namespace

DriveStudyResult run_drive_study(const mesh::TetMesh& m, const DriveStudyRequest& request,
                                 const StageHooks& hooks) {
  check(request);
  const SteppedStudyOptions& o = request.stepping;
  prepare_output_folder(o.out, "--out");
  DriveStudyResult r;
  r.request = request;
  r.schedule = drive_schedule(request.compression_mm, request.flexion_deg, request.time_scale);
  for (const auto& mat : request.materials) {
    hooks.begin_stage("material " + mat.name);
    r.runs.push_back(drive_one(m, mat, o, r.schedule));
    hooks.end_stage(std::to_string(r.runs.back().stats.steps_done) + " steps");
  }
  r.json_path = (fs::path(o.out) / "drive.json").string();
  r.summary = drive_summary(m, r);
  write_json_file(r.json_path, r.summary);
  return r;
}

void print_drive_study(std::ostream& os, const mesh::TetMesh& m, const DriveStudyResult& r) {
  const SteppedStudyOptions& o = r.request.stepping;
  os << "Drive study (thesis 5.3, test 2) on " << m.source << " (" << m.num_tets()
     << " tets): inferior endplate (L3) fixed, superior (L2) driven, disc frame (x lateral, y "
        "axial, z anterior), "
     << o.model_variant << " MSS, " << o.integrator_name << " Euler dt " << o.dynamics.dt_s
     << " s\n"
     << "  schedule (linear in between):\n";
  TextTable keys({"time (s)", "axial (mm)", "flexion (deg)"}, 0);
  for (const auto& k : r.schedule)
    keys.add({significant(k.time_s, 6), significant(k.axial_mm, 6), significant(k.flexion_deg, 6)});
  keys.print(os, false, "    ");

  TextTable t({"material", "E (MPa)", "peak |F| (N)", "peak Fy (N)", "peak |M| (N·mm)", "max dV/V0",
               "step (ms)", ""});
  for (const auto& run : r.runs) {
    std::ostringstream e;  // "4.2/1" when annulus and nucleus differ
    e << run.e_annulus_mpa;
    if (run.e_nucleus_mpa != run.e_annulus_mpa) e << "/" << run.e_nucleus_mpa;
    t.add({run.material, e.str(), significant(run.peak_force_n, 5),
           significant(run.peak_axial_n, 5), significant(run.peak_moment_nmm, 5),
           significant(100 * run.volume_change.extreme_or_zero(), 5) + "%",
           significant(run.stats.mean_seconds() * 1e3, 5), run.stats.diverged ? "DIVERGED" : ""});
  }
  os << "\n";
  t.print(os, false);
  os << "  wrote " << r.json_path << " and drive-<material>.{pvd,csv} in " << o.out << "\n";
}

}  // namespace spinesim::studies

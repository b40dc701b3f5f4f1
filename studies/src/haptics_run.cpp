#include "spinesim/studies/haptics_run.hpp"

#include "spinesim/haptics/hostile.hpp"
#include "spinesim/studies/spine_database.hpp"
#include "spinesim/studies/spine_solve.hpp"

#include "spinesim/common/atomic_file.hpp"
#include "spinesim/common/machine.hpp"
#include "spinesim/common/timer.hpp"
#include "spinesim/haptics/compliant_stage.hpp"
#include "spinesim/haptics/disc_palpation.hpp"
#include "spinesim/haptics/hostile.hpp"
#include "spinesim/haptics/recording.hpp"
#include "spinesim/haptics/renderer.hpp"
#include "spinesim/mesh/vertebra_geometry.hpp"
#include "spinesim/studies/disc_palpation_setup.hpp"
#include "spinesim/studies/toolkit.hpp"

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <memory>
#include <sstream>
#include <stdexcept>

namespace spinesim::studies {

namespace fs = std::filesystem;

std::string hostile_script_name(const std::string& script) {
  const std::string prefix = "hostile:";
  if (script.compare(0, prefix.size(), prefix) != 0) return {};
  const std::string name = script.substr(prefix.size());
  try {
    haptics::check_hostile_name(name);
  } catch (const std::invalid_argument& e) {
    throw std::invalid_argument("--script " + script + ": " + e.what());
  }
  return name;
}

std::string default_haptic_script(const std::string& scene, const std::string& data_dir) {
  const fs::path dir = fs::path(data_dir) / "haptics";
  if (scene == "plane") return (dir / "press_plane.csv").string();
  if (scene == "vertebra") return (dir / "press_lumbar.csv").string();
  if (scene == "disc") return (dir / "press_disc_l4l5.csv").string();
  return (dir / "stroke_spinous.csv").string();
}

namespace {

void check_twist_request(const HapticsRunRequest& r) {
  const double k = r.rotational_stiffness_nmm_per_rad;
  if (std::isnan(k)) return;  // the device's own
  if (!(k >= 0) || !std::isfinite(k))
    throw std::invalid_argument("--rotational-stiffness must be >= 0 N mm/rad");
  if (r.spine.empty())
    throw std::invalid_argument("--rotational-stiffness is for --spine multirate (a 6-DOF hook)");
}

}  // namespace

/// The disc scene's flags (one line for each refusal).
void check_disc_request(const HapticsRunRequest& r) {
  if (r.scene.scene != "disc" &&
      (!r.disc_params.empty() || r.disc_budget_us != 0 || r.disc_cell_size_mm != 0 ||
       r.disc_solver != "multirate" || r.disc_model != "mss" || r.disc_period_ms != 10 ||
       r.disc_sync_check))
    throw std::invalid_argument(
        "--params, --disc-solver, --disc-model, --disc-period-ms, --disc-budget-us, "
        "--disc-cell-size and --disc-sync-check are for --scene disc");
  if (r.disc_model != "mss" && r.disc_model != "fem")
    throw std::invalid_argument("--disc-model " + r.disc_model +
                                ": unknown (mss, the tuned mass-spring disc, or fem, its linear "
                                "FEM)");
  if (r.disc_solver != "multirate" && r.disc_solver != "direct")
    throw std::invalid_argument("--disc-solver " + r.disc_solver +
                                ": unknown (multirate or direct)");
  if (!(r.disc_period_ms >= 1 && r.disc_period_ms <= 10))
    throw std::invalid_argument("--disc-period-ms must be 1 to 10 ms");
  if (r.disc_solver == "direct" && (r.disc_period_ms != 10 || r.disc_sync_check))
    throw std::invalid_argument(
        "--disc-period-ms and --disc-sync-check are for --disc-solver multirate");
  if (!(r.disc_budget_us >= 0) || !std::isfinite(r.disc_budget_us))
    throw std::invalid_argument("--disc-budget-us must be >= 0 (0: the default)");
}

void check_haptics_request(const HapticsRunRequest& r) {
  check_scene_name(r.scene.scene);
  if (!(r.probe_radius_mm > 0) || !std::isfinite(r.probe_radius_mm) || r.probe_radius_mm > 100)
    throw std::invalid_argument("--probe-radius must be > 0 and at most 100 mm");
  if (r.renderer != "proxy" && r.renderer != "gao-gibson")
    throw std::invalid_argument("--renderer " + r.renderer + ": give proxy or gao-gibson");
  if (!(r.duration_s >= 0) || r.duration_s > 24 * 3600)
    throw std::invalid_argument("--duration must be 0 (the script's length) to 86400 s");
  if (!(r.spin_us >= 0) || r.spin_us > 900)
    throw std::invalid_argument("--spin-us must be 0 to 900 us");
  if (!(r.stiffness_n_per_mm >= 0) || !std::isfinite(r.stiffness_n_per_mm))
    throw std::invalid_argument("--stiffness must be >= 0 N/mm (0: the device's default)");
  if (r.device == "mouse" && !(r.live && r.live->pointer))
    throw std::invalid_argument(
        "--device mouse is the viewer's pointer: run it with spinesim view --device mouse");
  if (r.device != "sim" && r.device != "replay" && r.device != "null" &&
      r.device != "openhaptics" && r.device != "dhd" && r.device != "mouse")
    throw std::invalid_argument("--device " + r.device +
                                ": unknown (sim, replay, null, openhaptics, dhd; mouse in the "
                                "viewer)");
  if (r.view != "back" && r.view != "front")
    throw std::invalid_argument("--view " + r.view + ": give back or front");
  if (!r.sdk_library.empty() && r.device != "openhaptics" && r.device != "dhd")
    throw std::invalid_argument("--sdk-lib is for --device openhaptics or dhd");
  if (r.device == "openhaptics" || r.device == "dhd") {  // before anything slow
    const auto probe = r.device == "dhd" ? haptics::probe_dhd(r.sdk_library)
                                         : haptics::probe_openhaptics(r.sdk_library);
    if (!probe.loaded) throw std::runtime_error(probe.detail);
  }
  if (r.device == "replay" && r.replay.empty())
    throw std::invalid_argument("--device replay needs --replay REC.csv");
  if (r.device != "replay" && !r.replay.empty())
    throw std::invalid_argument("--replay is for --device replay");
  if (r.device != "sim" && !r.script.empty())
    throw std::invalid_argument("--script is for --device sim");
  hostile_script_name(r.script);  // an unknown hostile:NAME, before anything slow
  if (!r.spine.empty() && r.spine != "multirate" && r.spine != "database")
    throw std::invalid_argument("--spine " + r.spine + ": give multirate or database");
  if (r.posture != "standing" && r.posture != "seated")
    throw std::invalid_argument("--posture " + r.posture + ": give standing or seated");
  if (r.posture == "seated" && r.spine != "multirate")
    throw std::invalid_argument(
        "--posture seated needs --spine multirate (the displacement database is the standing "
        "spine's)");
  if (r.posture == "seated") spine::check_chair(r.chair);
  if (!r.spine.empty() && r.scene.scene != "spine")
    throw std::invalid_argument(
        "--spine needs --scene spine (the compliant stage drags the spine)");
  if (r.spine.empty() && r.scene.scene != "disc" && r.force_scale != 0)
    throw std::invalid_argument("--force-scale is for --spine multirate|database or --scene disc");
  if (r.spine.empty() && !r.database.empty())
    throw std::invalid_argument("--database is for --spine multirate|database");
  if (r.scene.rib_cage && r.scene.scene != "spine")
    throw std::invalid_argument("--rib-cage is for --scene spine");
  if (r.spine.empty() && r.scene.scene != "disc" &&
      (r.coupling_stiffness_n_per_mm != 0 || r.coupling_damping_n_s_per_mm != 0))
    throw std::invalid_argument(
        "--coupling-stiffness and --coupling-damping are for --spine or --scene disc");
  check_disc_request(r);
  if (!(r.force_scale >= 0) || !std::isfinite(r.force_scale))
    throw std::invalid_argument("--force-scale must be > 0 (0: the default)");
  check_twist_request(r);
  if (!(r.coupling_stiffness_n_per_mm >= 0) || !std::isfinite(r.coupling_stiffness_n_per_mm) ||
      !(r.coupling_damping_n_s_per_mm >= 0) || !std::isfinite(r.coupling_damping_n_s_per_mm))
    throw std::invalid_argument("--coupling-stiffness and --coupling-damping must be >= 0");
  if (r.scene.scene == "disc" && r.force_scale != 0 &&
      !(r.force_scale >= 1 && r.force_scale * haptics::device_model(r.model).peak_force_n <= 1000))
    throw std::invalid_argument(
        "--force-scale on the disc must be >= 1 and put at most 1000 N on the disc at the "
        "device's peak force");
  if (!r.spine.empty() && r.force_scale > 0) {
    // Both responses answer for the thesis's validated 600 N (3.3.5).
    const double peak = haptics::device_model(r.model).peak_force_n;
    if (r.force_scale * peak > 600 * (1 + 1e-9))
      throw std::invalid_argument("--force-scale " + fixed(r.force_scale, 1) + " puts " +
                                  fixed(r.force_scale * peak, 0) +
                                  " N on the spine at the device's peak force, beyond the 600 N "
                                  "the spine answers for");
  }
  if (!r.record.empty()) require_output_folder(r.record, "--record");
  if (!r.write_scene.empty() && !fs::is_directory(r.write_scene))
    throw std::invalid_argument("--write-scene " + r.write_scene + ": not an existing folder");
}

namespace {

// The renderer the request names, at the result's stiffness (samples the scene for Gao-Gibson).
std::unique_ptr<haptics::ForceRenderer> make_renderer(const HapticsRunRequest& request,
                                                      double stiffness, haptics::Scene& scene) {
  if (request.renderer == "proxy") {
    haptics::ProxyParameters p;
    p.radius_mm = request.probe_radius_mm;
    p.stiffness_n_per_mm = stiffness;
    return std::make_unique<haptics::SphereProxyRenderer>(p);
  }
  haptics::GaoGibsonParameters p;
  p.radius_mm = request.probe_radius_mm;
  p.stiffness = stiffness;
  p.sample_spacing_mm = std::min(0.25, request.probe_radius_mm / 8);
  scene.sample_surfaces(p.sample_spacing_mm);
  return std::make_unique<haptics::GaoGibsonRenderer>(p);
}

// The device the request names; a vendor device is mapped into the scene (view, centre).
std::unique_ptr<haptics::Device> make_device(const HapticsRunRequest& request,
                                             const haptics::DeviceCapabilities& caps,
                                             const haptics::Trajectory& trajectory,
                                             const Eigen::Vector3d& scene_center, double period_s,
                                             double duration_s, const Eigen::Vector3d& start) {
  if (request.device == "mouse")
    return haptics::make_mouse_device(*request.live->pointer, start, caps, period_s);
  if (request.device == "sim") return haptics::make_sim_device(trajectory, caps, period_s);
  if (request.device == "replay") return haptics::make_replay_device(trajectory, caps, period_s);
  if (request.device == "null")
    return haptics::make_null_device(scene_center + Eigen::Vector3d(0, 0, 150), caps, period_s,
                                     duration_s);
  auto vendor = request.device == "openhaptics"
                    ? haptics::make_openhaptics_device(caps, request.sdk_library)
                    : haptics::make_dhd_device(caps, request.sdk_library);
  const Eigen::Matrix3d R = request.view == "back"
                                ? Eigen::Matrix3d(Eigen::Vector3d(-1, 1, -1).asDiagonal())
                                : Eigen::Matrix3d::Identity();
  const Eigen::Vector3d c =
      request.workspace_center_mm.allFinite() ? request.workspace_center_mm : scene_center;
  return haptics::map_device(std::move(vendor), R, c);
}

// Where a mouse starts: 25 mm behind (posterior to) the scene's bodies, at their centre's height.
Eigen::Vector3d behind_the_scene(const haptics::Scene& scene) {
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(1e300), hi = -lo;
  for (int i = 0; i < scene.size(); ++i) {
    const Eigen::MatrixX3d& V = scene.body(i).tree.vertices();
    lo = lo.cwiseMin(V.colwise().minCoeff().transpose());
    hi = hi.cwiseMax(V.colwise().maxCoeff().transpose());
  }
  if (scene.size() == 0) return Eigen::Vector3d::Zero();
  const Eigen::Vector3d c = 0.5 * (lo + hi);
  return {c.x(), c.y(), lo.z() - 25};
}

// The scene's summary into the result, and its surfaces written when asked.
void describe_scene(const HapticsRunRequest& request, const HapticScene& scene,
                    HapticsRunResult* result) {
  result->scene_description = scene.description;
  result->bodies = scene.scene.size();
  result->triangles = scene.scene.triangle_count();
  result->scene_seconds = scene.seconds;
  result->scene_cached_bodies = scene.cached;
  result->registered = scene.registered;
  result->registration = scene.registration;
  for (int i = 0; !request.write_scene.empty() && i < scene.scene.size(); ++i) {
    const auto& tree = scene.scene.body(i).tree;
    mesh::write_obj((fs::path(request.write_scene) / (scene.scene.body(i).name + ".obj")).string(),
                    mesh::TriSurface{tree.vertices(), tree.triangles()},
                    scene.scene.body(i).name + " (" + scene.sources[std::size_t(i)] +
                        ") at the reference posture");
  }
}

// The compliant stage of a request: the spine model, the response and the stage.
struct CompliantSetup {
  std::unique_ptr<spine::SpineModel> model;
  std::unique_ptr<spine::DisplacementDatabase> database;
  std::unique_ptr<haptics::SpineResponse> response;
  std::unique_ptr<haptics::CompliantStage> stage;
};

/// The seated spine for the multirate stage: seated in the request's chair (spine::solve_seated),
/// then every hook solve recruits in the seated posture with the chair's contact forces of that
/// equilibrium and lets the contact springs answer the hook (one solve per update: the contact
/// rounds and the lean are those of the unloaded sitter).
void seat_for_haptics(const HapticsRunRequest& request, CompliantSetup& c,
                      haptics::MultirateOptions& o) {
  const spine::Sitter sitter = spine::load_sitter(*c.model);
  spine::SeatingOptions so;
  so.solve.recruit = request.spine_recruit;
  const spine::SeatedSolution seated = spine::solve_seated(*c.model, request.chair, sitter, {}, so);
  spine::SeatedModel sm = spine::seat_model(*c.model, request.chair, sitter, seated.pelvic_tilt_deg,
                                            seated.ischia_forward_mm);
  o.solve.posture = sm.posture;
  o.solve.recruitment_contact_forces = seated.spine.contact_force_n;
  *c.model = std::move(sm.model);
}

/// The hook's torsional spring (6-DOF): on a device with torque motors and a response that takes
/// moments, the requested stiffness (default: the device's usable one, within half its passive
/// limit), refused beyond the passive limit; otherwise none, with the reason in the result.
void set_torsion(const HapticsRunRequest& request, HapticsRunResult& result,
                 const haptics::SpineResponse& response, haptics::CouplingParameters& p) {
  const auto& caps = result.capabilities;
  const double limit = haptics::passive_rotational_stiffness_limit(caps, 1e-3);
  result.rotational_passive_limit_nmm_per_rad = limit;
  const double asked = request.rotational_stiffness_nmm_per_rad;
  if (!caps.renders_torque()) {
    result.twist_note = caps.senses_orientation ? "the " + caps.model +
                                                      " senses the stylus's turn but has no torque "
                                                      "motors: the hook holds no orientation"
                                                : "";
    return;
  }
  if (request.device == "openhaptics" || request.device == "dhd") {
    result.twist_note = "the " + request.device +
                        " backend drives three degrees of freedom (no orientation read, no "
                        "torque sent): the hook holds no orientation";
    return;
  }
  if (response.max_moment_nmm() <= 0) {
    result.twist_note = std::string("the ") + response.name() +
                        " spine knows forces only: the hook holds no orientation (use --spine "
                        "multirate)";
    return;
  }
  p.rotational_stiffness_nmm_per_rad =
      std::isnan(asked) ? std::min(caps.usable_rotational_stiffness_nmm_per_rad, 0.5 * limit)
                        : asked;
  if (p.rotational_stiffness_nmm_per_rad > limit)
    throw std::invalid_argument(
        "--rotational-stiffness " + fixed(p.rotational_stiffness_nmm_per_rad, 0) +
        " N mm/rad is beyond the device's passive limit (" + fixed(limit, 0) + " N mm/rad)");
  if (p.rotational_stiffness_nmm_per_rad == 0) result.twist_note = "--rotational-stiffness 0";
}

CompliantSetup make_compliant_stage(const HapticsRunRequest& request, const std::string& data_dir,
                                    const haptics::Scene& scene, HapticsRunResult& result) {
  CompliantSetup c;
  spine::ModelOptions options;
  options.rib_cage = request.scene.rib_cage;
  options.scoliosis = request.scene.scoliosis;
  options.subject = request.scene.subject;
  c.model = std::make_unique<spine::SpineModel>(spine::load_spine_model(data_dir, options));
  if (request.spine == "database") {
    const std::string path = request.database.empty()
                                 ? (fs::path(data_dir) / "spine" / "displacement_db.json").string()
                                 : request.database;
    c.database = std::make_unique<spine::DisplacementDatabase>(read_database(path));
    if (request.scene.scoliosis.cobb_deg != 0)
      throw std::invalid_argument(
          "--spine database with --scoliosis: the database is the straight spine's (use --spine "
          "multirate)");
    const spine::Subject asked = spine::resolve_subject(data_dir, request.scene.subject),
                         built = spine::resolve_subject(data_dir, c.database->info.model.subject);
    if (asked.height_m != built.height_m || asked.body_mass_kg != built.body_mass_kg ||
        asked.sex != built.sex)
      throw std::invalid_argument(path + " is the spine of a " + subject_text(built) +
                                  " body, not of the " + subject_text(asked) +
                                  " one asked for (use --spine multirate)");
    if (c.database->info.model.rib_cage != request.scene.rib_cage)
      throw std::invalid_argument(path +
                                  (request.scene.rib_cage
                                       ? " is a spine without a rib cage: build one with `spinesim "
                                         "spine database --rib-cage`"
                                       : " is the rib-caged spine's: add --rib-cage"));
    c.response = std::make_unique<haptics::DatabaseResponse>(*c.database);
  } else {
    haptics::MultirateOptions o;
    o.solve.recruit = request.spine_recruit;
    if (request.posture == "seated") seat_for_haptics(request, c, o);
    c.response = std::make_unique<haptics::MultirateSpine>(*c.model, o);
  }
  const double peak = result.capabilities.peak_force_n;
  const double most = c.response->max_force_n();
  haptics::CouplingParameters p;
  p.force_scale = request.force_scale > 0 ? request.force_scale : most / peak;
  if (p.force_scale * peak > most * (1 + 1e-9))
    throw std::invalid_argument("--force-scale " + fixed(p.force_scale, 1) + " puts " +
                                fixed(p.force_scale * peak, 0) +
                                " N on the spine at the device's peak force, beyond the " +
                                fixed(most, 0) + " N the " + request.spine + " spine answers for");
  p.stiffness_n_per_mm = request.coupling_stiffness_n_per_mm > 0
                             ? request.coupling_stiffness_n_per_mm
                             : result.stiffness_n_per_mm;
  if (p.stiffness_n_per_mm > result.passive_limit_n_per_mm)
    throw std::invalid_argument("--coupling-stiffness " + fixed(p.stiffness_n_per_mm, 2) +
                                " N/mm is beyond the device's passive limit (" +
                                fixed(result.passive_limit_n_per_mm, 2) + " N/mm)");
  p.damping_n_s_per_mm = request.coupling_damping_n_s_per_mm;
  set_torsion(request, result, *c.response, p);
  std::vector<Eigen::Vector3d> centres;
  std::array<int, haptics::kSpineVertebrae> body_of{};
  for (int i = 0; i < haptics::kSpineVertebrae; ++i) {
    centres.push_back(c.model->vertebrae[std::size_t(i)].centre_mm);
    body_of[std::size_t(i)] = scene.index(spine::vertebra_names()[std::size_t(i)]);
  }
  c.stage = std::make_unique<haptics::CompliantStage>(*c.response, centres, body_of, p);
  if (c.model->rib_cage) {
    std::vector<int> ribs;
    for (const spine::Rib& rib : c.model->rib_cage->ribs) ribs.push_back(scene.index(rib.name));
    ribs.push_back(scene.index("sternum"));
    c.stage->attach_rib_cage(*c.model->rib_cage, c.model->vertebrae, ribs);
  }
  result.spine = request.spine;
  result.force_scale = p.force_scale;
  result.coupling_stiffness_n_per_mm = p.stiffness_n_per_mm;
  result.rotational_stiffness_nmm_per_rad =
      c.stage->twists() ? p.rotational_stiffness_nmm_per_rad : 0;
  result.spine_max_force_n = most;
  return c;
}

void finish_compliant(CompliantSetup& c, HapticsRunResult* result) {
  c.response->stop();
  if (auto* m = dynamic_cast<haptics::MultirateSpine*>(c.response.get())) {
    const auto& st = m->stats();
    result->worker_solves = st.solves;
    result->worker_failures = st.failures;
    result->worker_update_ms = 1e3 * st.mean_update_s;
    result->worker_rate_hz = st.mean_update_s > 0 ? 1.0 / st.mean_update_s : 0;
    result->worker_error = st.last_error;
  }
}

/// The disc's load at the device's peak force by default (N): a palpating hand's hundred newtons
/// indent the anterior wall by a few millimetres (docs/benchmarks.md).
constexpr double kDiscLoadAtPeakN = 100;

/// The disc scene's disc, at the finest resolution that fits the budget, coupled at the request's
/// stiffness (default: the rendering stiffness, within the device's passive limit).
DiscSetup make_disc(const HapticsRunRequest& request, const std::string& data_dir,
                    HapticsRunResult& result) {
  DiscSceneRequest d;
  d.level = request.scene.level;
  d.params = request.disc_params;
  d.disc_model = request.disc_model;
  const bool multirate = request.disc_solver == "multirate";
  d.palpation.multirate = multirate;
  d.palpation.dt_s = multirate ? 1e-3 * request.disc_period_ms : 1e-3;
  d.budget_us = request.disc_budget_us > 0 ? request.disc_budget_us
                : multirate                ? 800 * request.disc_period_ms
                                           : 500;
  if (multirate) {  // the FEM reference's resolution: >= 20,000 tets
    d.cell_sizes_mm = {1.5, 2.0, 2.5, 3.0};
    d.min_tets = 20000;
  }
  const double peak = result.capabilities.peak_force_n;
  d.palpation.force_scale =
      request.force_scale > 0 ? request.force_scale : std::max(1.0, kDiscLoadAtPeakN / peak);
  d.fixed_cell_size_mm = request.disc_cell_size_mm;
  d.cache_dir = request.scene.cache_dir == "none" ? "" : request.scene.cache_dir;
  d.palpation.coupling_stiffness_n_per_mm = request.coupling_stiffness_n_per_mm > 0
                                                ? request.coupling_stiffness_n_per_mm
                                                : result.stiffness_n_per_mm;
  if (d.palpation.coupling_stiffness_n_per_mm > result.passive_limit_n_per_mm)
    throw std::invalid_argument("--coupling-stiffness " +
                                fixed(d.palpation.coupling_stiffness_n_per_mm, 2) +
                                " N/mm is beyond the device's passive limit (" +
                                fixed(result.passive_limit_n_per_mm, 2) + " N/mm)");
  // The static FEM disc keeps none of the hand's work: its held-for-a-tick spring would give back
  // a little more than it took, so its coupling gets Colgate & Brown's damping k_c T / 2 unless
  // one is given (the mass-spring disc's implicit steps dissipate more than that by themselves).
  d.palpation.coupling_damping_n_s_per_mm =
      request.coupling_damping_n_s_per_mm > 0 || request.disc_model != "fem"
          ? request.coupling_damping_n_s_per_mm
          : 0.5 * d.palpation.coupling_stiffness_n_per_mm * 1e-3;
  d.palpation.probe_radius_mm = request.probe_radius_mm;
  d.palpation.realtime_priority = request.realtime_priority;
  DiscSetup setup = make_disc_setup(d, data_dir);
  result.disc_level = d.level;
  result.disc_tets = setup.chosen.tets;
  result.disc_cell_size_mm = setup.chosen.cell_size_mm;
  result.disc_tuned_file = setup.tuned_file;
  result.disc_note = setup.note;
  result.disc_candidates = setup.tried;
  result.coupling_stiffness_n_per_mm = d.palpation.coupling_stiffness_n_per_mm;
  result.coupling_damping_n_s_per_mm = d.palpation.coupling_damping_n_s_per_mm;
  result.force_scale = d.palpation.force_scale;
  result.request.disc_budget_us = d.budget_us;
  return setup;
}

/// The hand's path and the disc force it met, per tick (for --disc-sync-check).
struct DiscTrace {
  std::vector<Eigen::Vector3d> device_mm, force_n;
  void append(const haptics::TickRecord* rows, std::size_t n) {
    for (std::size_t i = 0; i < n; ++i) {
      device_mm.push_back(rows[i].probe_mm);
      force_n.push_back(rows[i].disc_contact ? Eigen::Vector3d(rows[i].disc_force_n.cast<double>())
                                             : Eigen::Vector3d::Zero());
    }
  }
};

/// The live run's disc force against the disc stepped every tick off the clock along the same
/// hand path (the synchronous solve).
void sync_check(const DiscSetup& d, const DiscTrace& trace, double T, HapticsRunResult* result) {
  const Timer timer;
  haptics::DiscPalpationOptions o = d.palpation->options();
  o.multirate = false;
  o.dt_s = T;
  const std::vector<Eigen::Vector3d> reference =
      haptics::palpate_offline(d.make_disc, o, trace.device_mm, T);
  result->sync_error = haptics::force_error(trace.force_n, reference);
  result->sync_ticks = std::int64_t(reference.size());
  result->sync_seconds = timer.seconds();
}

void finish_disc(DiscSetup& d, HapticsRunResult* result) {
  d.palpation->stop();
  const auto& st = d.palpation->stats();
  result->disc_steps = st.steps;
  result->disc_overruns = st.overruns;
  result->disc_dropped_periods = st.dropped_periods;
  result->disc_failed_steps = st.failed_steps;
  result->disc_step_us = haptics::percentiles(st.step_us);
  result->disc_max_force_n = st.max_force_n;
  result->disc_volume_change_min = st.min_volume_change;
  result->disc_volume_change_max = st.max_volume_change;
  result->disc_max_indentation_mm = st.max_indentation_mm;
  result->disc_rate_hz = result->stats.seconds > 0 ? double(st.steps) / result->stats.seconds : 0;
  result->disc_thread = st.realtime_reason;
}

// The --record file, fed by the loop's writer thread (null without --record), and the disc trace
// (when not null).
std::unique_ptr<haptics::HapticRecordingWriter> start_recording(const HapticsRunRequest& request,
                                                                const HapticsRunResult& result,
                                                                const spine::SpineModel* model,
                                                                bool disc, DiscTrace* trace,
                                                                haptics::ServoLoop& loop) {
  if (request.record.empty()) {
    if (trace)
      loop.record_to(
          [trace](const haptics::TickRecord* rows, std::size_t n) { trace->append(rows, n); },
          1 << 13);
    return nullptr;
  }
  std::ostringstream what;
  what << "device " << request.device << ", renderer " << request.renderer << ", probe radius "
       << request.probe_radius_mm << " mm";
  if (disc)
    what << "; disc " << result.disc_level << " (" << result.disc_tets << " tets, "
         << result.disc_tuned_file << ")";
  auto record = std::make_unique<haptics::HapticRecordingWriter>(
      request.record, what.str(), model, request.spine, disc,
      result.capabilities.senses_orientation);
  haptics::HapticRecordingWriter* sink = record.get();
  loop.record_to(
      [sink, trace](const haptics::TickRecord* rows, std::size_t n) {
        sink->append(rows, n);
        if (trace) trace->append(rows, n);
      },
      1 << 13);
  return record;
}

std::string floor_line(const HapticsRunResult& r) {
  if (r.floor.wakeups == 0) return "";
  const auto& s = r.stats;
  const double missed = s.ticks ? 100.0 * double(s.missed_deadlines) / double(s.ticks) : 0;
  return "  the machine's floor in the same run (a bare periodic thread): " +
         std::to_string(r.floor.late) + " of " + std::to_string(r.floor.wakeups) +
         " wake-ups a period late (" + fixed(r.floor.late_percent, 2) + " %; the loop " +
         fixed(missed, 2) + " %), wake-up latency p99 " + fixed(r.floor.latency_us.p99, 0) +
         " us, max " + fixed(r.floor.latency_us.max, 0) + " us\n";
}

}  // namespace

namespace {

// The scripted or replayed hand (empty for a hostile script, which needs the scene first).
haptics::Trajectory read_hand_trajectory(const HapticsRunRequest& request,
                                         const std::string& data_dir, HapticsRunResult* result) {
  if (request.device == "sim" && hostile_script_name(request.script).empty()) {
    result->request.script = request.script.empty()
                                 ? default_haptic_script(request.scene.scene, data_dir)
                                 : request.script;
    return haptics::read_trajectory(result->request.script);
  }
  if (request.device == "replay") return haptics::read_trajectory(request.replay);
  return {};
}

double run_duration(const HapticsRunRequest& request, const haptics::Trajectory& trajectory,
                    double T) {
  if (request.duration_s != 0) return request.duration_s;
  return request.device == "null"    ? 10.0
         : request.device == "mouse" ? 3600.0  // until the window closes
                                     : trajectory.duration_s() + T;
}

}  // namespace

HapticsRunResult run_haptics(const HapticsRunRequest& request, const std::string& data_dir,
                             const std::function<void(const haptics::ServoStatus&)>& status,
                             const std::function<void(int, int)>& scene_progress) {
  const Timer startup;
  check_haptics_request(request);
  HapticsRunResult result;
  result.request = request;
  result.capabilities = haptics::device_model(request.model);
  const double T = 1e-3;
  // Files are read (and refused) before the scene is built.
  haptics::Trajectory trajectory = read_hand_trajectory(request, data_dir, &result);
  HapticScene scene = build_haptic_scene(request.scene, data_dir, scene_progress);
  const std::string hostile = hostile_script_name(request.script);
  if (!hostile.empty()) trajectory = haptics::hostile_trajectory(hostile, scene.scene);
  const double duration = run_duration(request, trajectory, T);
  result.request.duration_s = duration;
  describe_scene(request, scene, &result);
  result.passive_limit_n_per_mm = haptics::passive_stiffness_limit(result.capabilities, T);
  result.stiffness_n_per_mm = request.stiffness_n_per_mm > 0
                                  ? request.stiffness_n_per_mm
                                  : std::min(result.capabilities.usable_stiffness_n_per_mm,
                                             0.5 * result.passive_limit_n_per_mm);
  const auto rigid = make_renderer(request, result.stiffness_n_per_mm, scene.scene);
  DiscSetup disc;
  std::unique_ptr<haptics::DiscCouplingRenderer> coupled;
  if (request.scene.scene == "disc") {
    disc = make_disc(request, data_dir, result);
    coupled = std::make_unique<haptics::DiscCouplingRenderer>(*rigid, *disc.palpation);
  }
  haptics::ForceRenderer& renderer = coupled ? *coupled : *rigid;
  const Eigen::Vector3d start = behind_the_scene(scene.scene);
  const auto device =
      make_device(request, result.capabilities, trajectory, scene.center_mm, T, duration, start);
  device->open();

  haptics::TripleBuffer<haptics::ScenePoses> poses{haptics::ScenePoses{}};
  haptics::ServoOptions options;
  options.period_s = T;
  options.duration_s = duration;
  options.realtime_priority = request.realtime_priority;
  options.spin_us = request.spin_us;
  haptics::ServoLoop loop(*device, renderer, scene.scene, poses,
                          haptics::SafetyOptions::for_device(result.capabilities), options);
  CompliantSetup compliant;
  if (!request.spine.empty()) {
    compliant = make_compliant_stage(request, data_dir, scene.scene, result);
    loop.set_compliant_stage(compliant.stage.get());
    compliant.response->start();
  }
  DiscTrace trace;
  const std::unique_ptr<haptics::HapticRecordingWriter> record =
      start_recording(request, result, compliant.model.get(), disc.palpation != nullptr,
                      request.disc_sync_check ? &trace : nullptr, loop);

  if (request.live && request.live->ready)
    request.live->ready({scene, disc.model.get(), result.disc_level, result.capabilities,
                         result.stiffness_n_per_mm, request.probe_radius_mm, request.device,
                         request.spine, start,
                         disc.palpation ? disc.palpation->disc().name() : ""});
  if (disc.palpation) disc.palpation->start();
  int calls = 0;
  HapticsLiveFrame live;
  result.startup_seconds = startup.seconds();
  haptics::LatencyProbe floor;
  if (request.measure_floor)
    floor.start(T, request.realtime_priority, haptics::ServoOptions{}.priority, duration + 1);
  result.stats = loop.run([&](const haptics::ServoStatus& s, double now) {
    haptics::ScenePoses p;  // the rigid stage's bodies stay at the reference posture
    p.time_s = now;
    poses.write(p);
    if (request.stop && request.stop->load()) loop.request_stop();
    if (status && ++calls % 10 == 0) status(s);
    if (request.live && request.live->frame) {
      live.status = s;
      live.loop_time_s = now;
      if (disc.palpation) live.disc_x_mm = disc.palpation->latest_positions();
      request.live->frame(live);
    }
  });
  result.floor = floor.stop();
  device->close();
  if (compliant.response) finish_compliant(compliant, &result);
  if (disc.palpation) {
    finish_disc(disc, &result);
    if (coupled) result.disc_stale_ticks = coupled->stale_ticks();
    if (request.disc_sync_check) sync_check(disc, trace, T, &result);
  }
  if (request.stop && request.stop->load())
    result.stats.stop_reason = request.live ? "window closed" : "interrupted";
  if (result.stats.error && !device->last_error().empty())
    result.stats.stop_reason += ": " + device->last_error();
  if (record) {
    const std::string& why = result.stats.stop_reason;
    const bool clean = why == "duration" || why == "device finished" || why == "window closed";
    record->finish(clean ? "" : why);
    result.recorded_rows = record->rows();
  }
  return result;
}

namespace {

nlohmann::json disc_json(const HapticsRunResult& r) {
  if (r.disc_level.empty()) return nlohmann::json();
  nlohmann::json tried = nlohmann::json::array();
  for (const auto& c : r.disc_candidates)
    tried.push_back({{"cell_size_mm", c.cell_size_mm},
                     {"tets", c.tets},
                     {"step_us", {{"p50", c.step_us.p50}, {"p99", c.step_us.p99}}},
                     {"step_cpu_us", {{"p50", c.step_cpu_us.p50}, {"p99", c.step_cpu_us.p99}}},
                     {"judged_cpu_us", c.judged_cpu_us},
                     {"fits", c.fits}});
  const auto& p = r.disc_step_us;
  const bool multi = r.request.disc_solver == "multirate";
  nlohmann::json sync;
  if (r.sync_ticks > 0)
    sync = {{"ticks", r.sync_ticks},
            {"seconds", r.sync_seconds},
            {"reference", "the disc stepped every 1 ms along the recorded hand path"},
            {"peak_force_n", r.sync_error.peak_n},
            {"rms_error_n", r.sync_error.rms_n},
            {"max_error_n", r.sync_error.max_n},
            {"relative_rms_error", r.sync_error.relative_rms()},
            {"relative_max_error", r.sync_error.relative_max()}};
  return {
      {"level", r.disc_level},
      {"solver", r.request.disc_solver},
      {"model", r.request.disc_model == "fem" ? "linear FEM" : "mass-spring"},
      {"period_ms", multi ? r.request.disc_period_ms : 1.0},
      {"rate_hz", r.disc_rate_hz},
      {"stale_ticks", r.disc_stale_ticks},
      {"force_scale", r.force_scale},
      {"max_load_n", r.disc_max_force_n},
      {"max_indentation_mm", r.disc_max_indentation_mm},
      {"sync_check", sync},
      {"tets", r.disc_tets},
      {"cell_size_mm", r.disc_cell_size_mm},
      {"tuned", r.disc_tuned_file},
      {"cpu", cpu_description()},
      {"thread", multi ? "own thread at 1/period; the servo evaluates its local contact model "
                         "every tick"
                       : "own thread at 1 kHz behind a virtual coupling"},
      {"thread_priority", r.disc_thread},
      {"budget_us", r.request.disc_budget_us},
      {"budget_check", tried},
      {"note", r.disc_note},
      {"coupling_stiffness_n_per_mm", r.coupling_stiffness_n_per_mm},
      {"coupling_damping_n_s_per_mm", r.coupling_damping_n_s_per_mm},
      {"steps", r.disc_steps},
      {"overruns", r.disc_overruns},
      {"dropped_periods", r.disc_dropped_periods},
      {"failed_steps", r.disc_failed_steps},
      {"step_us", {{"p50", p.p50}, {"p99", p.p99}, {"p999", p.p999}, {"max", p.max}}},
      {"max_contact_force_n", r.disc_max_force_n},
      {"volume_change", {{"min", r.disc_volume_change_min}, {"max", r.disc_volume_change_max}}}};
}

}  // namespace

nlohmann::json haptics_run_json(const HapticsRunResult& r) {
  const auto& s = r.stats;
  auto pct = [](const haptics::Percentiles& p) {
    return nlohmann::json{{"p50", p.p50}, {"p99", p.p99}, {"p999", p.p999}, {"max", p.max}};
  };
  return {{"scene", r.request.scene.scene},
          {"scene_description", r.scene_description},
          {"bodies", r.bodies},
          {"triangles", r.triangles},
          {"scene_seconds", r.scene_seconds},
          {"scene_cached_bodies", r.scene_cached_bodies},
          {"startup_seconds", r.startup_seconds},
          {"vertebrae", r.request.scene.vertebrae},
          {"registration", r.registered ? registration_json(r.registration) : nlohmann::json()},
          {"device", r.request.device},
          {"model", r.capabilities.model},
          {"renderer", r.request.renderer},
          {"probe_radius_mm", r.request.probe_radius_mm},
          {"stiffness_n_per_mm", r.stiffness_n_per_mm},
          {"passive_stiffness_limit_n_per_mm", r.passive_limit_n_per_mm},
          {"script", r.request.script},
          {"duration_s", r.request.duration_s},
          {"ticks", s.ticks},
          {"seconds", s.seconds},
          {"rate_hz", s.rate_hz},
          {"period_us", pct(s.period_us)},
          {"compute_us", pct(s.compute_us)},
          {"missed_deadlines", s.missed_deadlines},
          {"floor", r.floor.wakeups == 0
                        ? nlohmann::json(nullptr)
                        : nlohmann::json{{"wakeups", r.floor.wakeups},
                                         {"latency_us", pct(r.floor.latency_us)},
                                         {"late", r.floor.late},
                                         {"late_percent", r.floor.late_percent},
                                         {"realtime_priority", r.floor.realtime_priority},
                                         {"what",
                                          "a bare periodic thread beside the servo: wake-ups more "
                                          "than one period late (cyclictest's measure)"}}},
          {"max_force_n", s.max_force_n},
          {"peak_force_n", r.capabilities.peak_force_n},
          {"six_dof",
           !r.capabilities.senses_orientation
               ? nlohmann::json(nullptr)
               : nlohmann::json{{"torque_axes", r.capabilities.torque_axes},
                                {"peak_torque_nmm", r.capabilities.peak_torque_nmm},
                                {"continuous_torque_nmm", r.capabilities.continuous_torque_nmm},
                                {"max_torque_nmm", s.max_torque_nmm},
                                {"torque_clamped_ticks", s.torque_clamped_ticks},
                                {"torque_limited_ticks", s.torque_limited_ticks}}},
          {"clamped_ticks", s.clamped_ticks},
          {"limited_ticks", s.limited_ticks},
          {"non_finite_ticks", s.non_finite_ticks},
          {"fading_ticks", s.fading_ticks},
          {"contact_ticks", s.contact_ticks},
          {"truncated_ticks", s.truncated_ticks},
          {"max_render_work", s.max_render_work},
          {"passivity_energy_mj", {{"min", s.passivity_min_mj}, {"final", s.passivity_final_mj}}},
          {"realtime_priority", {{"enabled", s.realtime_priority}, {"reason", s.realtime_reason}}},
          {"spin_us", r.request.spin_us},
          {"stop_reason", s.stop_reason},
          {"record", r.request.record},
          {"recorded_rows", r.recorded_rows},
          {"compliant_stage",
           r.spine.empty()
               ? nlohmann::json()
               : nlohmann::json{{"spine", r.spine},
                                {"posture", r.request.posture},
                                {"rib_cage", r.request.scene.rib_cage},
                                {"force_scale", r.force_scale},
                                {"coupling_stiffness_n_per_mm", r.coupling_stiffness_n_per_mm},
                                {"spine_max_force_n", r.spine_max_force_n},
                                {"hooked_ticks", s.hooked_ticks},
                                {"max_spine_force_n", s.max_spine_force_n},
                                {"spine_clamped_ticks", s.spine_clamped_ticks},
                                {"rotational_stiffness_nmm_per_rad",
                                 r.rotational_stiffness_nmm_per_rad},
                                {"rotational_passive_limit_nmm_per_rad",
                                 r.rotational_passive_limit_nmm_per_rad},
                                {"max_spine_moment_nmm", s.max_spine_moment_nmm},
                                {"twist_note", r.twist_note},
                                {"worker_solves", r.worker_solves},
                                {"worker_failures", r.worker_failures},
                                {"worker_update_ms", r.worker_update_ms},
                                {"worker_rate_hz", r.worker_rate_hz},
                                {"worker_error", r.worker_error}}},
          {"disc_palpation", disc_json(r)}};
}

std::string haptics_run_table(const HapticsRunResult& r) {
  const auto& s = r.stats;
  std::ostringstream os;
  os << "  scene      " << r.scene_description << " (" << r.bodies << " bodies, " << r.triangles
     << " triangles, built in " << fixed(r.scene_seconds, 1) << " s"
     << (r.scene_cached_bodies ? ", " + std::to_string(r.scene_cached_bodies) + " from the cache"
                               : std::string())
     << "; first tick " << fixed(r.startup_seconds, 1) << " s after the start)\n"
     << "  device     " << r.request.device << " (" << r.capabilities.description << ", peak "
     << fixed(r.capabilities.peak_force_n, 2) << " N)\n"
     << "  renderer   " << r.request.renderer << ", probe radius "
     << fixed(r.request.probe_radius_mm, 1) << " mm, stiffness " << fixed(r.stiffness_n_per_mm, 2)
     << " N/mm (passive up to " << fixed(r.passive_limit_n_per_mm, 2) << ")\n"
     << (r.registered ? "  registered real L1-S1 to the model: residual rms " +
                            fixed(r.registration.rms_mm, 1) + " mm\n"
                      : std::string())
     << "  real time  " << (s.realtime_priority ? "yes" : "no") << ": " << s.realtime_reason
     << "\n\n";
  TextTable t({"", "p50", "p99", "p99.9", "max"});
  auto row = [&](const std::string& name, const haptics::Percentiles& p) {
    t.add({name, fixed(p.p50, 1), fixed(p.p99, 1), fixed(p.p999, 1), fixed(p.max, 1)});
  };
  row("period (us)", s.period_us);
  row("compute (us)", s.compute_us);
  t.print(os, false);
  os << "\n  " << s.ticks << " ticks in " << fixed(s.seconds, 2) << " s (" << fixed(s.rate_hz, 1)
     << " Hz), " << s.missed_deadlines << " missed deadlines, stopped: " << s.stop_reason << "\n"
     << floor_line(r) << "  force: max " << fixed(s.max_force_n, 3) << " N; contact "
     << s.contact_ticks << " ticks, clamped " << s.clamped_ticks << ", limited " << s.limited_ticks
     << ", faded " << s.fading_ticks << "\n"
     << "  passivity energy: min " << fixed(s.passivity_min_mj, 3) << " mJ, final "
     << fixed(s.passivity_final_mj, 3) << " mJ\n";
  if (!r.spine.empty()) {
    os << "  spine: " << r.spine << " (" << r.request.posture << "), force scale "
       << fixed(r.force_scale, 1) << " (spine N per felt N), coupling "
       << fixed(r.coupling_stiffness_n_per_mm, 2) << " N/mm; hooked " << s.hooked_ticks
       << " ticks, spine force max " << fixed(s.max_spine_force_n, 1) << " N (clamped "
       << s.spine_clamped_ticks << ")\n";
    if (r.rotational_stiffness_nmm_per_rad > 0)
      os << "  twist: torsional spring " << fixed(r.rotational_stiffness_nmm_per_rad, 0)
         << " N mm/rad felt (passive up to " << fixed(r.rotational_passive_limit_nmm_per_rad, 0)
         << "); spine moment max " << fixed(s.max_spine_moment_nmm / 1000, 2)
         << " N m, torque on the hand max " << fixed(s.max_torque_nmm, 1) << " N mm (peak "
         << fixed(r.capabilities.peak_torque_nmm, 0) << "; clamped " << s.torque_clamped_ticks
         << ", limited " << s.torque_limited_ticks << ")\n";
    else if (!r.twist_note.empty())
      os << "  twist: none (" << r.twist_note << ")\n";
    if (r.spine == "multirate")
      os << "  worker: " << r.worker_solves << " updates, " << fixed(r.worker_update_ms, 1)
         << " ms each (" << fixed(r.worker_rate_hz, 1) << " Hz), " << r.worker_failures << " failed"
         << (r.worker_error.empty() ? "" : ": " + r.worker_error) << "\n";
  }
  if (!r.disc_level.empty()) {
    const auto& p = r.disc_step_us;
    const bool multi = r.request.disc_solver == "multirate";
    const std::string period = multi ? fixed(r.request.disc_period_ms, 0) + " ms" : "1 ms";
    os << "  disc: " << r.disc_level << ", "
       << (r.request.disc_model == "fem" ? "the linear FEM disc" : "the tuned mass-spring disc")
       << ", " << r.disc_tets << " tets (CGAL " << fixed(r.disc_cell_size_mm, 1) << " mm, "
       << r.disc_tuned_file << "), "
       << (multi ? "stepped every " + period + ", its local contact model felt every tick"
                 : std::string("stepped every tick"))
       << "; coupling " << fixed(r.coupling_stiffness_n_per_mm, 2) << " N/mm felt, force scale "
       << fixed(r.force_scale, 1) << " disc N per felt N\n"
       << "  disc step (us): p50 " << fixed(p.p50, 0) << ", p99 " << fixed(p.p99, 0) << ", max "
       << fixed(p.max, 0) << "; " << r.disc_steps << " steps (" << fixed(r.disc_rate_hz, 1)
       << " Hz), " << r.disc_overruns << " overran the " << period << " (" << r.disc_dropped_periods
       << " periods dropped), " << r.disc_failed_steps << " rejected"
       << (multi ? ", " + std::to_string(r.disc_stale_ticks) + " stale ticks" : "") << "; on "
       << cpu_description() << "\n"
       << "  disc: load max " << fixed(r.disc_max_force_n, 1) << " N, indentation max "
       << fixed(r.disc_max_indentation_mm, 2) << " mm, volume change "
       << fixed(100 * r.disc_volume_change_min, 3) << " .. "
       << fixed(100 * r.disc_volume_change_max, 3) << " %\n";
    if (r.sync_ticks > 0)
      os << "  against the synchronous solve (1 ms steps, " << r.sync_ticks << " ticks, "
         << fixed(r.sync_seconds, 1) << " s): force RMS error " << fixed(r.sync_error.rms_n, 2)
         << " N (" << fixed(100 * r.sync_error.relative_rms(), 2) << " % of the "
         << fixed(r.sync_error.peak_n, 1) << " N peak), max " << fixed(r.sync_error.max_n, 2)
         << " N (" << fixed(100 * r.sync_error.relative_max(), 2) << " %)\n";
    if (!r.disc_note.empty()) os << "  note: " << r.disc_note << "\n";
  }
  if (!r.request.record.empty())
    os << "  recorded " << r.recorded_rows << " ticks to " << r.request.record << "\n";
  return os.str();
}

std::string missed_deadlines_warning(const HapticsRunResult& r, double max_missed_percent) {
  const auto& s = r.stats;
  if (s.ticks <= 0) return "";
  const double percent = 100.0 * double(s.missed_deadlines) / double(s.ticks);
  if (!(percent > max_missed_percent)) return "";
  return std::to_string(s.missed_deadlines) + " of " + std::to_string(s.ticks) +
         " deadlines missed (" + fixed(percent, 2) + " %, more than the " +
         fixed(max_missed_percent, 2) + " % allowed): the loop did not hold its rate here (" +
         fixed(s.rate_hz, 1) + " Hz" +
         (r.floor.wakeups ? "; the machine's own floor in the same run: " +
                                fixed(r.floor.late_percent, 2) + " % of a bare thread's wake-ups"
                          : std::string()) +
         ")";
}

nlohmann::json haptic_devices_json(const std::string& openhaptics_lib, const std::string& dhd_lib) {
  nlohmann::json backends = nlohmann::json::array();
  backends.push_back({{"name", "sim"},
                      {"available", true},
                      {"devices", 1},
                      {"detail", "a simulated hand holding the device (scripted set-point)"}});
  backends.push_back({{"name", "replay"},
                      {"available", true},
                      {"devices", 1},
                      {"detail", "plays a --record file"}});
  backends.push_back(
      {{"name", "null"}, {"available", true}, {"devices", 1}, {"detail", "stays at one point"}});
  for (const auto& p : {haptics::probe_openhaptics(openhaptics_lib), haptics::probe_dhd(dhd_lib)})
    backends.push_back({{"name", p.name},
                        {"available", p.loaded},
                        {"library", p.library},
                        {"devices", p.devices},
                        {"detail", p.detail}});
  nlohmann::json models = nlohmann::json::array();
  for (const auto& m : haptics::device_models())
    models.push_back(
        {{"model", m.model},
         {"description", m.description},
         {"workspace_mm", {m.workspace_mm.x(), m.workspace_mm.y(), m.workspace_mm.z()}},
         {"peak_force_n", m.peak_force_n},
         {"continuous_force_n", m.continuous_force_n},
         {"usable_stiffness_n_per_mm", m.usable_stiffness_n_per_mm},
         {"physical_damping_n_s_per_mm", m.physical_damping_n_s_per_mm},
         {"passive_stiffness_limit_at_1khz_n_per_mm", haptics::passive_stiffness_limit(m, 1e-3)},
         {"senses_orientation", m.senses_orientation},
         {"torque_axes", m.torque_axes},
         {"peak_torque_nmm", m.peak_torque_nmm},
         {"continuous_torque_nmm", m.continuous_torque_nmm},
         {"usable_rotational_stiffness_nmm_per_rad", m.usable_rotational_stiffness_nmm_per_rad},
         {"rotational_damping_nmm_s_per_rad", m.rotational_damping_nmm_s_per_rad},
         {"source", m.source}});
  return {{"backends", backends}, {"models", models}};
}

std::string haptic_devices_table(const std::string& openhaptics_lib, const std::string& dhd_lib) {
  std::ostringstream os;
  os << "backends (all built in; the vendor libraries are loaded when used):\n";
  TextTable b({"backend", "usable", "devices", "detail"}, 4);
  const nlohmann::json all = haptic_devices_json(openhaptics_lib, dhd_lib);
  for (const auto& j : all["backends"]) {
    const int n = j["devices"].get<int>();
    b.add({j["name"].get<std::string>(), j["available"].get<bool>() ? "yes" : "no",
           n < 0 ? "?" : std::to_string(n), one_line(j["detail"].get<std::string>())});
  }
  b.print(os, false);
  os << "\n";
  TextTable t({"model", "workspace mm", "peak N", "cont. N", "stiffness N/mm", "passive limit N/mm",
               "DOF", "peak torque N mm"});
  for (const auto& m : haptics::device_models())
    t.add({m.model,
           fixed(m.workspace_mm.x(), 0) + " x " + fixed(m.workspace_mm.y(), 0) + " x " +
               fixed(m.workspace_mm.z(), 0),
           fixed(m.peak_force_n, 2), fixed(m.continuous_force_n, 2),
           fixed(m.usable_stiffness_n_per_mm, 2),
           fixed(haptics::passive_stiffness_limit(m, 1e-3), 1),
           !m.senses_orientation ? "3"
           : m.renders_torque()  ? "6"
                                 : "6 (3 forced)",
           m.renders_torque() ? fixed(m.peak_torque_nmm, 0) : "-"});
  t.print(os, false);
  return os.str();
}

}  // namespace spinesim::studies

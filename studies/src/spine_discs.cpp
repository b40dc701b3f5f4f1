#include "spinesim/studies/spine_discs.hpp"
#include "spinesim/common/constants.hpp"

#include "spinesim/common/timer.hpp"
#include "spinesim/haptics/hybrid_spine.hpp"
#include "spinesim/mesh/disc_geometry.hpp"
#include "spinesim/mesh/disc_level.hpp"
#include "spinesim/mss/boundary.hpp"
#include "spinesim/mss/quantities.hpp"
#include "spinesim/mss/simulator.hpp"
#include "spinesim/mss/solver.hpp"
#include "spinesim/spine/kinematics.hpp"
#include "spinesim/studies/data.hpp"
#include "spinesim/studies/spine_solve.hpp"
#include "spinesim/studies/toolkit.hpp"
#include "spinesim/studies/vertebra_surfaces.hpp"

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <sstream>
#include <stdexcept>
#include <thread>

namespace spinesim::studies {
namespace fs = std::filesystem;

namespace {

int vertebra_index(const spine::SpineModel& model, const std::string& name) {
  for (std::size_t i = 0; i < model.vertebrae.size(); ++i)
    if (model.vertebrae[i].name == name) return int(i);
  return -1;  // the sacrum
}

std::string mesh_label(const calibration::MeshFingerprint& f) {
  return std::to_string(f.tets) + " tets, fingerprint " + f.hash;
}

using haptics::HybridDisc;
using haptics::SegmentState;

/// The poses of the 17 vertebrae T1 … L5 in a recorded frame.
std::vector<spine::Pose> frame_poses(const spine::SpineModel& m, const DragFrame& f) {
  std::vector<spine::Pose> poses(m.vertebrae.size());
  for (std::size_t i = 0; i < poses.size(); ++i) poses[i] = f.pose(m, int(i));
  return poses;
}

void add_to_peaks(const SegmentState& s, DiscPeaks& p) {
  p.compression_mm = std::max(p.compression_mm, -s.shift_mm.y());
  p.shear_mm = std::max(p.shear_mm, std::hypot(s.shift_mm.x(), s.shift_mm.z()));
  p.rotation_deg = std::max(p.rotation_deg, s.rotation_deg.norm());
  p.volume_change_min = std::min(p.volume_change_min, s.volume_change);
  p.volume_change_max = std::max(p.volume_change_max, s.volume_change);
  p.inverted_tets = std::max(p.inverted_tets, s.inverted_tets);
  p.force_n = std::max(p.force_n, s.force_n.norm());
  p.moment_nmm = std::max(p.moment_nmm, s.moment_nmm.norm());
}

/// The 17 discs as one mesh (for one VTU per frame), with each cell's disc index.
struct CombinedDiscs {
  mesh::TetMesh mesh;
  Eigen::VectorXd disc;
  std::vector<Eigen::Index> first_vertex;
};

CombinedDiscs combine(const SpineDiscs& discs) {
  CombinedDiscs c;
  Eigen::Index nv = 0, nt = 0;
  for (const auto& m : discs.models) nv += m.mesh().num_vertices(), nt += m.mesh().num_tets();
  c.mesh.V.resize(nv, 3), c.mesh.T.resize(nt, 4), c.mesh.region.resize(nt);
  c.mesh.surface.resize(nv), c.disc.resize(nt);
  c.mesh.source = "the 17 structured discs of the spine";
  Eigen::Index v0 = 0, t0 = 0;
  for (std::size_t i = 0; i < discs.models.size(); ++i) {
    const mesh::TetMesh& m = discs.models[i].mesh();
    c.first_vertex.push_back(v0);
    c.mesh.V.middleRows(v0, m.num_vertices()) = m.V;
    c.mesh.surface.segment(v0, m.num_vertices()) = m.surface;
    c.mesh.T.middleRows(t0, m.num_tets()) = m.T.array() + int(v0);
    c.mesh.region.segment(t0, m.num_tets()) = m.region;
    c.disc.segment(t0, m.num_tets()).setConstant(double(i));
    v0 += m.num_vertices(), t0 += m.num_tets();
  }
  return c;
}

void write_discs_frame(const std::string& path, CombinedDiscs& c, const mss::DiscSet& set) {
  const Eigen::Index nt = c.mesh.num_tets();
  Eigen::MatrixXd displacement(c.mesh.num_vertices(), 3), volume(nt, 1), strain(nt, 1);
  Eigen::Index t0 = 0;
  for (int i = 0; i < set.size(); ++i) {
    const mss::MssModel& m = set.model(i);
    const Eigen::VectorXd& x = set.state(i).x_mm;
    const Eigen::Index v0 = c.first_vertex[std::size_t(i)], n = m.num_nodes();
    const Eigen::MatrixX3d u = mss::displacement(m, x);
    displacement.middleRows(v0, n) = u;
    c.mesh.V.middleRows(v0, n) = m.mesh().V + u;
    const Eigen::Index k = m.mesh().num_tets();
    volume.middleRows(t0, k) = mss::tet_volume_change(m, x);
    strain.middleRows(t0, k) = mss::tet_edge_strain(m, x);
    t0 += k;
  }
  mesh::write_vtu(path, c.mesh, {{"displacement", displacement}},
                  {{"volume_change", volume}, {"spring_strain", strain}, {"disc", c.disc}},
                  {mesh::VtuEncoding::zlib});
}

/// The vertebrae's poses in a curved spine's rest posture; none for a straight spine.
std::vector<spine::Pose> rest_poses(const spine::SpineModel& m) {
  return m.rest_posture.size() > 0 ? spine::vertebra_poses(m, m.rest_posture)
                                   : std::vector<spine::Pose>();
}

/// The vertebra surfaces as one surface, each body's vertices in a block.
struct CombinedVertebrae {
  mesh::TriSurface rest, moved;
  Eigen::MatrixXd body;
  std::vector<int> vertebra;  ///< per body: index in the spine model (-1: the sacrum)
  std::vector<Eigen::Index> first, count;
};

CombinedVertebrae combine(const VertebraSurfacesResult& s, const spine::SpineModel& m) {
  CombinedVertebrae c;
  const std::vector<spine::Pose> rest = rest_poses(m);
  Eigen::Index nv = 0, nf = 0;
  for (const auto& b : s.surfaces) nv += b.surface.V.rows(), nf += b.surface.F.rows();
  c.rest.V.resize(nv, 3), c.rest.F.resize(nf, 3), c.body.resize(nf, 1);
  Eigen::Index v0 = 0, f0 = 0;
  for (std::size_t i = 0; i < s.surfaces.size(); ++i) {
    const mesh::TriSurface& b = s.surfaces[i].surface;
    c.vertebra.push_back(vertebra_index(m, s.surfaces[i].name));
    c.first.push_back(v0), c.count.push_back(b.V.rows());
    c.rest.V.middleRows(v0, b.V.rows()) = m.scale.length * b.V;  // the body's vertebrae
    if (!rest.empty() && c.vertebra.back() >= 0) {               // a curve's rest posture
      const spine::Pose& p = rest[std::size_t(c.vertebra.back())];
      for (Eigen::Index k = v0; k < v0 + b.V.rows(); ++k)
        c.rest.V.row(k) = (p.R * c.rest.V.row(k).transpose() + p.t).transpose();
    }
    c.rest.F.middleRows(f0, b.F.rows()) = b.F.array() + int(v0);
    c.body.middleRows(f0, b.F.rows()).setConstant(double(i));
    v0 += b.V.rows(), f0 += b.F.rows();
  }
  c.moved = c.rest;
  return c;
}

void write_vertebrae_frame(const std::string& path, CombinedVertebrae& c,
                           const std::vector<spine::Pose>& poses) {
  for (std::size_t b = 0; b < c.vertebra.size(); ++b) {
    const spine::Pose p = c.vertebra[b] < 0 ? spine::Pose() : poses[std::size_t(c.vertebra[b])];
    for (Eigen::Index k = c.first[b]; k < c.first[b] + c.count[b]; ++k)
      c.moved.V.row(k) = p.apply(c.rest.V.row(k).transpose()).transpose();
  }
  mesh::write_surface_vtu(path, c.moved, {}, {{"body", c.body}}, {mesh::VtuEncoding::zlib});
}

std::string motion_header(const std::string& recording) {
  return "# the hybrid spine's discs over " + recording +
         ": the upper plate centre's displacement and the rotation vector relative to the lower "
         "vertebra, in the disc's axes (x lateral, y axial, z anterior), the volume change "
         "(V-V0)/V0, inverted tets, and the reaction on the upper plate about its centre\n"
         "t_s,level,dx_mm,dy_mm,dz_mm,rx_deg,ry_deg,rz_deg,volume_change,inverted_tets,fx_n,fy_n,"
         "fz_n,mx_nmm,my_nmm,mz_nmm\n";
}

/// One frame of the series: the discs (part 0) and, if given, the vertebrae (part 1).
void add_frame(VtuSeries& series, CombinedDiscs& discs, const mss::DiscSet& set,
               CombinedVertebrae* vertebrae, double t_s, const std::vector<spine::Pose>& poses) {
  series.add(t_s, 0, [&](const std::string& p) { write_discs_frame(p, discs, set); });
  if (vertebrae)
    series.add(t_s, 1, [&](const std::string& p) { write_vertebrae_frame(p, *vertebrae, poses); });
}

void check(const SpineDiscsRequest& r) {
  if (r.recording.empty())
    throw std::invalid_argument("--record: give a compliant-stage recording");
  if (!(r.frame_period_s > 0) || !std::isfinite(r.frame_period_s))
    throw std::invalid_argument("--frame-period must be a finite number of seconds > 0");
  if (r.vertebra_triangles != 0 && (r.vertebra_triangles < 100 || r.vertebra_triangles > 200000))
    throw std::invalid_argument("--vertebra-triangles must be 0 (none) or 100 to 200000");
  if (r.threads < 0 || r.threads > 64)
    throw std::invalid_argument("--threads must be 0 (one per core) to 64");
  if (r.newton_iterations < 1 || r.newton_iterations > 50)
    throw std::invalid_argument("--newton-iterations must be 1 to 50");
  if (r.out.empty()) throw std::invalid_argument("--out: give an output folder");
}

/// Starts every disc at its static equilibrium at the first recorded posture.
void start_at_equilibrium(const spine::SpineModel& m, const std::vector<HybridDisc>& runs,
                          const SpineDiscs& discs, const DragFrame& first, mss::DiscSet& set) {
  for (std::size_t i = 0; i < runs.size(); ++i) {
    const mss::StaticResult eq =
        mss::solve_static(*runs[i].model, haptics::disc_boundary(runs[i], frame_poses(m, first)));
    if (!eq.converged || !eq.x_mm.allFinite())
      throw std::runtime_error(discs.levels[i] +
                               ": no static equilibrium at the first recorded posture (" +
                               eq.message + ")");
    mss::State s;
    s.x_mm = eq.x_mm;
    s.v_mm_s = Eigen::VectorXd::Zero(eq.x_mm.size());
    s.time_s = first.t_s;
    set.set_state(int(i), s);
  }
}

/// The implicit Euler of the offline discs: one recorded tick a step.
mss::DynamicsOptions disc_dynamics(const SpineDiscsRequest& request) {
  mss::DynamicsOptions dyn;
  dyn.integrator = mss::Integrator::implicit_euler;
  dyn.dt_s = 1e-3;  // one recorded tick
  dyn.newton_iterations = request.newton_iterations;
  dyn.matrix_update =
      request.refactorize ? mss::MatrixUpdate::every_iteration : mss::MatrixUpdate::frozen;
  return dyn;
}

/// The discs added to `set`, coupled to their vertebrae; the result's per-disc rows begun.
std::vector<HybridDisc> add_discs(const SpineDiscs& discs, const mss::DynamicsOptions& dyn,
                                  mss::DiscSet& set, SpineDiscsResult& r) {
  std::vector<HybridDisc> runs;
  for (std::size_t i = 0; i < discs.models.size(); ++i) set.add(discs.models[i], dyn);
  for (int i = 0; i < set.size(); ++i) {
    runs.push_back({&set.model(i), mss::default_plate_center(set.model(i).mesh()),
                    discs.upper[std::size_t(i)], discs.lower[std::size_t(i)]});
    r.tets += long(set.model(i).mesh().num_tets());
    r.peaks.push_back({});
    r.peaks.back().level = discs.levels[std::size_t(i)];
  }
  return runs;
}

void motion_row(std::ostream& os, double t, const std::string& level, const SegmentState& s) {
  char line[512];
  std::snprintf(line, sizeof line,
                "%.3f,%s,%.5f,%.5f,%.5f,%.5f,%.5f,%.5f,%.6f,%ld,%.4f,%.4f,%.4f,%.3f,%.3f,%.3f\n", t,
                level.c_str(), s.shift_mm.x(), s.shift_mm.y(), s.shift_mm.z(), s.rotation_deg.x(),
                s.rotation_deg.y(), s.rotation_deg.z(), s.volume_change, s.inverted_tets,
                s.force_n.x(), s.force_n.y(), s.force_n.z(), s.moment_nmm.x(), s.moment_nmm.y(),
                s.moment_nmm.z());
  os << line;
}

std::string table_csv(const SpineDiscsResult& r) {
  std::ostringstream os;
  os << "# the hybrid spine's discs over " << r.request.recording
     << ": peaks in the disc's axes (compression = shortening of its axis)\n"
        "level,peak_compression_mm,peak_shear_mm,peak_rotation_deg,volume_change_min,"
        "volume_change_max,inverted_tets_max,peak_force_n,peak_moment_nmm,rejected_steps\n";
  for (const DiscPeaks& p : r.peaks) {
    char line[256];
    std::snprintf(line, sizeof line, "%s,%.5f,%.5f,%.5f,%.6f,%.6f,%ld,%.4f,%.3f,%d\n",
                  p.level.c_str(), p.compression_mm, p.shear_mm, p.rotation_deg,
                  p.volume_change_min, p.volume_change_max, p.inverted_tets, p.force_n,
                  p.moment_nmm, p.rejected_steps);
    os << line;
  }
  return os.str();
}

}  // namespace

std::string spine_discs_params_path(const std::string& params, const std::string& data_dir) {
  return calibration::tuned_set_path(
      params,
      {{"real-disc", calibration::shipped_structured_tuned_set_path(data_dir)},
       {"fibre-reinforced", calibration::shipped_structured_fibre_tuned_set_path(data_dir)}});
}

SpineDiscs build_spine_discs(const spine::SpineModel& model, const calibration::TunedSet& tuned) {
  const mesh::StructuredDiscOptions options = calibration::structured_resolution(tuned);
  const std::string resolution = std::to_string(options.sectors) + " sectors x " +
                                 std::to_string(options.rings) + " rings x " +
                                 std::to_string(options.layers) + " layers";
  SpineDiscs d;
  d.resolution = resolution;
  const std::vector<spine::Pose> rest = rest_poses(model);
  auto rest_motion = [&](int vertebra) {  // the sacrum (-1) never moves
    return vertebra < 0
               ? mesh::RigidMotion()
               : mesh::RigidMotion{rest[std::size_t(vertebra)].R, rest[std::size_t(vertebra)].t};
  };
  for (const std::string& level : mesh::disc_levels()) {
    const calibration::TunedDisc& entry = calibration::tuned_level(tuned, level);
    mesh::TetMesh m = mesh::mesh_structured_level(level, options, studies::data_dir());
    const calibration::MeshFingerprint here = calibration::fingerprint(m);
    if (!(entry.mesh == here))
      throw std::invalid_argument(
          level + ": its tuned parameters were fitted on another mesh (" + mesh_label(entry.mesh) +
          ") than the structured disc simulated (" + resolution + ", " + mesh_label(here) +
          "): calibrate the structured discs with `spinesim calibrate --level all --structured`");
    d.levels.push_back(level);
    // Another body's disc is the reference disc scaled (geometric similarity, as its spine is):
    // the tuned scales were fitted on the reference mesh; springs and masses follow the scaled
    // geometry.
    m.V *= model.scale.length;
    m.frame.origin_mm *= model.scale.length;
    const std::size_t dash = level.find('-');
    d.upper.push_back(vertebra_index(model, level.substr(0, dash)));
    d.lower.push_back(vertebra_index(model, level.substr(dash + 1)));
    if (d.upper.back() < 0)
      throw std::invalid_argument(level + ": its upper vertebra is not in the spine model");
    // A curved spine's disc rests wedged between its vertebrae's rest poses (the recorded motions
    // start there); its springs are stress-free in that shape, as the spine's joints are.
    if (!rest.empty())
      mesh::carry_between(
          m, m.frame,
          model.scale.length * mesh::disc_dimensions(level, studies::data_dir()).height_mm,
          rest_motion(d.lower.back()), rest_motion(d.upper.back()));
    d.models.push_back(calibration::build_tuned_model(entry, m, entry.materials()));
  }
  return d;
}

SpineDiscsResult run_spine_discs(const SpineDiscsRequest& request, const std::string& data_dir,
                                 const std::function<void(int, int)>& progress) {
  // 1. Everything checked before anything is written.
  check(request);
  Timer total;
  SpineDiscsResult r;
  r.request = request;
  spine::ModelOptions body;  // the recorded spine's body (the reference when not recorded)
  const haptics::RecordedSpine recorded = haptics::recording_spine(request.recording);
  body.subject = recorded.subject;
  body.scoliosis = recorded.scoliosis;
  const spine::SpineModel model = spine::load_spine_model(data_dir, body);
  r.subject = model.subject;
  r.scoliosis = model.scoliosis;
  const DragRecording rec = read_drag_recording(request.recording, model);
  r.fingerprint = rec.fingerprint;
  r.recording_complete = rec.complete;
  r.recording_incomplete = rec.incomplete_reason;
  const std::string tuned_path = spine_discs_params_path(request.tuned, data_dir);
  const SpineDiscs discs = build_spine_discs(model, calibration::read_tuned_set(tuned_path));
  r.resolution = discs.resolution;
  VertebraSurfacesResult surfaces;
  if (request.vertebra_triangles > 0) {
    VertebraSurfacesRequest vs;
    vs.triangles = request.vertebra_triangles;
    surfaces = make_vertebra_surfaces(vs, data_dir);
  }

  prepare_output_folder(request.out, "--out");  // made once every input is read and checked

  // 2. The discs, started at equilibrium.
  const mss::DynamicsOptions dyn = disc_dynamics(request);
  if (r.request.threads == 0)
    r.request.threads = int(std::max(1u, std::min(17u, std::thread::hardware_concurrency())));
  mss::DiscSet set(r.request.threads);
  const std::vector<HybridDisc> runs = add_discs(discs, dyn, set, r);
  r.discs = set.size();
  start_at_equilibrium(model, runs, discs, rec.frames.front(), set);

  // 3. Step through the recording; frames and rows every frame period.
  r.pvd = (fs::path(request.out) / "spine.pvd").string();
  VtuSeries series(r.pvd);
  CombinedDiscs all_discs = combine(discs);
  CombinedVertebrae all_vertebrae = combine(surfaces, model);
  std::ostringstream motion;
  motion << motion_header(request.recording);
  std::vector<mss::Boundary> bcs(runs.size());
  std::vector<SegmentState> samples(runs.size());
  double next_frame = -INFINITY;
  const int n = int(rec.frames.size());
  for (int k = 0; k < n; ++k) {
    const DragFrame& f = rec.frames[std::size_t(k)];
    const std::vector<spine::Pose> poses = frame_poses(model, f);
    for (std::size_t i = 0; i < runs.size(); ++i) bcs[i] = haptics::disc_boundary(runs[i], poses);
    if (k > 0) {
      Timer step;
      const std::vector<mss::StepReport>& reports = set.step(bcs);
      r.stepping_s += step.seconds();
      ++r.steps;
      for (std::size_t i = 0; i < reports.size(); ++i)
        if (!reports[i].ok) ++r.peaks[i].rejected_steps;
    }
    const bool frame = f.t_s >= next_frame || k == n - 1;
    Timer measuring;
    set.for_each([&](int i) {
      samples[std::size_t(i)] =
          haptics::segment_state(runs[std::size_t(i)], bcs[std::size_t(i)], set.state(i).x_mm);
    });
    for (std::size_t i = 0; i < runs.size(); ++i) {
      add_to_peaks(samples[i], r.peaks[i]);
      if (frame) motion_row(motion, f.t_s, discs.levels[i], samples[i]);
    }
    r.measuring_s += measuring.seconds();
    if (frame) {
      next_frame = f.t_s + request.frame_period_s;
      add_frame(series, all_discs, set, request.vertebra_triangles > 0 ? &all_vertebrae : nullptr,
                f.t_s, poses);
      ++r.frames;
    }
    if (progress && (k % 100 == 0 || k == n - 1)) progress(k + 1, n);
  }
  r.simulated_s = r.steps * dyn.dt_s;

  // 4. The series, the tables.
  series.finish();
  r.table_csv = (fs::path(request.out) / "discs.csv").string();
  r.motion_csv = (fs::path(request.out) / "disc_motion.csv").string();
  r.json = (fs::path(request.out) / "discs.json").string();
  write_csv_file(r.table_csv, table_csv(r));
  write_csv_file(r.motion_csv, motion.str());
  r.total_s = total.seconds();
  r.diverged = spine_discs_diverged(r);
  write_json_file(r.json, spine_discs_json(r), 1);
  return r;
}

std::string spine_discs_diverged(const SpineDiscsResult& r) {
  // No disc reacts with more than a body's weight many times over; 1e5 N is far beyond any.
  constexpr double kMaxPhysicalForceN = 1e5;
  for (const DiscPeaks& p : r.peaks) {
    if (p.rejected_steps > 0)
      return p.level + ": " + std::to_string(p.rejected_steps) + " steps rejected (diverged)";
    if (p.inverted_tets > 0)
      return p.level + ": " + std::to_string(p.inverted_tets) + " tetrahedra inside out";
    if (!(p.force_n <= kMaxPhysicalForceN) || !std::isfinite(p.moment_nmm))
      return p.level + ": a reaction of " + significant(p.force_n, 3) + " N, beyond any disc's";
  }
  return "";
}

nlohmann::json spine_discs_json(const SpineDiscsResult& r) {
  nlohmann::json discs = nlohmann::json::array();
  for (const DiscPeaks& p : r.peaks)
    discs.push_back({{"level", p.level},
                     {"peak_compression_mm", p.compression_mm},
                     {"peak_shear_mm", p.shear_mm},
                     {"peak_rotation_deg", p.rotation_deg},
                     {"volume_change_min", p.volume_change_min},
                     {"volume_change_max", p.volume_change_max},
                     {"inverted_tets_max", p.inverted_tets},
                     {"peak_force_n", p.force_n},
                     {"peak_moment_nmm", p.moment_nmm},
                     {"rejected_steps", p.rejected_steps}});
  return {{"recording", r.request.recording},
          {"recording_complete", r.recording_complete},
          {"recording_incomplete", r.recording_incomplete},
          {"diverged", !r.diverged.empty()},
          {"diverged_reason", r.diverged},
          {"spine_model", r.fingerprint},
          {"subject", subject_json(r.subject)},
          {"scoliosis", scoliosis_curve_json(r.scoliosis)},
          {"tuned", r.request.tuned.empty() ? "real-disc" : r.request.tuned},
          {"resolution", r.resolution},
          {"integrator", "implicit Euler"},
          {"dt_s", 1e-3},
          {"newton_iterations", r.request.newton_iterations},
          {"threads", r.request.threads},
          {"discs", r.discs},
          {"tets", r.tets},
          {"steps", r.steps},
          {"frames", r.frames},
          {"simulated_s", r.simulated_s},
          {"matrix_update", r.request.refactorize ? "every iteration" : "frozen"},
          {"stepping_s", r.stepping_s},
          {"measuring_s", r.measuring_s},
          {"speedup_with_measurements", r.speedup_measured()},
          {"total_s", r.total_s},
          {"speedup_over_real_time", r.speedup()},
          {"pvd", r.pvd},
          {"table_csv", r.table_csv},
          {"motion_csv", r.motion_csv},
          {"per_disc", discs}};
}

std::string spine_discs_table(const SpineDiscsResult& r) {
  std::ostringstream os;
  os << "The hybrid spine offline: " << r.discs << " tuned structured discs (" << r.resolution
     << ", " << r.tets << " tets; " << (r.request.tuned.empty() ? "real-disc" : r.request.tuned)
     << "), implicit Euler at 1 ms, " << r.steps << " steps of " << r.request.recording
     << (r.recording_complete ? "" : " (not whole: " + r.recording_incomplete + ")") << "\n"
     << "stepping " << fixed(r.stepping_s, 2) << " s for " << fixed(r.simulated_s, 2)
     << " s simulated: " << fixed(r.speedup(), 2) << "x real time ("
     << (r.request.refactorize ? "refactorised" : "frozen matrix") << ", " << r.request.threads
     << (r.request.threads == 1 ? " thread" : " threads") << "); with the per-step reactions "
     << "and volumes " << fixed(r.speedup_measured(), 2) << "x; total " << fixed(r.total_s, 1)
     << " s\n";
  if (r.scoliosis.cobb_deg != 0)
    os << "the spine rests in a " << fixed(r.scoliosis.cobb_deg, 0) << " deg " << r.scoliosis.type
       << " scoliosis (" << r.scoliosis.upper_end << "-" << r.scoliosis.lower_end << ", apex "
       << r.scoliosis.apex << "): each disc rests wedged between its vertebrae in the curve\n";
  os << "\n";
  TextTable t({"disc", "compression (mm)", "shear (mm)", "rotation (deg)", "volume change (%)",
               "inverted", "force (N)", "moment (N·m)", "rejected"});
  for (const DiscPeaks& p : r.peaks)
    t.add({p.level, fixed(p.compression_mm, 3), fixed(p.shear_mm, 3), fixed(p.rotation_deg, 2),
           fixed(100 * p.volume_change_min, 2) + " .. " + fixed(100 * p.volume_change_max, 2),
           std::to_string(p.inverted_tets), fixed(p.force_n, 1), fixed(p.moment_nmm / 1000, 2),
           std::to_string(p.rejected_steps)});
  t.print(os, false);
  os << "\nwrote " << r.pvd << " (" << r.frames << " frames), " << r.table_csv << ", "
     << r.motion_csv << ", " << r.json << "\n";
  return os.str();
}

}  // namespace spinesim::studies

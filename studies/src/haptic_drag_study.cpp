#include "spinesim/studies/haptic_drag_study.hpp"
#include "spinesim/common/constants.hpp"

#include "spinesim/common/timer.hpp"
#include "spinesim/haptics/recording.hpp"
#include "spinesim/spine/database.hpp"
#include "spinesim/spine/kinematics.hpp"
#include "spinesim/studies/toolkit.hpp"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <sstream>
#include <stdexcept>

namespace spinesim::studies {

using haptics::DragFrame;
using haptics::DragRecording;
using haptics::read_drag_recording;

namespace fs = std::filesystem;

namespace {

constexpr int kVertebrae = 17;

ErrorPercentiles percentiles_of(std::vector<double> v) {
  ErrorPercentiles p;
  if (v.empty()) return p;
  std::sort(v.begin(), v.end());
  auto rank = [&](double q) {
    return v[std::min(v.size() - 1, std::size_t(std::ceil(q * double(v.size()))) - 1)];
  };
  p.p50 = rank(0.5);
  p.p95 = rank(0.95);
  p.max = v.back();
  return p;
}

/// The motion from the gravity-only displacement `base` to `direct` of vertebra i: centre
/// displacement (mm) and rotation (matrix).
spine::Pose relative_motion(const spine::SpineModel& m, const spine::VertebraResponse& base,
                            const spine::VertebraResponse& direct, int i) {
  const Eigen::Vector3d& c = m.vertebrae[std::size_t(i)].centre_mm;
  auto pose = [&](const spine::VertebraResponse& d) {
    return spine::pose_from_displacement(c, d.row(i).head<3>().transpose(),
                                         d.row(i).tail<3>().transpose());
  };
  const spine::Pose a = pose(base), b = pose(direct);
  spine::Pose r;
  r.R = b.R * a.R.transpose();
  r.t = b.t - r.R * a.t;
  return r;
}

/// Compares the recorded motions with direct solves at sampled hooked ticks.
void measure_pose_error(const spine::SpineModel& m, const DragRecording& rec,
                        const HapticDragRequest& request, bool at_centre, DragMethodResult& out) {
  std::vector<const DragFrame*> picked;
  double next = -1;
  for (const DragFrame& f : rec.frames)
    if (f.attached && f.hook_vertebra >= 0 && f.spine_force_n.norm() >= request.min_force_n &&
        f.t_s >= next) {
      picked.push_back(&f);
      next = f.t_s + request.sample_every_s;
    }
  std::vector<std::vector<spine::ExternalLoad>> loads = {{}};  // case 0: gravity only
  for (const DragFrame* f : picked) {
    spine::ExternalLoad l;
    l.vertebra = f->hook_vertebra;
    l.force_n = f->spine_force_n;
    l.has_point = !at_centre;
    l.point_mm = f->hook_ref_mm;
    loads.push_back({l});
  }
  std::vector<spine::VertebraResponse> direct;
  std::vector<std::string> errors;
  spine::solve_cases(m, loads, spine::SolveOptions(), 0, direct, errors);
  if (!errors[0].empty()) throw std::runtime_error("the gravity-only solve failed: " + errors[0]);
  std::array<std::vector<double>, kVertebrae> et, er, ep;
  for (std::size_t k = 0; k < picked.size(); ++k) {
    if (!errors[k + 1].empty()) {
      ++out.failed_solves;
      continue;
    }
    const DragFrame& f = *picked[k];
    const Eigen::Vector3d& ch = m.vertebrae[std::size_t(f.hook_vertebra)].centre_mm;
    const double hook_motion =
        (relative_motion(m, direct[0], direct[k + 1], f.hook_vertebra).apply(ch) - ch).norm();
    out.hook_motion_max_mm = std::max(out.hook_motion_max_mm, hook_motion);
    for (int i = 0; i < kVertebrae; ++i) {
      const Eigen::Vector3d& c = m.vertebrae[std::size_t(i)].centre_mm;
      const spine::Pose d = relative_motion(m, direct[0], direct[k + 1], i);
      const spine::Pose r = f.pose(m, i);
      const double e = (r.apply(c) - d.apply(c)).norm();
      et[std::size_t(i)].push_back(e);
      er[std::size_t(i)].push_back(spine::rotation_log(r.R * d.R.transpose()).norm() * kDegPerRad);
    }
    ++out.samples;
  }
  // Relative to the hook vertebra's largest motion over the drag (a per-sample ratio is
  // ill-conditioned where the motion passes through zero, at the start and the return).
  for (int i = 0; i < kVertebrae; ++i)
    for (double e : et[std::size_t(i)])
      if (out.hook_motion_max_mm > 0)
        ep[std::size_t(i)].push_back(100 * e / out.hook_motion_max_mm);
  for (int i = 0; i < kVertebrae; ++i) {
    out.translation_mm[std::size_t(i)] = percentiles_of(et[std::size_t(i)]);
    out.rotation_deg[std::size_t(i)] = percentiles_of(er[std::size_t(i)]);
    out.relative_percent[std::size_t(i)] = percentiles_of(ep[std::size_t(i)]);
  }
}

/// Relative translation (of the upper centre, in the lower vertebra's axes) and rotation of
/// every adjacent pair, every 10 ms.
std::string pairs_csv(const spine::SpineModel& m, const DragRecording& rec) {
  std::ostringstream os;
  os << "# vertebra pairs over the drag (" << rec.path
     << "): the upper centre's displacement relative to the lower vertebra, in its axes (mm), "
        "and the rotation vector of the upper relative to the lower (deg)\n"
        "t_s,pair,dx_mm,dy_mm,dz_mm,rx_deg,ry_deg,rz_deg\n";
  const auto& names = spine::vertebra_names();
  double next = -1;
  for (const DragFrame& f : rec.frames) {
    if (f.t_s < next) continue;
    next = f.t_s + 0.01;
    for (int i = 0; i + 1 < kVertebrae; ++i) {
      const spine::Pose up = f.pose(m, i), low = f.pose(m, i + 1);
      const Eigen::Vector3d cu = m.vertebrae[std::size_t(i)].centre_mm;
      const Eigen::Vector3d cl = m.vertebrae[std::size_t(i + 1)].centre_mm;
      const Eigen::Vector3d d = low.R.transpose() * (up.apply(cu) - low.apply(cl)) - (cu - cl);
      const Eigen::Vector3d r = spine::rotation_log(low.R.transpose() * up.R) * kDegPerRad;
      char line[256];
      std::snprintf(line, sizeof line, "%.3f,%s-%s,%.4f,%.4f,%.4f,%.4f,%.4f,%.4f\n", f.t_s,
                    names[std::size_t(i)].c_str(), names[std::size_t(i + 1)].c_str(), d.x(), d.y(),
                    d.z(), r.x(), r.y(), r.z());
      os << line;
    }
  }
  return os.str();
}

}  // namespace

HapticDragResult run_haptic_drag_study(const HapticDragRequest& request,
                                       const std::string& data_dir,
                                       const std::function<void(const std::string&)>& stage) {
  for (const auto& c : request.cases)
    if (c != "lateral" && c != "sagittal" && c != "oblique")
      throw std::invalid_argument("--case " + c + ": give lateral, sagittal or oblique");
  for (const auto& m : request.methods)
    if (m != "multirate" && m != "database")
      throw std::invalid_argument("method " + m + ": give multirate or database");
  if (!(request.sample_every_s > 0))
    throw std::invalid_argument("the sampling interval must be > 0 s");
  prepare_output_folder(request.out, "--out");
  Timer timer;
  HapticDragResult result;
  result.request = request;
  const spine::SpineModel model = spine::load_spine_model(data_dir);
  for (const std::string& name : request.cases) {
    DragCaseResult c;
    c.name = name;
    for (const std::string& method : request.methods) {
      if (stage) stage(name + " drag, " + method + " spine");
      HapticsRunRequest run;
      run.scene.scene = "spine";
      run.scene.triangles = request.triangles;
      run.spine = method;
      run.device = "sim";
      run.script = (fs::path(data_dir) / "haptics" / ("drag_t1_" + name + ".csv")).string();
      run.record = (fs::path(request.out) / ("drag_" + name + "_" + method + ".csv")).string();
      run.realtime_priority = request.realtime_priority;
      const HapticsRunResult r = run_haptics(run, data_dir);
      DragMethodResult mr;
      mr.method = method;
      mr.recording = run.record;
      mr.stats = r.stats;
      mr.worker_rate_hz = r.worker_rate_hz;
      if (stage) stage(name + " drag, " + method + ": direct solves");
      const DragRecording rec = read_drag_recording(run.record, model);
      measure_pose_error(model, rec, request, false, mr);
      if (method == "multirate" || c.pairs_csv.empty()) {
        c.pairs_csv = (fs::path(request.out) / ("pairs_" + name + ".csv")).string();
        write_csv_file(c.pairs_csv, pairs_csv(model, rec));
      }
      c.methods.push_back(mr);
      if (method == "database") {
        // The database knows forces at the vertebra centres only: its error against solves
        // with the force there separates its fit and superposition from the moment it leaves out.
        DragMethodResult centre = mr;
        centre.method = "database (vs force at centre)";
        centre.samples = centre.failed_solves = 0;
        centre.hook_motion_max_mm = 0;
        measure_pose_error(model, rec, request, true, centre);
        c.methods.push_back(centre);
      }
    }
    if (request.discs && std::find(request.methods.begin(), request.methods.end(), "multirate") !=
                             request.methods.end()) {
      if (stage) stage(name + " drag: the 17 offline discs");
      SpineDiscsRequest d;
      d.recording = (fs::path(request.out) / ("drag_" + name + "_multirate.csv")).string();
      d.out = (fs::path(request.out) / ("discs_" + name)).string();
      c.discs = run_spine_discs(d, data_dir);
      c.has_discs = true;
    }
    result.cases.push_back(c);
  }
  result.seconds = timer.seconds();
  return result;
}

nlohmann::json haptic_drag_json(const HapticDragResult& r) {
  nlohmann::json cases = nlohmann::json::array();
  const auto& names = spine::vertebra_names();
  auto pct = [](const ErrorPercentiles& p) {
    return nlohmann::json{{"p50", p.p50}, {"p95", p.p95}, {"max", p.max}};
  };
  for (const auto& c : r.cases) {
    nlohmann::json methods = nlohmann::json::array();
    for (const auto& m : c.methods) {
      nlohmann::json per = nlohmann::json::object();
      for (int i = 0; i < kVertebrae; ++i)
        per[names[std::size_t(i)]] = {
            {"translation_mm", pct(m.translation_mm[std::size_t(i)])},
            {"rotation_deg", pct(m.rotation_deg[std::size_t(i)])},
            {"percent_of_hook_motion", pct(m.relative_percent[std::size_t(i)])}};
      methods.push_back({{"method", m.method},
                         {"recording", m.recording},
                         {"samples", m.samples},
                         {"failed_solves", m.failed_solves},
                         {"hook_motion_max_mm", m.hook_motion_max_mm},
                         {"worker_rate_hz", m.worker_rate_hz},
                         {"compute_us_p99", m.stats.compute_us.p99},
                         {"period_us_p999", m.stats.period_us.p999},
                         {"missed_deadlines", m.stats.missed_deadlines},
                         {"max_spine_force_n", m.stats.max_spine_force_n},
                         {"vertebrae", per}});
    }
    cases.push_back({{"case", c.name},
                     {"pairs_csv", c.pairs_csv},
                     {"methods", methods},
                     {"discs", c.has_discs ? spine_discs_json(c.discs) : nlohmann::json()}});
  }
  return {{"cases", cases}, {"seconds", r.seconds}};
}

std::string haptic_drag_table(const HapticDragResult& r) {
  std::ostringstream os;
  for (const auto& c : r.cases) {
    os << "T1 dragged " << c.name << " (vertebra pairs: " << c.pairs_csv << ")\n";
    TextTable t({"method", "samples", "hook motion max (mm)", "T1 error p50 / p95 (% of motion)",
                 "T1 p95 (mm)", "worst vertebra p95 (mm)", "spine force max (N)", "solves/s",
                 "compute p99 (us)"});
    for (const auto& m : c.methods) {
      double worst = 0;
      for (const auto& p : m.translation_mm) worst = std::max(worst, p.p95);
      t.add({m.method, std::to_string(m.samples), fixed(m.hook_motion_max_mm, 1),
             fixed(m.relative_percent[0].p50, 1) + " / " + fixed(m.relative_percent[0].p95, 1),
             fixed(m.translation_mm[0].p95, 2), fixed(worst, 2),
             fixed(m.stats.max_spine_force_n, 0),
             m.method == "multirate" ? fixed(m.worker_rate_hz, 1) : "-",
             fixed(m.stats.compute_us.p99, 1)});
    }
    t.print(os, false);
    if (c.has_discs) {
      const auto& d = c.discs;
      double rot = 0, force = 0;
      std::string at_rot, at_force;
      for (const auto& p : d.peaks) {
        if (p.rotation_deg > rot) rot = p.rotation_deg, at_rot = p.level;
        if (p.force_n > force) force = p.force_n, at_force = p.level;
      }
      os << "  offline discs: " << d.pvd << ", " << d.table_csv << "; " << fixed(d.speedup(), 2)
         << "x real time stepping; largest rotation " << fixed(rot, 2) << " deg (" << at_rot
         << "), reaction " << fixed(force, 1) << " N (" << at_force << ")\n";
    }
    os << "\n";
  }
  os << "(errors against direct equilibrium solves at the recorded hook force and point; "
     << fixed(r.seconds, 0) << " s)\n";
  return os.str();
}

}  // namespace spinesim::studies

#include "spinesim/studies/probe_study.hpp"
#include "spinesim/mss/simulator.hpp"

#include "spinesim/mesh/io.hpp"
#include "spinesim/mss/boundary.hpp"
#include "spinesim/mss/quantities.hpp"
#include "spinesim/studies/toolkit.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <filesystem>
#include <iomanip>
#include <sstream>
#include <stdexcept>
#include <unordered_map>

namespace spinesim::studies {
namespace fs = std::filesystem;

Eigen::MatrixX3d boundary_normals(const mesh::TetMesh& m) {
  static const int face[4][3] = {{1, 2, 3}, {0, 3, 2}, {0, 1, 3}, {0, 2, 1}};  // opposite vertex k
  struct Seen {
    int count = 0;
    Eigen::Index tet = 0;
    int local = 0;
  };
  std::unordered_map<std::uint64_t, Seen> faces;
  faces.reserve(std::size_t(2 * m.num_tets()));
  for (Eigen::Index t = 0; t < m.num_tets(); ++t)
    for (int k = 0; k < 4; ++k) {
      std::array<std::uint64_t, 3> v{std::uint64_t(m.T(t, face[k][0])),
                                     std::uint64_t(m.T(t, face[k][1])),
                                     std::uint64_t(m.T(t, face[k][2]))};
      std::sort(v.begin(), v.end());
      Seen& s = faces[(v[0] << 42) | (v[1] << 21) | v[2]];
      ++s.count;
      s.tet = t;
      s.local = k;
    }
  Eigen::MatrixX3d n = Eigen::MatrixX3d::Zero(m.num_vertices(), 3);
  for (const auto& [key, s] : faces) {
    if (s.count != 1) continue;
    const auto a = m.T(s.tet, face[s.local][0]), b = m.T(s.tet, face[s.local][1]),
               c = m.T(s.tet, face[s.local][2]);
    Eigen::Vector3d nf =
        (m.V.row(b) - m.V.row(a)).transpose().cross((m.V.row(c) - m.V.row(a)).transpose());
    if (nf.dot((m.V.row(m.T(s.tet, s.local)) - m.V.row(a)).transpose()) > 0)
      nf = -nf;  // point away from the tet
    for (auto i : {a, b, c}) n.row(i) += nf.transpose();
  }
  return n;
}

ProbeSite pick_site(const mesh::TetMesh& m, const Eigen::MatrixX3d& normals,
                    const std::string& name) {
  Eigen::Vector3d d_local;
  if (name == "anterior")
    d_local << 0, 0, 1;
  else if (name == "posterior")
    d_local << 0, 0, -1;
  else if (name == "left")
    d_local << 1, 0, 0;  // the body's right is -x
  else if (name == "right")
    d_local << -1, 0, 0;
  else
    throw std::invalid_argument("unknown probe site '" + name +
                                "' (anterior, posterior, left, right)");
  ProbeSite site;
  site.name = name;
  double best = INFINITY;
  for (Eigen::Index i = 0; i < m.num_vertices(); ++i) {
    if (m.surface(i) != int(mesh::Surface::outer_wall)) continue;
    const Eigen::Vector3d p =
        m.frame.axes.transpose() * (m.V.row(i).transpose() - m.frame.origin_mm);
    const double along = p.dot(d_local);
    const double off = (p - along * d_local).norm();
    if (along > 0 && off < best) best = off, site.node = i;
  }
  if (!std::isfinite(best))
    throw std::invalid_argument("probe site " + name + ": the mesh has no outer-wall node there");
  site.point_mm = m.V.row(site.node).transpose();
  site.normal = normals.row(site.node).transpose().normalized();
  return site;
}

namespace {

/// Where the probe is at time t: per site, press at `speed` to `depth`, hold, withdraw, then
/// rest with the probe away (the dent recovers).
struct ProbeSchedule {
  std::vector<ProbeSite> sites;
  double depth_mm, speed_mm_s, hold_s, rest_s;
  double press_s() const { return depth_mm / speed_mm_s; }
  double site_s() const { return 2 * press_s() + hold_s + rest_s; }
  double total_s() const { return site_s() * double(sites.size()); }
  struct Command {
    bool active = false;
    std::size_t site = 0;
    double depth_mm = 0;
  };
  Command at(double t) const {
    Command c;
    c.site = std::min(sites.size() - 1, std::size_t(std::max(0.0, t) / site_s()));
    const double s = t - double(c.site) * site_s(), p = press_s();
    if (s <= p)
      c.active = true, c.depth_mm = speed_mm_s * s;
    else if (s <= p + hold_s)
      c.active = true, c.depth_mm = depth_mm;
    else if (s <= 2 * p + hold_s)
      c.active = true, c.depth_mm = depth_mm - speed_mm_s * (s - p - hold_s);
    c.depth_mm = std::clamp(c.depth_mm, 0.0, depth_mm);
    return c;
  }
};

bool known_site(const std::string& name) {
  return name == "anterior" || name == "posterior" || name == "left" || name == "right";
}

}  // namespace

void check(const ProbeStudyRequest& rq) {
  check(rq.stepping);
  for (double v : {rq.radius_mm, rq.depth_mm, rq.speed_mm_s})
    if (!std::isfinite(v) || v <= 0)
      throw std::invalid_argument("--radius, --depth and --speed must be finite and > 0");
  for (double v : {rq.hold_s, rq.rest_s, rq.stiffness_n_per_mm})
    if (!std::isfinite(v) || v < 0)
      throw std::invalid_argument("--hold, --rest and --probe-stiffness must be finite and >= 0");
  if (rq.sites.empty())
    throw std::invalid_argument("--sites: give at least one of anterior, posterior, left, right");
  for (const auto& name : rq.sites)
    if (!known_site(name))
      throw std::invalid_argument("unknown probe site '" + name +
                                  "' (anterior, posterior, left, right)");
}

/// The summary JSON of a probe run (also written to probe.json).
nlohmann::json probe_summary(const mesh::TetMesh& m, const mesh::RegionMaterials& materials,
                             const mss::MssModel& model, const ProbeStudyResult& r) {
  const ProbeStudyRequest& rq = r.request;
  const SteppedStudyOptions& o = rq.stepping;
  const Range& dv = r.volume_change;
  nlohmann::json sites = nlohmann::json::array();
  for (const auto& p : r.sites)
    sites.push_back({{"name", p.name},
                     {"node", p.node},
                     {"point_mm", to_json(p.point_mm)},
                     {"normal", to_json(p.normal)},
                     {"start_s", p.start_s}});
  return {{"study", "probe"},
          {"thesis", "5.3 test 1, fig. 5.8"},
          {"mesh", study_mesh_json(m)},
          {"material", materials.name},
          {"model_variant", o.model_variant},
          {"model", mss_model_json(model, materials)},
          {"probe",
           {{"radius_mm", rq.radius_mm},
            {"depth_mm", rq.depth_mm},
            {"speed_mm_s", rq.speed_mm_s},
            {"hold_s", rq.hold_s},
            {"rest_s", rq.rest_s},
            {"stiffness_n_per_mm", r.stiffness_n_per_mm},
            {"schedule",
             "per site: press at speed to depth, hold, withdraw, rest with the probe away"}}},
          {"sites", sites},
          {"integrator", o.integrator_name},
          {"dt_s", o.dynamics.dt_s},
          {"steps", r.steps},
          {"max_force_n", r.max_force_n},
          {"max_volume_change", dv.extreme_or_zero()},
          {"volume_change_range",
           {std::isfinite(dv.lo) ? dv.lo : 0.0, std::isfinite(dv.hi) ? dv.hi : 0.0}},
          {"max_displacement_mm", r.max_displacement_mm},
          {"files", {{"pvd", r.pvd_path}, {"csv", r.csv_path}, {"json", r.json_path}}},
          {"frames", r.frames}};
}

ProbeStudyResult run_probe_study(const mesh::TetMesh& m, const mesh::RegionMaterials& materials,
                                 const ProbeStudyRequest& rq, const StageHooks& hooks) {
  // 1. The model and the probe sites.
  check(rq);
  const SteppedStudyOptions& o = rq.stepping;
  prepare_output_folder(o.out, "--out");
  ProbeStudyResult r;
  r.request = rq;
  hooks.begin_stage("building the mass-spring model (" + o.model_variant + ")");
  const mss::MssModel model(m, materials, o.model);
  hooks.end_stage();
  const Eigen::MatrixX3d normals = boundary_normals(m);
  ProbeSchedule plan{{}, rq.depth_mm, rq.speed_mm_s, rq.hold_s, rq.rest_s};
  for (const auto& name : rq.sites) plan.sites.push_back(pick_site(m, normals, name));
  for (std::size_t i = 0; i < plan.sites.size(); ++i)
    plan.sites[i].start_s = double(i) * plan.site_s();
  r.sites = plan.sites;
  r.steps =
      int(std::ceil(plan.total_s() / o.dynamics.dt_s - 1e-6));  // round-off must not add a step

  // 2. Step: both endplates fixed (identity poses), the probe moving.
  SteppedRun run(model, o, "probe",
                 "time_s,site,probe_active,probe_x_mm,probe_y_mm,probe_z_mm,depth_mm,force_x_n,"
                 "force_y_n,force_z_n,force_n,volume_mm3,volume_change,max_displacement_mm",
                 r.steps);
  hooks.begin_stage(std::to_string(r.steps) + " steps (" + o.integrator_name + " Euler, dt " +
                    std::to_string(o.dynamics.dt_s) + " s)");
  // The default penalty costs a rest-Hessian evaluation: resolve it once, not per step.
  const double k_probe =
      rq.stiffness_n_per_mm > 0 ? rq.stiffness_n_per_mm : mss::default_probe_stiffness(model);
  r.stiffness_n_per_mm = k_probe;
  for (int k = 1; k <= r.steps; ++k) {
    const double t = k * o.dynamics.dt_s;
    const auto cmd = plan.at(t);
    const ProbeSite& site = r.sites[cmd.site];
    const Eigen::Vector3d center = site.point_mm + (rq.radius_mm - cmd.depth_mm) * site.normal;
    mss::Boundary bc;
    if (cmd.active) bc.probes.push_back({center, rq.radius_mm, k_probe});
    if (!run.step(k, bc)) break;
    const mss::State& s = run.state();
    const Eigen::Vector3d f =
        cmd.active ? mss::probe_forces(model, bc, s.x_mm).front() : Eigen::Vector3d::Zero();
    const double v = model.volume_mm3(s.x_mm), u = mss::max_displacement_mm(model, s.x_mm);
    const double dv = mss::volume_change(model, s.x_mm);
    r.volume_change.add(dv);
    r.max_force_n = std::max(r.max_force_n, f.norm());
    r.max_displacement_mm = std::max(r.max_displacement_mm, u);
    run.csv() << s.time_s << "," << site.name << "," << int(cmd.active) << "," << center.x() << ","
              << center.y() << "," << center.z() << "," << cmd.depth_mm << "," << f.x() << ","
              << f.y() << "," << f.z() << "," << f.norm() << "," << v << "," << dv << "," << u
              << "\n";
  }
  r.stats = run.stats();
  hooks.end_stage(std::to_string(r.stats.steps_done) + " steps");

  // 3. Files and summary.
  hooks.begin_stage("writing " + o.out);
  run.finish();
  r.pvd_path = run.pvd_path();
  r.frames = run.num_frames();
  r.csv_path = run.csv_path();
  r.json_path = (fs::path(o.out) / "probe.json").string();
  r.summary = probe_summary(m, materials, model, r);
  r.stats.add_to(r.summary);
  write_json_file(r.json_path, r.summary);
  hooks.end_stage();
  return r;
}

void print_probe_study(std::ostream& os, const mesh::TetMesh& m, const std::string& material,
                       const ProbeStudyResult& r) {
  const ProbeStudyRequest& rq = r.request;
  os << std::setprecision(4) << "Probe study (thesis 5.3, test 1) on " << m.source << " ("
     << m.num_tets() << " tets), material " << material << ", MSS "
     << r.request.stepping.model_variant << "\n"
     << "  probe radius " << rq.radius_mm << " mm, depth " << rq.depth_mm << " mm at "
     << rq.speed_mm_s << " mm/s, hold " << rq.hold_s << " s, rest " << rq.rest_s
     << " s; both endplates fixed\n";
  for (const auto& p : r.sites)
    os << "  site " << pad(p.name, 10, true) << " from t = " << p.start_s << " s at ("
       << p.point_mm.transpose() << ") mm, normal (" << p.normal.transpose() << ")\n";
  os << "  " << r.stats.steps_done << " of " << r.steps << " steps, mean step "
     << r.stats.mean_seconds() * 1e3 << " ms\n"
     << "  max probe force " << r.max_force_n << " N, max |u| " << r.max_displacement_mm << " mm\n"
     << "  volume change " << 100 * r.summary["volume_change_range"][0].get<double>() << " % .. "
     << 100 * r.summary["volume_change_range"][1].get<double>() << " %\n"
     << "  wrote " << r.pvd_path << " (" << r.frames << " frames), " << r.csv_path << ", "
     << r.json_path << "\n";
}

}  // namespace spinesim::studies

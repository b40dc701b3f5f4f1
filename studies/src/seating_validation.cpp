// The seating sweep and the seated spine beside in-vivo data (seating_study.hpp; docs/seating.md).
#include "spinesim/common/input_file.hpp"
#include "spinesim/common/timer.hpp"
#include "spinesim/studies/seating_study.hpp"
#include "spinesim/studies/toolkit.hpp"

#include <cmath>
#include <numeric>
#include <sstream>
#include <stdexcept>

namespace spinesim::studies {
namespace {
using nlohmann::json;

json read_targets(const std::string& data_dir) {
  return read_json_file(data_dir + "/validation/sitting_in_vivo.json", "sitting targets");
}

double number_at(const json& j, const std::string& key, const std::string& where) {
  if (!j.contains(key) || !j.at(key).is_number())
    throw std::runtime_error("sitting_in_vivo.json: " + where + " needs a number '" + key + "'");
  return j.at(key).get<double>();
}

double l4l5(const spine::SpineSolution& s) {
  return s.joints[std::size_t(spine::joint_index("L4-L5"))].axial_n;
}

/// A quantity of one seated run, by the name the validation file uses.
double quantity(const SeatingRun& r, const std::string& name) {
  if (name == "L4-L5 compression") return l4l5(r.seated.spine);
  if (name == "L5-S1 compression") return r.seated.spine.joints.back().axial_n;
  if (name == "back-muscle force") return r.back_muscle_force_n;
  if (name == "backrest force") return r.seated.backrest_force_n.norm();
  throw std::runtime_error("sitting_in_vivo.json: unknown quantity '" + name + "'");
}

/// Does `y` over increasing `x` go `direction` (decreasing | increasing: least-squares slope and
/// the ends agree; flat: every value within `flat` of the mean)?
bool follows(const std::vector<double>& x, const std::vector<double>& y,
             const std::string& direction, double flat) {
  const double n = double(x.size());
  const double mx = std::accumulate(x.begin(), x.end(), 0.0) / n;
  const double my = std::accumulate(y.begin(), y.end(), 0.0) / n;
  double sxy = 0, sxx = 0;
  for (std::size_t i = 0; i < x.size(); ++i) {
    sxy += (x[i] - mx) * (y[i] - my);
    sxx += (x[i] - mx) * (x[i] - mx);
  }
  const double slope = sxx > 0 ? sxy / sxx : 0;
  if (direction == "flat") {
    for (double v : y)
      if (std::abs(v - my) > flat * std::abs(my)) return false;
    return true;
  }
  if (direction == "decreasing") return slope < 0 && y.back() < y.front();
  if (direction == "increasing") return slope > 0 && y.back() > y.front();
  throw std::runtime_error("sitting_in_vivo.json: unknown direction '" + direction + "'");
}

/// The trends of the validation file over `s.parameter`, checked on the sweep's own values.
std::vector<Finding> sweep_findings(const json& targets, const SeatingSweep& s) {
  std::vector<Finding> out;
  const double flat = number_at(targets, "flat_within", "the file");
  for (const json& t : targets.at("trends")) {
    if (t.at("parameter").get<std::string>() != s.parameter || s.runs.size() < 2) continue;
    const std::string q = t.at("quantity").get<std::string>(),
                      dir = t.at("direction").get<std::string>();
    std::vector<double> y;
    std::ostringstream ours;
    for (std::size_t i = 0; i < s.runs.size(); ++i) {
      y.push_back(quantity(s.runs[i], q));
      ours << (i ? ", " : "") << significant(s.values[i], 3) << ": " << fixed(y.back(), 0) << " N";
    }
    Finding f;
    f.id = t.at("id").get<std::string>();
    f.load = s.parameter;
    f.thesis = q + " " + dir + " (" + t.at("source").get<std::string>() + ")";
    f.ours = q + " at " + ours.str();
    f.match = follows(s.values, y, dir, flat);
    out.push_back(f);
  }
  return out;
}

}  // namespace

SeatingSweep run_seating_sweep(const std::string& data_dir, const std::string& parameter,
                               const std::vector<double>& values, const SeatingRequest& base,
                               const StageHooks& hooks) {
  Timer timer;
  if (values.empty()) throw std::invalid_argument("--values needs at least one number");
  for (double v : values)
    if (!std::isfinite(v)) throw std::invalid_argument("--values must be finite numbers");
  // An unknown parameter or a value no chair can have fails before any work.
  for (double v : values) {
    try {
      check_seating_request(with_parameter(base, parameter, v));
    } catch (const std::invalid_argument& e) {
      throw std::invalid_argument(parameter + " " + significant(v, 4) + ": " + e.what());
    }
  }
  SeatingSweep s;
  s.parameter = parameter;
  s.values = values;
  for (double v : values) {
    hooks.begin_stage(parameter + " " + significant(v, 4));
    try {
      s.runs.push_back(run_seating(data_dir, with_parameter(base, parameter, v)));
    } catch (const std::invalid_argument& e) {
      throw std::invalid_argument(parameter + " " + significant(v, 4) + ": " + e.what());
    }
    hooks.end_stage("L4-L5 " + fixed(l4l5(s.runs.back().seated.spine), 0) + " N, " +
                    fixed(s.runs.back().seated.seconds, 2) + " s");
  }
  s.findings = sweep_findings(read_targets(data_dir), s);
  s.seconds = timer.seconds();
  return s;
}

void print_seating_sweep(std::ostream& os, const SeatingSweep& s, bool markdown) {
  TextTable t({s.parameter, "lean (deg)", "backrest (N)", "seat (N)", "L4-L5 comp. (N)",
               "L5-S1 comp. (N)", "L5-S1 shear AP (N)", "L5-S1 Mx (N·m)", "back muscles (N)",
               "max back act.", "seat friction", "residual (N)", "time (s)"});
  for (std::size_t i = 0; i < s.runs.size(); ++i) {
    const auto& r = s.runs[i].seated;
    const auto& l5 = r.spine.joints.back();
    t.add({significant(s.values[i], 4), fixed(r.lean_deg, 1), fixed(r.backrest_force_n.norm(), 1),
           fixed(r.seat_force_n.norm(), 1), fixed(l4l5(r.spine), 1), fixed(l5.axial_n, 1),
           fixed(l5.shear_ap_n, 1), fixed(l5.moment_local_nmm.x() / 1000, 2),
           fixed(s.runs[i].back_muscle_force_n, 1), fixed(s.runs[i].back_muscle_max_activation, 3),
           fixed(r.seat_friction_needed, 2), significant(r.force_residual_n, 2),
           fixed(r.seconds, 2)});
  }
  t.print(os, markdown);
  if (!s.findings.empty()) {
    os << "\nAgainst the literature (in-vivo trends, data/validation/sitting_in_vivo.json)\n";
    print_findings(os, s.findings, markdown, "literature says");
  }
}

json seating_sweep_json(const SeatingSweep& s) {
  json runs = json::array();
  for (std::size_t i = 0; i < s.runs.size(); ++i) {
    json r = seating_json(s.runs[i]);
    r["value"] = s.values[i];
    runs.push_back(r);
  }
  return {{"parameter", s.parameter},
          {"values", s.values},
          {"runs", runs},
          {"findings", findings_json(s.findings)},
          {"seconds", s.seconds}};
}

std::string seating_sweep_csv(const SeatingSweep& s) {
  std::ostringstream os;
  os << s.parameter
     << ",lean_deg,backrest_n,seat_n,l4l5_compression_n,l5s1_compression_n,"
        "l5s1_shear_ap_n,l5s1_moment_x_nmm,back_muscle_force_n,"
        "back_muscle_max_activation,seat_friction_needed,force_residual_n,seconds\n";
  for (std::size_t i = 0; i < s.runs.size(); ++i) {
    const auto& r = s.runs[i].seated;
    const auto& l5 = r.spine.joints.back();
    os << s.values[i] << "," << r.lean_deg << "," << r.backrest_force_n.norm() << ","
       << r.seat_force_n.norm() << "," << l4l5(r.spine) << "," << l5.axial_n << "," << l5.shear_ap_n
       << "," << l5.moment_local_nmm.x() << "," << s.runs[i].back_muscle_force_n << ","
       << s.runs[i].back_muscle_max_activation << "," << r.seat_friction_needed << ","
       << r.force_residual_n << "," << r.seconds << "\n";
  }
  return os.str();
}

SittingValidation run_posture_comparison(const std::string& data_dir,
                                         const spine::ModelOptions& model, double swelling_mpa) {
  const json targets = read_targets(data_dir);
  const double area = number_at(targets, "disc_area_mm2", "the file");
  const double tol = number_at(targets, "tolerance", "the file");
  const json& p = targets.at("pressures");
  auto mpa = [&](const std::string& k) { return number_at(p.at(k), "mpa", k); };
  auto source = [&](const std::string& k) { return p.at(k).at("source").get<std::string>(); };
  if (std::isnan(swelling_mpa))
    swelling_mpa = number_at(targets, "swelling_pressure_mpa", "the file");
  if (!(swelling_mpa >= 0 && swelling_mpa <= 0.5))
    throw std::invalid_argument("the disc's swelling pressure must lie within 0 … 0.5 MPa");
  SittingValidation v;
  v.disc_area_mm2 = area;
  const spine::SpineModel standing_model = spine::load_spine_model(data_dir, model);
  // The swelling pressure on this body's L4-L5 disc: the area scales with the body's length².
  const double s = standing_model.scale.length;
  v.swelling_mpa = swelling_mpa;
  v.swelling_n = swelling_mpa * area * s * s;
  const double standing = l4l5(spine::solve_spine(standing_model, {})) + v.swelling_n;
  SeatingRequest stool;
  stool.model = model;
  stool.chair.backrest_height_mm = 0;
  const double unsupported = l4l5(run_seating(data_dir, stool).seated.spine) + v.swelling_n;
  SeatingRequest slouched = stool;  // leaning back in an ordinary chair
  slouched.chair = spine::Chair();
  slouched.chair.backrest_recline_deg = 110;
  const double in_chair = l4l5(run_seating(data_dir, slouched).seated.spine) + v.swelling_n;
  const double crate = run_wilke_case(data_dir, model).l4l5.axial_n + v.swelling_n;
  auto row = [&](const std::string& id, const std::string& what, double ours, double target,
                 const std::string& unit, const std::string& src) {
    SittingValidation::Row r{id,   what, ours, target, target * (1 - tol), target * (1 + tol),
                             unit, src,  false};
    r.pass = ours >= r.low && ours <= r.high;
    v.rows.push_back(r);
  };
  const double ps = mpa("standing");
  row("standing", "standing, L4-L5 compression", standing, ps * area, "N", source("standing"));
  row("sitting-unsupported", "sitting without backrest / standing", unsupported / standing,
      mpa("sitting_unsupported") / ps, "", source("sitting_unsupported"));
  row("sitting-in-chair", "leaning back in a chair (110 deg) / standing", in_chair / standing,
      mpa("sitting_slouched_in_chair") / ps, "", source("sitting_slouched_in_chair"));
  row("crate", "crate / standing", crate / standing, mpa("crate") / ps, "", source("crate"));
  for (const auto& r : v.rows) {
    Finding f;
    f.id = r.id;
    f.load = "posture";
    f.thesis = r.what + " " + significant(r.target, 3) + " " + r.unit + " (" + r.source + ")";
    f.ours = significant(r.ours, 3) + " " + r.unit + " (window " + significant(r.low, 3) + " … " +
             significant(r.high, 3) + ")";
    f.match = r.pass;
    v.findings.push_back(f);
  }
  return v;
}

SittingValidation run_sitting_validation(const std::string& data_dir,
                                         const spine::ModelOptions& model,
                                         const StageHooks& hooks) {
  Timer timer;
  const json targets = read_targets(data_dir);
  hooks.begin_stage("standing, sitting with and without a backrest, crate");
  SittingValidation v = run_posture_comparison(data_dir, model);
  hooks.end_stage();
  std::vector<std::string> parameters;
  for (const json& t : targets.at("trends")) {
    const std::string par = t.at("parameter").get<std::string>();
    if (std::find(parameters.begin(), parameters.end(), par) != parameters.end()) continue;
    parameters.push_back(par);
    hooks.begin_stage("sweep " + par);
    SeatingRequest base;
    base.model = model;
    v.sweeps.push_back(
        run_seating_sweep(data_dir, par, t.at("values").get<std::vector<double>>(), base));
    hooks.end_stage();
    for (const auto& f : v.sweeps.back().findings) v.findings.push_back(f);
  }
  v.seconds = timer.seconds();
  return v;
}

void print_sitting_validation(std::ostream& os, const SittingValidation& v, bool markdown) {
  TextTable t({"case", "ours", "in vivo", "window", "", "source"}, 1);
  for (const auto& r : v.rows)
    t.add({r.what, significant(r.ours, 3) + (r.unit.empty() ? "" : " " + r.unit),
           significant(r.target, 3), significant(r.low, 3) + " … " + significant(r.high, 3),
           r.pass ? "MATCH" : "DIFFERS", r.source});
  t.print(os, markdown);
  os << "  L4-L5 compression: the joint's axial force + the disc's swelling pressure, "
     << fixed(v.swelling_mpa, 2) << " MPa × the disc area = " << fixed(v.swelling_n, 0)
     << " N in every posture (Wilke et al. 1999, lying prone; self-equilibrated, so no joint "
        "force changes)\n";
  for (const auto& s : v.sweeps) {
    os << "\nSweep: " << s.parameter << "\n";
    print_seating_sweep(os, s, markdown);
  }
  int match = 0;
  for (const auto& f : v.findings) match += f.match;
  os << "\n" << match << " of " << v.findings.size() << " MATCH\n";
}

json sitting_validation_json(const SittingValidation& v) {
  json rows = json::array();
  for (const auto& r : v.rows)
    rows.push_back({{"id", r.id},
                    {"what", r.what},
                    {"ours", r.ours},
                    {"target", r.target},
                    {"low", r.low},
                    {"high", r.high},
                    {"unit", r.unit},
                    {"pass", r.pass},
                    {"source", r.source}});
  json sweeps = json::array();
  for (const auto& s : v.sweeps) sweeps.push_back(seating_sweep_json(s));
  return {{"rows", rows},
          {"sweeps", sweeps},
          {"findings", findings_json(v.findings)},
          {"swelling_mpa", v.swelling_mpa},
          {"swelling_n", v.swelling_n},
          {"seconds", v.seconds}};
}

std::string sitting_validation_csv(const SittingValidation& v) {
  std::ostringstream os;
  os << "id,ours,target,low,high,match\n";
  for (const auto& r : v.rows)
    os << r.id << "," << r.ours << "," << r.target << "," << r.low << "," << r.high << ","
       << (r.pass ? "MATCH" : "DIFFERS") << "\n";
  for (const auto& f : v.findings)
    if (f.load != "posture") os << f.id << ",,,,," << (f.match ? "MATCH" : "DIFFERS") << "\n";
  return os.str();
}

}  // namespace spinesim::studies

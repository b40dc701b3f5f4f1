// Loads that vary in time, solved as a quasi-static sequence (spine_schedule.hpp).
#include "spinesim/studies/spine_schedule.hpp"

#include "spinesim/common/csv_table.hpp"
#include "spinesim/common/timer.hpp"
#include "spinesim/haptics/recording.hpp"
#include "spinesim/spine/database.hpp"
#include "spinesim/spine/dynamics.hpp"
#include "spinesim/spine/kinematics.hpp"
#include "spinesim/studies/spine_solve.hpp"
#include "spinesim/studies/toolkit.hpp"

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <sstream>
#include <stdexcept>

namespace spinesim::studies {
namespace {

/// A number, or null in JSON when it is not finite (unknown, or no load ever changes).
nlohmann::json finite_or_null(double v) {
  return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(nullptr);
}

const char* const kComponents[6] = {"fx_n", "fy_n", "fz_n", "mx_nmm", "my_nmm", "mz_nmm"};

/// "T7.fz_n" → vertebra 6, component 2; throws naming the column.
std::pair<int, int> parse_column(const std::string& column, const std::string& path) {
  const auto dot = column.find('.');
  const std::string where = path + ": column '" + column + "'";
  if (dot == std::string::npos)
    throw std::invalid_argument(where + " is not VERTEBRA.COMPONENT (e.g. T7.fz_n)");
  int vertebra = 0;
  try {
    vertebra = spine::vertebra_index(column.substr(0, dot));
  } catch (const std::invalid_argument& e) {
    throw std::invalid_argument(where + ": " + e.what());
  }
  const std::string component = column.substr(dot + 1);
  for (int k = 0; k < 6; ++k)
    if (component == kComponents[k]) return {vertebra, k};
  throw std::invalid_argument(where +
                              ": unknown component (known: fx_n, fy_n, fz_n, mx_nmm, my_nmm, "
                              "mz_nmm)");
}

}  // namespace

LoadSchedule read_load_schedule(const std::string& path) {
  const CsvTable t = read_csv(path);  // a ragged row (a missing cell) is refused here
  LoadSchedule s;
  s.path = path;
  if (t.header.empty() || t.header.front() != "time_s")
    throw std::invalid_argument(path + ": the first column must be time_s");
  if (t.header.size() < 2)
    throw std::invalid_argument(path + ": no load column (e.g. T7.fz_n) after time_s");
  s.columns.assign(t.header.begin() + 1, t.header.end());
  for (const auto& c : s.columns) {
    const auto target = parse_column(c, path);
    if (std::find(s.targets.begin(), s.targets.end(), target) != s.targets.end())
      throw std::invalid_argument(path + ": column '" + c + "' is given twice");
    s.targets.push_back(target);
  }
  if (t.rows.empty()) throw std::invalid_argument(path + ": no rows");
  for (std::size_t r = 0; r < t.rows.size(); ++r) {
    for (const auto& name : t.header)
      if (t.text(r, name).empty())
        throw std::invalid_argument(path + ": row " + std::to_string(r + 1) + " column '" + name +
                                    "' is empty (a gap in the schedule)");
    const double time = t.number(r, "time_s");
    if (!s.time_s.empty() && !(time > s.time_s.back()))
      throw std::invalid_argument(path + ": row " + std::to_string(r + 1) + ": time " +
                                  t.text(r, "time_s") +
                                  " s does not come after the row before (times must increase)");
    std::vector<double> row;
    for (std::size_t c = 0; c < s.columns.size(); ++c) {
      const double v = t.number(r, s.columns[c]);
      const double limit = s.targets[c].second < 3 ? spine::kMaxForceN : spine::kMaxMomentNmm;
      if (std::abs(v) > limit)
        throw std::invalid_argument(path + ": row " + std::to_string(r + 1) + " column '" +
                                    s.columns[c] + "': " + t.text(r, s.columns[c]) +
                                    " is beyond any body (limit " + fixed(limit, 0) + ")");
      row.push_back(v);
    }
    s.time_s.push_back(time);
    s.values.push_back(std::move(row));
  }
  return s;
}

std::vector<spine::ExternalLoad> schedule_loads(const LoadSchedule& s, double t) {
  if (s.time_s.empty() || t < s.time_s.front() || t > s.time_s.back())
    throw std::invalid_argument("time " + fixed(t, 6) + " s is outside the schedule");
  std::size_t k = 0;  // the key interval [k, k + 1] holding t
  while (k + 1 < s.time_s.size() && s.time_s[k + 1] < t) ++k;
  const double w = k + 1 < s.time_s.size()
                       ? (t - s.time_s[k]) / (s.time_s[k + 1] - s.time_s[k])
                       : 0.0;
  std::vector<spine::ExternalLoad> loads;
  for (std::size_t c = 0; c < s.columns.size(); ++c) {
    const auto [vertebra, component] = s.targets[c];
    const double v0 = s.values[k][c];
    const double v = k + 1 < s.time_s.size() ? v0 + w * (s.values[k + 1][c] - v0) : v0;
    auto it = std::find_if(loads.begin(), loads.end(), [v = vertebra](const spine::ExternalLoad& l) {
      return l.vertebra == v;
    });
    if (it == loads.end()) {
      spine::ExternalLoad l;
      l.vertebra = vertebra;
      loads.push_back(l);
      it = loads.end() - 1;
    }
    if (component < 3)
      it->force_n(component) = v;
    else
      it->moment_nmm(component - 3) = v;
  }
  return loads;
}

std::vector<double> schedule_times(const LoadSchedule& s, double step_s) {
  std::vector<double> times = s.time_s;
  if (step_s > 0) {
    const double t0 = s.time_s.front(), t1 = s.time_s.back();
    for (long k = 1; t0 + double(k) * step_s < t1; ++k) times.push_back(t0 + double(k) * step_s);
  }
  std::sort(times.begin(), times.end());
  // A sample within a nanosecond of a key time is that key time.
  times.erase(std::unique(times.begin(), times.end(),
                          [](double a, double b) { return std::abs(a - b) < 1e-9; }),
              times.end());
  return times;
}

namespace {

double fastest_ramp_s(const LoadSchedule& s) {
  double fastest = INFINITY;
  for (std::size_t i = 1; i < s.time_s.size(); ++i)
    if (s.values[i] != s.values[i - 1]) fastest = std::min(fastest, s.time_s[i] - s.time_s[i - 1]);
  return fastest;
}

void check_inertia(ScheduleRun& run) {
  const ScheduleStep* first = nullptr;
  for (const ScheduleStep& s : run.steps)
    if (s.error.empty()) {
      first = &s;
      break;
    }
  run.fastest_ramp_s = fastest_ramp_s(run.schedule);
  if (!first || run.model.weights.empty()) return;
  try {
    run.first_frequency_hz =
        spine::spine_natural_modes(run.model, first->loads, first->solution, 1).frequency_hz[0];
  } catch (const std::invalid_argument&) {
    return;  // an unstable first posture: no modes to compare with
  }
  if (std::isfinite(run.fastest_ramp_s))
    run.overshoot_bound = spine::ramp_overshoot_bound(run.first_frequency_hz, run.fastest_ramp_s);
}

}  // namespace

ScheduleRun run_load_schedule(const std::string& data_dir, const LoadSchedule& schedule,
                              const spine::ModelOptions& model, const spine::SolveOptions& solve,
                              double step_s, int workers,
                              const std::function<void(int, int)>& progress) {
  const Timer timer;
  ScheduleRun run;
  run.schedule = schedule;
  run.model = spine::load_spine_model(data_dir, model);
  const std::vector<double> times = schedule_times(schedule, step_s);
  std::vector<std::vector<spine::ExternalLoad>> loads;
  for (double t : times) loads.push_back(schedule_loads(schedule, t));
  std::vector<spine::SpineSolution> solutions;
  std::vector<std::string> errors;
  spine::solve_many(run.model, loads, solve, workers, solutions, errors, progress);
  for (std::size_t i = 0; i < times.size(); ++i) {
    run.steps.push_back({times[i], loads[i], std::move(solutions[i]), errors[i]});
    if (!errors[i].empty()) ++run.failed;
  }
  check_inertia(run);
  run.seconds = timer.seconds();
  return run;
}

namespace {

/// The value of a schedule column's target (vertebra, component) in a step's loads.
double load_value(const ScheduleStep& step, const std::pair<int, int>& target) {
  const auto [vertebra, component] = target;
  for (const auto& l : step.loads)
    if (l.vertebra == vertebra) return component < 3 ? l.force_n(component) : l.moment_nmm(component - 3);
  return 0;
}

}  // namespace

std::string schedule_csv(const ScheduleRun& run) {
  std::ostringstream os;
  os << std::setprecision(10) << "time_s,converged";
  for (const auto& c : run.schedule.columns) os << "," << c;
  for (const auto& j : spine::joint_names())
    os << "," << j << ".axial_n," << j << ".shear_ap_n," << j << ".shear_lat_n";
  const char* d[6] = {"tx_mm", "ty_mm", "tz_mm", "rx_deg", "ry_deg", "rz_deg"};
  for (const auto& v : spine::vertebra_names())
    for (const char* k : d) os << "," << v << "." << k;
  os << "\n";
  for (const auto& step : run.steps) {
    const bool ok = step.error.empty();
    os << step.t_s << "," << (ok ? 1 : 0);
    for (const auto& t : run.schedule.targets) os << "," << load_value(step, t);
    for (std::size_t j = 0; j < spine::joint_names().size(); ++j) {
      if (!ok) {
        os << ",,,";
        continue;
      }
      const auto& r = step.solution.joints[j];
      os << "," << r.axial_n << "," << r.shear_ap_n << "," << r.shear_lat_n;
    }
    for (Eigen::Index v = 0; v < Eigen::Index(spine::vertebra_names().size()); ++v)
      for (int k = 0; k < 6; ++k)
        if (ok)
          os << "," << step.solution.displacement(v, k);
        else
          os << ",";
    os << "\n";
  }
  return os.str();
}

namespace {

/// The motion (null when not integrated).
nlohmann::json dynamic_json(const ScheduleRun& run) {
  if (run.dynamic.empty()) return nullptr;
  nlohmann::json samples = nlohmann::json::array();
  for (const DynamicSample& d : run.dynamic)
    samples.push_back({{"time_s", d.t_s},
                       {"l4l5_axial_n", d.l4l5_axial_n},
                       {"l5s1_axial_n", d.l5s1_axial_n},
                       {"t1_displacement", std::vector<double>(d.t1_displacement.data(),
                                                               d.t1_displacement.data() + 6)}});
  return {{"integrator", "Newmark average acceleration"},
          {"dt_s", run.dynamic_dt_s},
          {"damping_ratio", run.damping_ratio},
          {"steps", run.dynamic_steps},
          {"seconds", run.dynamic_seconds},
          {"samples", samples}};
}

}  // namespace

nlohmann::json schedule_json(const ScheduleRun& run) {
  nlohmann::json steps = nlohmann::json::array();
  for (const auto& step : run.steps) {
    nlohmann::json s = {{"time_s", step.t_s}, {"converged", step.error.empty()}};
    nlohmann::json loads = nlohmann::json::object();
    for (std::size_t c = 0; c < run.schedule.columns.size(); ++c)
      loads[run.schedule.columns[c]] = load_value(step, run.schedule.targets[c]);
    s["loads"] = loads;
    if (!step.error.empty()) {
      s["error"] = step.error;
    } else {
      nlohmann::json joints = nlohmann::json::object();
      for (const auto& r : step.solution.joints)
        joints[r.joint] = {{"axial_n", r.axial_n}, {"shear_ap_n", r.shear_ap_n},
                           {"shear_lat_n", r.shear_lat_n}};
      s["joints"] = joints;
      nlohmann::json t1 = nlohmann::json::array();
      for (int k = 0; k < 6; ++k) t1.push_back(step.solution.displacement(0, k));
      s["t1_displacement"] = t1;
      s["iterations"] = step.solution.iterations;
      s["stable"] = step.solution.min_stiffness_nmm_per_rad > 0;
      if (!step.solution.warnings.empty()) s["warnings"] = step.solution.warnings;
    }
    steps.push_back(s);
  }
  return {{"schedule", run.schedule.path},
          {"columns", run.schedule.columns},
          {"key_times_s", run.schedule.time_s},
          {"subject", subject_json(run.model.subject)},
          {"scoliosis", scoliosis_curve_json(run.model.scoliosis)},
          {"steps", steps},
          {"failed", run.failed},
          {"inertia",
           {{"first_frequency_hz", finite_or_null(run.first_frequency_hz)},
            {"fastest_ramp_s", finite_or_null(run.fastest_ramp_s)},
            {"overshoot_bound", finite_or_null(run.overshoot_bound)}}},
          {"dynamic", dynamic_json(run)},
          {"seconds", run.seconds},
          {"units",
           {{"force", "N"},
            {"moment", "N·mm"},
            {"translation", "mm"},
            {"rotation", "deg"},
            {"t1_displacement", "tx, ty, tz (mm), rx, ry, rz (deg)"}}}};
}

void run_schedule_dynamics(ScheduleRun& run, const spine::DynamicsOptions& options) {
  if (run.failed)
    throw std::invalid_argument("--dynamic: a step reached no equilibrium; the motion needs all");
  if (run.steps.size() < 2) throw std::invalid_argument("--dynamic: the schedule has one time");
  const Timer timer;
  const auto& steps = run.steps;
  // The muscle forces of the step interval holding t, linear in time.
  const auto forces_at = [&steps](double t) {
    std::size_t k = 1;
    while (k + 1 < steps.size() && steps[k].t_s < t) ++k;
    const Eigen::VectorXd& a = steps[k - 1].solution.recruitment.force_n;
    const Eigen::VectorXd& b = steps[k].solution.recruitment.force_n;
    if (a.size() == 0 || b.size() == 0) return Eigen::VectorXd();
    const double w =
        std::clamp((t - steps[k - 1].t_s) / (steps[k].t_s - steps[k - 1].t_s), 0.0, 1.0);
    return Eigen::VectorXd((1 - w) * a + w * b);
  };
  const spine::TimeLoads at = [&](double t, std::vector<spine::ExternalLoad>& loads,
                                  Eigen::VectorXd& F) {
    loads = schedule_loads(run.schedule, std::clamp(t, steps.front().t_s, steps.back().t_s));
    F = forces_at(t);
  };
  const std::vector<spine::DynamicStep> motion =
      spine::integrate_spine(run.model, at, steps.front().solution.theta, steps.front().t_s,
                             steps.back().t_s, options);
  run.dynamic.clear();
  std::size_t j = 1;
  for (const ScheduleStep& step : steps) {
    while (j + 1 < motion.size() && motion[j].t_s < step.t_s) ++j;
    const spine::DynamicStep &p = motion[j - 1], &q = motion[j];
    const double w = q.t_s > p.t_s ? std::clamp((step.t_s - p.t_s) / (q.t_s - p.t_s), 0.0, 1.0) : 1;
    const Eigen::VectorXd theta = (1 - w) * p.theta + w * q.theta,
                          accel = (1 - w) * p.acceleration + w * q.acceleration;
    std::vector<spine::ExternalLoad> loads;
    Eigen::VectorXd F;
    at(step.t_s, loads, F);
    for (const spine::ExternalLoad& l : spine::inertial_loads(run.model, theta, accel))
      loads.push_back(l);
    const spine::SpineSolution s = spine::spine_state(run.model, loads, F, theta);
    DynamicSample d;
    d.t_s = step.t_s;
    d.t1_displacement = s.displacement.row(0).transpose();
    d.l4l5_axial_n = s.joints[std::size_t(spine::joint_index("L4-L5"))].axial_n;
    d.l5s1_axial_n = s.joints.back().axial_n;
    run.dynamic.push_back(d);
  }
  run.dynamic_dt_s = options.dt_s;
  run.damping_ratio = options.damping_ratio;
  run.dynamic_steps = int(motion.size()) - 1;
  run.dynamic_seconds = timer.seconds();
}

/// The motion beside the quasi-static answer, when it was integrated.
void print_dynamics(std::ostream& os, const ScheduleRun& run) {
  if (run.dynamic.empty()) return;
  os << "\nThe motion (Newmark average acceleration, " << fixed(1000 * run.dynamic_dt_s, 1)
     << " ms steps, damping ratio " << fixed(run.damping_ratio, 2) << " at the first mode; "
     << run.dynamic_steps << " steps in " << fixed(run.dynamic_seconds, 2)
     << " s), beside the quasi-static answer:\n";
  TextTable table({"time (s)", "L4-L5 axial (N)", "quasi-static", "L5-S1 axial (N)",
                   "quasi-static", "T1 tz (mm)", "quasi-static"},
                  0);
  const int l4 = spine::joint_index("L4-L5");
  for (std::size_t k = 0; k < run.dynamic.size(); ++k) {
    const DynamicSample& d = run.dynamic[k];
    const spine::SpineSolution& s = run.steps[k].solution;
    table.add({fixed(d.t_s, 3), fixed(d.l4l5_axial_n, 1),
               fixed(s.joints[std::size_t(l4)].axial_n, 1),
               fixed(d.l5s1_axial_n, 1), fixed(s.joints.back().axial_n, 1),
               fixed(d.t1_displacement[2], 2), fixed(s.displacement(0, 2), 2)});
  }
  table.print(os, false);
}

/// Whether inertia matters: the first natural frequency beside the fastest ramp.
void print_inertia(std::ostream& os, const ScheduleRun& run) {
  if (!std::isfinite(run.first_frequency_hz)) return;
  os << "\nInertia: the spine's first natural frequency at " << fixed(run.steps.front().t_s, 3)
     << " s is " << fixed(run.first_frequency_hz, 2) << " Hz (period "
     << fixed(1 / run.first_frequency_hz, 3) << " s)";
  if (!std::isfinite(run.fastest_ramp_s)) {
    os << "; the loads do not change.\n";
    return;
  }
  os << "; the fastest ramp lasts " << fixed(run.fastest_ramp_s, 3)
     << " s, so the motion may overshoot the quasi-static answer by up to "
     << fixed(100 * run.overshoot_bound, 1) << " % of a ramp's step"
     << (run.overshoot_bound > kInertiaMatters
             ? " (undamped bound; damping lowers it): inertia may matter here, and this "
               "quasi-static sequence may not be the motion.\n"
             : " (undamped bound): quasi-static.\n");
}

void print_schedule(std::ostream& os, const ScheduleRun& run) {
  os << "Loads in time (" << run.schedule.path << "): " << run.steps.size()
     << " quasi-static equilibria, body " << subject_text(run.model.subject);
  const spine::ScoliosisCurve& c = run.model.scoliosis;
  if (c.cobb_deg != 0)
    os << ", resting in a " << fixed(c.cobb_deg, 0) << " deg " << c.type << " scoliosis ("
       << c.upper_end << "-" << c.lower_end << ", apex " << c.apex << ")";
  os << "\n\n";
  std::vector<std::string> header = {"time (s)"};
  for (const auto& c : run.schedule.columns) header.push_back(c);
  for (const char* h : {"L4-L5 axial (N)", "L5-S1 axial (N)", "L5-S1 shear AP (N)",
                        "T1 tz (mm)", "T1 rx (deg)"})
    header.push_back(h);
  TextTable table(header, 0);
  const int l4 = spine::joint_index("L4-L5"), l5 = spine::joint_index("L5-S1");
  for (const auto& step : run.steps) {
    std::vector<std::string> row = {fixed(step.t_s, 3)};
    for (const auto& t : run.schedule.targets) row.push_back(fixed(load_value(step, t), 1));
    if (step.error.empty()) {
      const auto& s = step.solution;
      row.push_back(fixed(s.joints[std::size_t(l4)].axial_n, 1));
      row.push_back(fixed(s.joints[std::size_t(l5)].axial_n, 1));
      row.push_back(fixed(s.joints[std::size_t(l5)].shear_ap_n, 1));
      row.push_back(fixed(s.displacement(0, 2), 2));
      row.push_back(fixed(s.displacement(0, 3), 2));
    } else {
      for (int k = 0; k < 5; ++k) row.push_back("-");
    }
    table.add(row);
  }
  table.print(os, false);
  for (const auto& step : run.steps)
    if (!step.error.empty())
      os << "no equilibrium at " << fixed(step.t_s, 3) << " s: " << step.error << "\n";
  print_inertia(os, run);
  print_dynamics(os, run);
  os << "\nTotal " << fixed(run.seconds + run.dynamic_seconds, 2) << " s\n";
}

void write_schedule_recording(const ScheduleRun& run, const std::string& path) {
  std::vector<const ScheduleStep*> solved;
  for (const auto& step : run.steps)
    if (step.error.empty()) solved.push_back(&step);
  if (solved.size() < 2)
    throw std::invalid_argument("--record: fewer than two steps reached equilibrium");
  // The recording is a servo's: one row a millisecond (the offline discs step 1 ms a row).
  // Between solved steps each vertebra moves along the straight line and the geodesic rotation
  // from one equilibrium pose to the next. A curved spine's motions are recorded from its rest
  // posture, where its (wedged) discs are stress-free, as the haptic stage records them.
  const std::vector<spine::Pose> rest =
      run.model.rest_posture.size() > 0 ? spine::vertebra_poses(run.model, run.model.rest_posture)
                                        : std::vector<spine::Pose>();
  constexpr double kTickS = 1e-3;
  const double t0 = solved.front()->t_s, t1 = solved.back()->t_s;
  const auto ticks = static_cast<std::int64_t>(std::floor((t1 - t0) / kTickS + 1e-9)) + 1;
  if (ticks > 10'000'000)
    throw std::invalid_argument("--record: the schedule lasts over 10000 s of 1 ms rows");
  haptics::HapticRecordingWriter writer(path, "a load schedule (" + run.schedule.path + ")",
                                        &run.model, "quasi-static schedule");
  std::vector<haptics::TickRecord> block;
  std::size_t seg = 0;
  for (std::int64_t k = 0; k < ticks; ++k) {
    const double t = t0 + double(k) * kTickS;
    while (seg + 2 < solved.size() && solved[seg + 1]->t_s <= t) ++seg;
    const ScheduleStep& a = *solved[seg];
    const ScheduleStep& b = *solved[seg + 1];
    const double w = std::clamp((t - a.t_s) / (b.t_s - a.t_s), 0.0, 1.0);
    haptics::TickRecord r;
    r.t_s = t;
    r.tick = k + 1;
    r.probe_mm = r.force_n = r.proxy_mm = Eigen::Vector3d::Zero();
    r.compliant = true;
    for (std::size_t v = 0; v < a.solution.poses.size(); ++v) {
      const spine::Pose& pa = a.solution.poses[v];
      const spine::Pose& pb = b.solution.poses[v];
      const Eigen::Matrix3d R =
          pa.R * spine::rotation_exp(w * spine::rotation_log(pa.R.transpose() * pb.R));
      const Eigen::Vector3d t_abs = pa.t + w * (pb.t - pa.t);
      if (rest.empty()) {
        r.R[v] = R.cast<float>();
        r.t[v] = t_abs.cast<float>();
      } else {  // x = R (R0ᵀ(y − t0)) + t for y on the vertebra at rest
        const Eigen::Matrix3d Rr = R * rest[v].R.transpose();
        r.R[v] = Rr.cast<float>();
        r.t[v] = (t_abs - Rr * rest[v].t).cast<float>();
      }
    }
    block.push_back(r);
    if (block.size() == 4096 || k + 1 == ticks) {
      writer.append(block.data(), block.size());
      block.clear();
    }
  }
  writer.finish();
}

}  // namespace spinesim::studies

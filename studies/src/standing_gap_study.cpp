// The standing-gap mechanisms, each measured (standing_gap_study.hpp; docs/seating.md).
#include "spinesim/studies/standing_gap_study.hpp"

#include "spinesim/common/timer.hpp"
#include "spinesim/output/format.hpp"
#include "spinesim/output/table.hpp"
#include "spinesim/spine/equilibrium.hpp"
#include "spinesim/studies/spine_studies.hpp"

#include <cmath>
#include <stdexcept>

namespace spinesim::studies {
namespace {
using nlohmann::json;

const SittingValidation::Row& row(const SittingValidation& v, const std::string& id) {
  for (const auto& r : v.rows)
    if (r.id == id) return r;
  throw std::logic_error("posture comparison has no row '" + id + "'");
}

spine::ModelOptions with_muscles(spine::ModelOptions o, double co_contraction, double tone) {
  o.co_contraction = co_contraction;
  o.muscle_tone = tone;
  return o;
}

/// Standing L4-L5 compression of the model alone (no pre-stress), N.
double standing_l4l5(const std::string& data_dir, const spine::ModelOptions& o) {
  const spine::SpineSolution s = spine::solve_spine(spine::load_spine_model(data_dir, o), {});
  if (!s.converged) throw std::runtime_error("standing-gap: the standing spine did not converge");
  return s.joints[std::size_t(spine::joint_index("L4-L5"))].axial_n;
}

bool inside(double v, double lo, double hi) { return v >= lo && v <= hi; }

StandingGapCase measure(const std::string& data_dir, const spine::ModelOptions& model,
                        const StandingGapStudy& s, StandingGapCase c) {
  const SittingValidation v = run_posture_comparison(
      data_dir, with_muscles(model, c.co_contraction, c.muscle_tone), c.prestress_mpa);
  c.standing_n = row(v, "standing").ours;
  c.sitting_n = row(v, "sitting-unsupported").ours * c.standing_n;
  c.chair_n = row(v, "sitting-in-chair").ours * c.standing_n;
  c.crate_n = row(v, "crate").ours * c.standing_n;
  c.in_window = int(inside(c.crate_n, s.crate_lo_n, s.crate_hi_n));
  for (const auto& r : v.rows) c.in_window += int(r.pass);
  return c;
}

/// The level (0 … 0.5) of co-contraction (`tone` false) or tone that brings standing, with the
/// pre-stress, to the in-vivo load: bisection on the standing solve alone.
StandingGapCase bisect(const std::string& data_dir, const spine::ModelOptions& model,
                       const StandingGapStudy& s, StandingGapCase c, bool tone) {
  const double target = s.standing_target_n - s.prestress_force_n;
  const auto standing_at = [&](double level) {
    return standing_l4l5(data_dir, with_muscles(model, tone ? 0 : level, tone ? level : 0));
  };
  double lo = 0, hi = 0.5;
  if (standing_at(hi) < target) {
    c.found = false;
    lo = hi;
  } else {
    for (int i = 0; i < 14 && hi - lo > 1e-4; ++i) {
      const double mid = 0.5 * (lo + hi);
      (standing_at(mid) < target ? lo : hi) = mid;
    }
  }
  const double level = c.found ? 0.5 * (lo + hi) : lo;
  (tone ? c.muscle_tone : c.co_contraction) = level;
  return measure(data_dir, model, s, c);
}

std::string percent(double fraction) { return fixed(100 * fraction, 1) + " %"; }

}  // namespace

StandingGapStudy run_standing_gap_study(const std::string& data_dir,
                                        const spine::ModelOptions& model, double prestress_mpa,
                                        const StageHooks& hooks) {
  if (!std::isfinite(prestress_mpa) || prestress_mpa < 0 || prestress_mpa > 0.5)
    throw std::invalid_argument("the swelling pressure must lie within 0 … 0.5 MPa");
  Timer timer;
  StandingGapStudy s;
  {
    const SittingValidation v =
        run_posture_comparison(data_dir, with_muscles(model, 0, 0), prestress_mpa);
    const auto& st = row(v, "standing");
    s.standing_target_n = st.target;
    s.tolerance = st.high / st.target - 1;
    s.area_mm2 = v.disc_area_mm2;
    s.prestress_force_n = v.swelling_n;
    s.sitting_ratio = row(v, "sitting-unsupported").target;
    s.chair_ratio = row(v, "sitting-in-chair").target;
    s.crate_ratio = row(v, "crate").target;
    const WilkeCase w = run_wilke_case(data_dir, model);
    s.crate_lo_n = w.target_n * (1 - w.tolerance);
    s.crate_hi_n = w.target_n * (1 + w.tolerance);
  }

  const double p = prestress_mpa;
  const std::vector<StandingGapCase> plan = {
      {"the model as it stands", "none", 0, 0, 0},
      {"+ swelling pressure " + fixed(p, 2) + " MPa", "swelling", p, 0, 0},
      {"co-contraction 2 %", "co-contraction", 0, 0.02, 0},
      {"co-contraction 5 %", "co-contraction", 0, 0.05, 0},
      {"resting tone 2 %", "tone", 0, 0, 0.02},
      {"resting tone 5 %", "tone", 0, 0, 0.05},
      {"swelling + co-contraction 5 %", "swelling + co-contraction", p, 0.05, 0},
      {"swelling + tone 5 %", "swelling + tone", p, 0, 0.05}};
  for (const StandingGapCase& c : plan) {
    hooks.begin_stage(c.name);
    s.cases.push_back(measure(data_dir, model, s, c));
    hooks.end_stage("standing " + fixed(s.cases.back().standing_n, 0) + " N");
  }
  for (const bool tone : {false, true}) {
    StandingGapCase c;
    c.mechanism = tone ? "swelling + tone" : "swelling + co-contraction";
    c.prestress_mpa = p;
    hooks.begin_stage(c.mechanism + " to the in-vivo standing load");
    c = bisect(data_dir, model, s, c, tone);
    c.name = c.mechanism + " " + percent(tone ? c.muscle_tone : c.co_contraction) +
             (c.found ? " (standing matched)" : " (largest tried: standing not reached)");
    s.cases.push_back(c);
    hooks.end_stage(c.name);
  }
  s.seconds = timer.seconds();
  return s;
}

void print_standing_gap_study(std::ostream& os, const StandingGapStudy& s, bool markdown) {
  const double t = s.tolerance;
  TextTable tab({"case", "standing (N)", "sitting / standing", "leaning back / standing",
                 "crate / standing", "crate (N)", "in window"},
                1);
  tab.add({"in vivo (window)",
           fixed(s.standing_target_n, 0) + " (" + fixed(s.standing_target_n * (1 - t), 0) + "–" +
               fixed(s.standing_target_n * (1 + t), 0) + ")",
           fixed(s.sitting_ratio, 2), fixed(s.chair_ratio, 2), fixed(s.crate_ratio, 2),
           fixed(s.crate_lo_n, 0) + "–" + fixed(s.crate_hi_n, 0), ""});
  for (const StandingGapCase& c : s.cases)
    tab.add({c.name, fixed(c.standing_n, 0), fixed(c.sitting_n / c.standing_n, 2),
             fixed(c.chair_n / c.standing_n, 2), fixed(c.crate_n / c.standing_n, 2),
             fixed(c.crate_n, 0), std::to_string(c.in_window) + " of 5"});
  tab.print(os, markdown);
  os << "  L4-L5 compression, joint frame. Swelling pressure: " << fixed(s.prestress_force_n, 0)
     << " N (the pressure × " << fixed(s.area_mm2, 0)
     << " mm², the comparison's area, × the body's length²) added to every posture's disc\n  "
        "compression, "
        "self-equilibrated by the fibres and ligaments (the joints' reactions do not change). "
        "Co-contraction: every\n  muscle at least that share of its maximum, counted by the "
        "criterion; tone: carried, not counted. Windows ±"
     << fixed(100 * t, 0) << " %.\n";
}

json standing_gap_study_json(const StandingGapStudy& s) {
  json cases = json::array();
  for (const StandingGapCase& c : s.cases)
    cases.push_back({{"name", c.name},
                     {"mechanism", c.mechanism},
                     {"prestress_mpa", c.prestress_mpa},
                     {"co_contraction", c.co_contraction},
                     {"muscle_tone", c.muscle_tone},
                     {"standing_n", c.standing_n},
                     {"sitting_n", c.sitting_n},
                     {"chair_n", c.chair_n},
                     {"crate_n", c.crate_n},
                     {"in_window", c.in_window},
                     {"found", c.found}});
  return {{"standing_target_n", s.standing_target_n},
          {"tolerance", s.tolerance},
          {"area_mm2", s.area_mm2},
          {"prestress_force_n", s.prestress_force_n},
          {"ratios_in_vivo",
           {{"sitting", s.sitting_ratio}, {"chair", s.chair_ratio}, {"crate", s.crate_ratio}}},
          {"crate_window_n", {s.crate_lo_n, s.crate_hi_n}},
          {"cases", cases},
          {"seconds", s.seconds}};
}

}  // namespace spinesim::studies

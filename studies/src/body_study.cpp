// The spine studies for each sourced body, side by side (body_study.hpp).
#include "spinesim/studies/body_study.hpp"

#include "spinesim/common/timer.hpp"
#include "spinesim/output/format.hpp"
#include "spinesim/output/table.hpp"

#include <sstream>

namespace spinesim::studies {
namespace {
using nlohmann::json;

int matches(const std::vector<Finding>& findings) {
  int n = 0;
  for (const Finding& f : findings) n += f.match;
  return n;
}

/// One quantity across the bodies, with its window (low > high: no window).
struct Quantity {
  std::string name, unit;
  double low = 1, high = 0;
  std::vector<double> values;
  int decimals = 1;
  bool has_window() const { return low <= high; }
  bool pass(double v) const { return v >= low && v <= high; }
};

const SittingValidation::Row& posture_row(const SittingValidation& v, const std::string& id) {
  for (const auto& r : v.rows)
    if (r.id == id) return r;
  throw std::logic_error("posture comparison has no row '" + id + "'");
}

std::vector<Quantity> quantities(const BodyStudy& s) {
  std::vector<Quantity> q;
  if (s.runs.empty()) return q;
  const McGillCase& m0 = s.runs.front().validation.mcgill;
  const WilkeCase& w0 = s.runs.front().validation.wilke;
  const double no = 1;  // low > high: no window
  q.push_back({"McGill: T7 force for 238 N·m at L5-S1", "N", no, 0, {}, 1});
  q.push_back({"McGill: L5-S1 axial, joint frame", "N", m0.axial_lo_n, m0.axial_hi_n, {}, 0});
  q.push_back({"McGill: L5-S1 shear, joint frame", "N", 0, m0.shear_max_n, {}, 0});
  q.push_back({"Wilke crate: L4-L5 axial, joint frame",
               "N",
               w0.target_n * (1 - w0.tolerance),
               w0.target_n * (1 + w0.tolerance),
               {},
               0});
  const std::vector<std::string> posture_ids = {"standing", "sitting-unsupported",
                                                "sitting-in-chair", "crate"};
  for (const std::string& id : posture_ids) {
    const auto& r = posture_row(s.runs.front().postures, id);
    q.push_back({r.what, r.unit, r.low, r.high, {}, r.unit == "N" ? 0 : 2});
  }
  q.push_back({"fusion: T1 |t| under the forward force, normal spine", "mm", no, 0, {}, 2});
  q.push_back({"fusion: thesis statements that hold", "", no, 0, {}, 0});
  q.push_back({"trends: thesis statements that hold", "", no, 0, {}, 0});
  for (const BodyStudyRun& r : s.runs) {
    std::size_t i = 0;
    q[i++].values.push_back(r.validation.mcgill.t7_force_n);
    q[i++].values.push_back(r.validation.mcgill.l5s1.axial_n);
    q[i++].values.push_back(joint_shear_n(r.validation.mcgill.l5s1));
    q[i++].values.push_back(r.validation.wilke.l4l5.axial_n);
    for (const std::string& id : posture_ids)
      q[i++].values.push_back(posture_row(r.postures, id).ours);
    q[i++].values.push_back(r.fusion.run("normal", "forward").t1_translation_mm.norm());
    q[i++].values.push_back(matches(r.fusion.findings));
    q[i++].values.push_back(matches(r.trends.findings));
  }
  return q;
}

std::string window_text(const Quantity& q) {
  if (!q.has_window()) return "-";
  const auto number = [&q](double v) { return q.unit == "N" ? fixed(v, 0) : significant(v, 3); };
  if (q.low == 0) return "≤ " + number(q.high);
  return number(q.low) + " … " + number(q.high);
}

}  // namespace

BodyStudy run_body_study(const std::string& data_dir, double force_n,
                         const spine::ModelOptions& model, const std::vector<std::string>& names,
                         const StageHooks& hooks) {
  Timer timer;
  std::vector<spine::NamedBody> bodies;
  if (names.empty())
    bodies = spine::named_bodies(data_dir);
  else
    for (const std::string& n : names) bodies.push_back(spine::named_body(data_dir, n));
  BodyStudy s;
  s.force_n = force_n;
  for (const spine::NamedBody& b : bodies) {
    BodyStudyRun r;
    r.body = b;
    spine::ModelOptions o = model;
    o.subject = b.subject;
    hooks.begin_stage(b.name + ": validation");
    r.validation = run_validation_study(data_dir, o);
    hooks.end_stage();
    hooks.begin_stage(b.name + ": fusion");
    r.fusion = run_fusion_study(data_dir, force_n, o);
    hooks.end_stage(std::to_string(matches(r.fusion.findings)) + " of " +
                    std::to_string(r.fusion.findings.size()) + " hold");
    hooks.begin_stage(b.name + ": trends");
    r.trends = run_trends_study(data_dir, force_n, o);
    hooks.end_stage(std::to_string(matches(r.trends.findings)) + " of " +
                    std::to_string(r.trends.findings.size()) + " hold");
    hooks.begin_stage(b.name + ": standing, sitting, crate");
    r.postures = run_posture_comparison(data_dir, o);
    hooks.end_stage();
    s.runs.push_back(std::move(r));
  }
  s.seconds = timer.seconds();
  return s;
}

void print_body_study(std::ostream& os, const BodyStudy& s, bool markdown) {
  TextTable bodies({"body", "sex", "height (m)", "mass (kg)", "BMI (kg/m²)", "source"}, 2);
  for (const BodyStudyRun& r : s.runs) {
    const spine::Subject& b = r.body.subject;
    bodies.add({r.body.name, spine::sex_name(b.sex), fixed(b.height_m, 3), fixed(b.body_mass_kg, 1),
                fixed(b.body_mass_kg / (b.height_m * b.height_m), 1), r.body.source});
  }
  bodies.print(os, markdown);
  os << "\n";
  std::vector<std::string> header = {"quantity", "window (one male subject)"};
  for (const BodyStudyRun& r : s.runs) header.push_back(r.body.name);
  TextTable t(header, 2);
  for (const Quantity& q : quantities(s)) {
    std::vector<std::string> row = {q.name + (q.unit.empty() ? "" : " (" + q.unit + ")"),
                                    window_text(q)};
    for (std::size_t i = 0; i < q.values.size(); ++i) {
      std::string cell = fixed(q.values[i], q.decimals);
      if (q.name.rfind("fusion: thesis", 0) == 0)
        cell += " of " + std::to_string(s.runs[i].fusion.findings.size());
      else if (q.name.rfind("trends: thesis", 0) == 0)
        cell += " of " + std::to_string(s.runs[i].trends.findings.size());
      else if (q.has_window())
        cell += q.pass(q.values[i]) ? " in" : " out";
      row.push_back(cell);
    }
    t.add(row);
  }
  t.print(os, markdown);
  os << "  The same loads for every body: " << fixed(s.force_n, 0)
     << " N on T1 (fusion, trends), McGill's 238 N·m, Wilke's 19.8 kg crate. The windows are "
        "one male\n  subject's (McGill & Norman's lifter, Wilke's 70 kg volunteer): for the other "
        "bodies they are shown\n  for scale, not as targets. in/out: inside or outside the "
        "window. The posture rows include the disc's\n  swelling pressure (`study "
        "seating-validation`).\n";
}

json body_study_json(const BodyStudy& s) {
  json runs = json::array();
  for (const BodyStudyRun& r : s.runs)
    runs.push_back({{"body", r.body.name},
                    {"source", r.body.source},
                    {"sex", spine::sex_name(r.body.subject.sex)},
                    {"height_m", r.body.subject.height_m},
                    {"body_mass_kg", r.body.subject.body_mass_kg},
                    {"validation", validation_json(r.validation)},
                    {"fusion", fusion_json(r.fusion)},
                    {"trends", trends_json(r.trends)},
                    {"postures", sitting_validation_json(r.postures)}});
  json table = json::array();
  for (const Quantity& q : quantities(s)) {
    json row = {{"quantity", q.name}, {"unit", q.unit}, {"values", q.values}};
    if (q.has_window()) row["window"] = {q.low, q.high};
    table.push_back(row);
  }
  return {{"force_n", s.force_n}, {"runs", runs}, {"table", table}, {"seconds", s.seconds}};
}

std::string body_study_csv(const BodyStudy& s) {
  std::ostringstream os;
  os.precision(10);
  os << "quantity,unit,window_low,window_high";
  for (const BodyStudyRun& r : s.runs) os << "," << r.body.name;
  os << "\n";
  for (const Quantity& q : quantities(s)) {
    os << "\"" << q.name << "\"," << q.unit << ",";
    if (q.has_window())
      os << q.low << "," << q.high;
    else
      os << ",";
    for (double v : q.values) os << "," << v;
    os << "\n";
  }
  return os.str();
}

}  // namespace spinesim::studies

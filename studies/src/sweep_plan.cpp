#include "spinesim/studies/sweep_plan.hpp"

#include "spinesim/studies/sensitivity.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <stdexcept>

namespace spinesim::studies {
namespace {

using nlohmann::json;

constexpr std::size_t kMostPoints = 1'000'000;

[[noreturn]] void refuse(const std::string& where, const std::string& field,
                         const std::string& why) {
  throw std::invalid_argument(where + ": " + field + ": " + why);
}

void require_known(const json& object, const std::vector<std::string>& known,
                   const std::string& where, const std::string& field) {
  for (const auto& item : object.items())
    if (std::find(known.begin(), known.end(), item.key()) == known.end())
      refuse(where, field + item.key(), "not a field of a sweep plan here");
}

double finite_number(const json& v, const std::string& where, const std::string& field) {
  if (!v.is_number() || !std::isfinite(v.get<double>()))
    refuse(where, field, "give a finite number");
  return v.get<double>();
}

SweepParameter parse_parameter(const std::string& name, const json& p, const std::string& where) {
  const std::string field = "parameters." + name;
  if (!p.is_object()) refuse(where, field, "give {\"values\": [...]} or {\"from\", \"to\"}");
  require_known(p, {"values", "from", "to", "steps"}, where, field + ".");
  SweepParameter out;
  out.option = name;
  if (p.contains("values")) {
    if (p.contains("from") || p.contains("to") || p.contains("steps"))
      refuse(where, field, "give either values or a range, not both");
    const json& v = p.at("values");
    if (!v.is_array() || v.empty()) refuse(where, field + ".values", "give a non-empty list");
    for (const auto& x : v) {
      if (!(x.is_number() || x.is_string() || x.is_boolean()))
        refuse(where, field + ".values", "each value is a number, a string or true/false");
      if (x.is_number()) finite_number(x, where, field + ".values");
      out.values.push_back(x);
    }
    return out;
  }
  if (!p.contains("from") || !p.contains("to"))
    refuse(where, field, "give values, or a range from … to");
  out.from = finite_number(p.at("from"), where, field + ".from");
  out.to = finite_number(p.at("to"), where, field + ".to");
  if (!(out.from < out.to)) refuse(where, field, "the range needs from < to");
  if (p.contains("steps")) {
    const json& s = p.at("steps");
    if (!s.is_number_integer() || s.get<long long>() < 2 || s.get<long long>() > 100000)
      refuse(where, field + ".steps", "give a whole number from 2 to 100000");
    const long long n = s.get<long long>();
    for (long long k = 0; k < n; ++k)
      out.values.push_back(k + 1 == n ? out.to
                                      : out.from + (out.to - out.from) * double(k) / double(n - 1));
  }
  return out;
}

/// A whole number of a design's object in [lo, hi] (`fallback` when absent and not required).
int design_number(const json& o, const std::string& key, int lo, int hi, int fallback,
                  const std::string& where, const std::string& field) {
  if (!o.contains(key)) {
    if (fallback < 0) refuse(where, field + key, "required");
    return fallback;
  }
  const json& v = o.at(key);
  if (!v.is_number_integer() || v.get<long long>() < lo || v.get<long long>() > hi)
    refuse(where, field + key,
           "give a whole number from " + std::to_string(lo) + " to " + std::to_string(hi));
  return int(v.get<long long>());
}

void parse_sensitivity_design(const json& d, SweepPlan& plan, const std::string& where) {
  plan.design = d.begin().key();
  const json& o = d.begin().value();
  const std::string field = "design." + plan.design + ".";
  if (!o.is_object()) refuse(where, "design." + plan.design, "give an object");
  if (o.contains("seed")) {
    const json& s = o.at("seed");
    if (!s.is_number_unsigned() && !(s.is_number_integer() && s.get<long long>() >= 0))
      refuse(where, field + "seed", "give a whole number >= 0");
    plan.seed = s.is_number_unsigned() ? s.get<std::uint64_t>() : std::uint64_t(s.get<long long>());
  }
  plan.resamples = design_number(o, "resamples", 10, 100000, 1000, where, field);
  if (o.contains("confidence")) {
    const json& c = o.at("confidence");
    if (!c.is_number() || !(c.get<double>() >= 0.5 && c.get<double>() < 1))
      refuse(where, field + "confidence", "give a number from 0.5 to below 1, e.g. 0.95");
    plan.confidence = c.get<double>();
  }
  if (plan.design == "morris") {
    require_known(o, {"trajectories", "levels", "seed", "resamples", "confidence"}, where, field);
    plan.trajectories = design_number(o, "trajectories", 2, 100000, -1, where, field);
    plan.levels = design_number(o, "levels", 4, 1000, 4, where, field);
    if (plan.levels % 2 != 0) refuse(where, field + "levels", "give an even number (Morris's Δ)");
  } else {
    require_known(o, {"base_points", "seed", "resamples", "confidence"}, where, field);
    plan.base_points = design_number(o, "base_points", 2, 1000000, -1, where, field);
  }
}

void parse_design(const json& d, SweepPlan& plan, const std::string& where) {
  if (d.is_string()) {
    plan.design = d.get<std::string>();
    if (plan.design != "grid" && plan.design != "zip")
      refuse(where, "design",
             "\"" + plan.design +
                 "\": give \"grid\", \"zip\" or {\"latin_hypercube\": {\"points\": "
                 "N, \"seed\": S}}");
    return;
  }
  if (!d.is_object() || d.size() != 1 ||
      !(d.contains("latin_hypercube") || d.contains("morris") || d.contains("sobol")))
    refuse(where, "design",
           "give \"grid\", \"zip\" or {\"latin_hypercube\" | \"morris\" | \"sobol\": {…}}");
  if (!d.contains("latin_hypercube")) return parse_sensitivity_design(d, plan, where);
  const json& l = d.at("latin_hypercube");
  if (!l.is_object()) refuse(where, "design.latin_hypercube", "give {\"points\": N, \"seed\": S}");
  require_known(l, {"points", "seed"}, where, "design.latin_hypercube.");
  plan.design = "latin_hypercube";
  const json& n = l.value("points", json());
  if (!n.is_number_integer() || n.get<long long>() < 2 ||
      n.get<long long>() > static_cast<long long>(kMostPoints))
    refuse(where, "design.latin_hypercube.points", "give a whole number from 2 to 1000000");
  plan.sample_points = int(n.get<long long>());
  if (l.contains("seed")) {
    const json& s = l.at("seed");
    if (!s.is_number_unsigned() && !(s.is_number_integer() && s.get<long long>() >= 0))
      refuse(where, "design.latin_hypercube.seed", "give a whole number >= 0");
    plan.seed = s.is_number_unsigned() ? s.get<std::uint64_t>() : std::uint64_t(s.get<long long>());
  }
}

void check_design(const SweepPlan& plan, const std::string& where) {
  const std::size_t k = plan.parameters.size();
  std::size_t total = plan.design == "latin_hypercube" ? std::size_t(plan.sample_points)
                      : plan.design == "morris"        ? std::size_t(plan.trajectories) * (k + 1)
                      : plan.design == "sobol"         ? std::size_t(plan.base_points) * (k + 2)
                                                       : 1;
  for (const auto& p : plan.parameters) {
    if (plan.design == "latin_hypercube") continue;
    if (plan.design == "morris" || plan.design == "sobol") {
      if (!p.values.empty())
        refuse(where, "parameters." + p.option,
               plan.design + " needs a range {\"from\", \"to\"} (without steps)");
      continue;
    }
    if (p.values.empty())
      refuse(where, "parameters." + p.option,
             "a continuous range needs a sampling design (latin_hypercube) or steps");
    if (plan.design == "zip") {
      if (p.values.size() != plan.parameters.front().values.size())
        refuse(where, "parameters." + p.option,
               "zip needs lists of one length (" + std::to_string(p.values.size()) + " against " +
                   std::to_string(plan.parameters.front().values.size()) + ")");
      total = p.values.size();
    } else {
      total *= p.values.size();
      if (total > kMostPoints) refuse(where, "parameters", "the grid has more than 10^6 points");
    }
  }
  if (total > kMostPoints) refuse(where, "design", "more than 10^6 points");
}

/// The unit-cube design of a morris or sobol plan.
UnitPoints sensitivity_design(const SweepPlan& plan) {
  const int k = int(plan.parameters.size());
  return plan.design == "morris" ? morris_design(k, plan.trajectories, plan.levels, plan.seed)
                                 : saltelli_design(k, plan.base_points, plan.seed);
}

}  // namespace

std::uint64_t SplitMix64::next() {
  std::uint64_t z = (state_ += 0x9e3779b97f4a7c15ull);
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
  return z ^ (z >> 31);
}

namespace {

/// "windows": {"output": {"low": L, "high": H, "source": "…"}}: measurements of outputs, for the
/// uncertainty a Latin hypercube's points carry (uncertainty.hpp).
void parse_windows(const json& w, SweepPlan& plan, const std::string& where) {
  if (!w.is_object() || w.empty())
    refuse(where, "windows", "give {\"output\": {\"low\": L, \"high\": H, \"source\": \"…\"}}");
  if (plan.design != "latin_hypercube")
    refuse(where, "windows",
           "weigh a sample of the ranges: give the design {\"latin_hypercube\": {…}}");
  for (const auto& item : w.items()) {
    const std::string field = "windows." + item.key();
    const json& o = item.value();
    if (std::none_of(plan.outputs.begin(), plan.outputs.end(),
                     [&](const auto& out) { return out.first == item.key(); }))
      refuse(where, field, "not one of the plan's outputs");
    if (!o.is_object()) refuse(where, field, "give {\"low\": L, \"high\": H}");
    require_known(o, {"low", "high", "source"}, where, field + ".");
    const json lo = o.value("low", json()), hi = o.value("high", json());
    if (!lo.is_number() || !hi.is_number() || !(lo.get<double>() > 0) ||
        !(hi.get<double>() > lo.get<double>()) || !std::isfinite(hi.get<double>()))
      refuse(where, field, "give numbers 0 < low < high (a window of a positive quantity)");
    if (o.contains("source") && !o.at("source").is_string())
      refuse(where, field + ".source", "give a string");
    plan.windows.push_back({item.key(), lo.get<double>(), hi.get<double>()});
    plan.window_sources.push_back(o.value("source", ""));
  }
}

}  // namespace

SweepPlan parse_sweep_plan(const json& j, const std::string& where) {
  if (!j.is_object()) refuse(where, "the plan", "give a JSON object");
  require_known(j,
                {"spinesim_sweep", "description", "verb", "options", "parameters", "design",
                 "outputs", "windows", "provenance"},
                where, "");
  if (!j.contains("spinesim_sweep") || j.at("spinesim_sweep") != kSweepPlanVersion)
    refuse(where, "spinesim_sweep", "give 1 (the plan format's version)");
  SweepPlan plan;
  if (j.contains("description")) {
    const json& d = j.at("description");
    if (d.is_string())
      plan.description = d.get<std::string>();
    else if (d.is_array() &&
             std::all_of(d.begin(), d.end(), [](const json& x) { return x.is_string(); }))
      for (const auto& line : d)
        plan.description += (plan.description.empty() ? "" : "\n") + line.get<std::string>();
    else
      refuse(where, "description", "give a string or a list of lines");
  }
  if (!j.contains("verb") || !j.at("verb").is_string() || j.at("verb").get<std::string>().empty())
    refuse(where, "verb", "give the verb, e.g. \"spine solve\"");
  plan.verb = j.at("verb").get<std::string>();
  if (j.contains("options")) {
    if (!j.at("options").is_object()) refuse(where, "options", "give an object");
    plan.options = j.at("options");
  }
  if (!j.contains("parameters") || !j.at("parameters").is_object() || j.at("parameters").empty())
    refuse(where, "parameters", "give at least one option to vary");
  for (const auto& item : j.at("parameters").items()) {
    if (plan.options.contains(item.key()))
      refuse(where, "parameters." + item.key(), "also a fixed option: give it in one place");
    plan.parameters.push_back(parse_parameter(item.key(), item.value(), where));
  }
  if (j.contains("design")) parse_design(j.at("design"), plan, where);
  check_design(plan, where);
  if (j.contains("outputs")) {
    if (!j.at("outputs").is_object())
      refuse(where, "outputs", "give {\"column\": \"/json/pointer\"}");
    for (const auto& item : j.at("outputs").items()) {
      const json& p = item.value();
      if (!p.is_string()) refuse(where, "outputs." + item.key(), "give a JSON pointer string");
      try {
        json::json_pointer(p.get<std::string>());
      } catch (const json::exception&) {
        refuse(
            where, "outputs." + item.key(),
            "\"" + p.get<std::string>() + "\" is not a JSON pointer (e.g. \"/joints/16/axial_n\")");
      }
      plan.outputs.emplace_back(item.key(), p.get<std::string>());
    }
  }
  if (j.contains("windows")) parse_windows(j.at("windows"), plan, where);
  return plan;
}

std::vector<SweepPoint> expand_sweep(const SweepPlan& plan) {
  std::vector<SweepPoint> points;
  const std::size_t m = plan.parameters.size();
  if (plan.design == "morris" || plan.design == "sobol") {
    const UnitPoints unit = sensitivity_design(plan);
    points.resize(unit.size());
    for (std::size_t i = 0; i < unit.size(); ++i)
      for (std::size_t k = 0; k < m; ++k) {
        const SweepParameter& p = plan.parameters[k];
        points[i].values[p.option] = p.from + unit[i][k] * (p.to - p.from);
      }
  } else if (plan.design == "latin_hypercube") {
    const std::size_t n = std::size_t(plan.sample_points);
    SplitMix64 rng(plan.seed);
    points.resize(n);
    for (std::size_t k = 0; k < m; ++k) {
      const SweepParameter& p = plan.parameters[k];
      std::vector<std::size_t> stratum(n);
      std::iota(stratum.begin(), stratum.end(), std::size_t(0));
      for (std::size_t i = n - 1; i > 0; --i)  // Fisher-Yates
        std::swap(stratum[i], stratum[std::size_t(rng.next() % (i + 1))]);
      for (std::size_t i = 0; i < n; ++i) {
        const double u = (double(stratum[i]) + rng.uniform()) / double(n);
        points[i].values[p.option] =
            p.values.empty()
                ? json(p.from + u * (p.to - p.from))
                : p.values[std::min(p.values.size() - 1, std::size_t(u * double(p.values.size())))];
      }
    }
  } else if (plan.design == "zip") {
    points.resize(plan.parameters.front().values.size());
    for (std::size_t i = 0; i < points.size(); ++i)
      for (const auto& p : plan.parameters) points[i].values[p.option] = p.values[i];
  } else {  // grid: the first parameter varies slowest
    std::size_t total = 1;
    for (const auto& p : plan.parameters) total *= p.values.size();
    points.resize(total);
    for (std::size_t i = 0; i < total; ++i) {
      std::size_t rest = i;
      for (std::size_t k = m; k-- > 0;) {
        const SweepParameter& p = plan.parameters[k];
        points[i].values[p.option] = p.values[rest % p.values.size()];
        rest /= p.values.size();
      }
    }
  }
  for (std::size_t i = 0; i < points.size(); ++i) points[i].index = int(i);
  return points;
}

json point_study(const SweepPlan& plan, const SweepPoint& point) {
  json options = plan.options;
  for (const auto& v : point.values.items()) options[v.key()] = v.value();
  json study = {{"spinesim_study", 1}, {"verb", plan.verb}, {"options", options}};
  study["description"] = "point " + std::to_string(point.index) + " of a sweep" +
                         (plan.description.empty() ? "" : ": " + plan.description);
  return study;
}

json point_outputs(const SweepPlan& plan, const json& result) {
  json out = json::object();
  for (const auto& [column, pointer] : plan.outputs) {
    const json::json_pointer at(pointer);
    out[column] = result.contains(at) ? result.at(at) : json();
  }
  return out;
}

json sweep_sensitivity(const SweepPlan& plan, const std::vector<SweepPoint>& points,
                       const std::vector<json>& outputs) {
  if (plan.design != "morris" && plan.design != "sobol") return nullptr;
  if (outputs.size() != points.size())
    throw std::invalid_argument("sweep_sensitivity: one output object per point");
  json out = {{"method", plan.design == "morris" ? "Morris elementary effects (mu*, sigma)"
                                                 : "Sobol indices (Saltelli 2010, Jansen 1999)"},
              {"runs", points.size()},
              {"bootstrap", {{"resamples", plan.resamples}, {"confidence", plan.confidence}}},
              {"outputs", json::object()}};
  // The intervals' own stream, apart from the design's and the same for every output.
  const std::uint64_t seed = plan.seed ^ 0x5eed'b007'57a9'0001ull;
  auto interval = [](const Interval& i) { return json::array({i.low, i.high}); };
  const UnitPoints unit = sensitivity_design(plan);
  std::vector<double> span;
  for (const auto& p : plan.parameters) span.push_back(p.to - p.from);
  for (const auto& [column, pointer] : plan.outputs) {
    std::vector<double> y;
    for (const auto& o : outputs) {
      const json v = o.is_object() ? o.value(column, json()) : json();
      if (!v.is_number()) break;
      y.push_back(v.get<double>());
    }
    json& entry = out["outputs"][column];
    if (y.size() != points.size()) {
      entry = {{"error", "not a number at point " + std::to_string(y.size()) +
                             " (a failed point or a non-numeric output)"}};
      continue;
    }
    try {
      if (plan.design == "morris") {
        const auto e = morris_effects(unit, y, span);
        const auto ci = morris_bootstrap(unit, y, span, plan.resamples, plan.confidence, seed);
        for (std::size_t k = 0; k < e.size(); ++k)
          entry[plan.parameters[k].option] = {
              {"mu_star", e[k].mu_star},
              {"mu", e[k].mu},
              {"sigma", e[k].sigma},
              {"mu_star_over_range", e[k].mu_star * span[k]},
              {"mu_star_interval", interval(ci[k].mu_star)},
              {"mu_star_over_range_interval",
               json::array({ci[k].mu_star.low * span[k], ci[k].mu_star.high * span[k]})}};
      } else {
        const int inputs = int(plan.parameters.size());
        const auto s = sobol_indices(inputs, y);
        const auto ci = sobol_bootstrap(inputs, y, plan.resamples, plan.confidence, seed);
        for (std::size_t k = 0; k < s.size(); ++k)
          entry[plan.parameters[k].option] = {{"first", s[k].first},
                                              {"total", s[k].total},
                                              {"first_interval", interval(ci[k].first)},
                                              {"total_interval", interval(ci[k].total)}};
      }
    } catch (const std::invalid_argument& e) {
      entry = {{"error", e.what()}};
    }
  }
  return out;
}

}  // namespace spinesim::studies

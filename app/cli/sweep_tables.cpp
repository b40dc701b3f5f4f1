#include "sweep_tables.hpp"

#include "cli_common.hpp"

#include <cmath>
#include <iostream>
#include <sstream>
#include <vector>

namespace spinesim::cli {
using nlohmann::json;

std::string csv_cell(const json& v) {
  if (v.is_null()) return "";
  if (!v.is_string()) return v.dump();  // numbers: the shortest text that reads back exactly
  const std::string t = v.get<std::string>();
  if (t.find_first_of(",\"\n") == std::string::npos) return t;
  std::string q = "\"";
  for (char c : t) q += c == '"' ? std::string("\"\"") : std::string(1, c == '\n' ? ' ' : c);
  return q + "\"";
}

/// One row per output and parameter: Morris's mu*, mu, sigma or Sobol's first and total index,
/// each with its bootstrap interval.
std::string sensitivity_csv(const studies::SweepPlan& plan, const json& summary) {
  const json& sens = summary["sensitivity"];
  const bool morris = plan.design == "morris";
  std::ostringstream csv;
  csv << "# provenance: " << summary["provenance"].dump() << "\n# "
      << sens["method"].get<std::string>() << ", " << sens["runs"] << " runs"
      << (morris ? "; per unit of the parameter" : "") << "; intervals: percentile bootstrap, "
      << sens["bootstrap"]["confidence"] << " confidence, " << sens["bootstrap"]["resamples"]
      << " resamples\n";
  const std::vector<std::string> columns =
      morris ? std::vector<std::string>{"mu_star_over_range", "mu_star", "mu", "sigma"}
             : std::vector<std::string>{"first", "total"};
  const std::vector<std::string> intervals =
      morris ? std::vector<std::string>{"mu_star_over_range", "mu_star"}
             : std::vector<std::string>{"first", "total"};
  csv << "output,parameter";
  for (const auto& c : columns) csv << "," << c;
  for (const auto& c : intervals) csv << "," << c << "_low," << c << "_high";
  csv << ",error\n";
  for (const auto& o : plan.outputs) {
    const json& e = sens["outputs"][o.first];
    if (e.contains("error")) {
      csv << csv_cell(o.first) << "," << std::string(1 + columns.size() + 2 * intervals.size(), ',')
          << csv_cell(e["error"]) << "\n";
      continue;
    }
    for (const auto& p : plan.parameters) {
      const json& v = e[p.option];
      csv << csv_cell(o.first) << "," << csv_cell(p.option);
      for (const auto& c : columns) csv << "," << csv_cell(v[c]);
      for (const auto& c : intervals)
        csv << "," << csv_cell(v[c + "_interval"][0]) << "," << csv_cell(v[c + "_interval"][1]);
      csv << ",\n";
    }
  }
  return csv.str();
}

namespace {

/// "value (low … high)" with `digits` significant digits (Morris) or `digits` decimals (Sobol).
std::string with_interval(const json& v, const std::string& key, bool morris) {
  auto text = [&](const json& x) {
    return morris ? significant(x.get<double>(), 3) : fixed(x.get<double>(), 2);
  };
  return text(v[key]) + " (" + text(v[key + "_interval"][0]) + " … " +
         text(v[key + "_interval"][1]) + ")";
}

}  // namespace

void print_sensitivity(const studies::SweepPlan& plan, const json& summary) {
  const json& sens = summary["sensitivity"];
  if (sens.is_null()) return;
  const bool morris = plan.design == "morris";
  const std::string ci =
      std::to_string(int(std::lround(100 * sens["bootstrap"]["confidence"].get<double>()))) +
      " % interval";
  std::cout << "\n"
            << sens["method"].get<std::string>() << " from " << sens["runs"] << " runs"
            << (morris ? " (mu*, sigma: output units per unit of the parameter)" : "")
            << "; in brackets the " << ci << " (bootstrap, " << sens["bootstrap"]["resamples"]
            << " resamples)\n";
  TextTable t(morris ? std::vector<std::string>{"output", "parameter", "mu* x range", "mu", "sigma"}
                     : std::vector<std::string>{"output", "parameter", "first S_i", "total S_Ti"});
  for (const auto& o : plan.outputs) {
    const json& e = sens["outputs"][o.first];
    if (e.contains("error")) {
      t.add(morris ? std::vector<std::string>{o.first, "-", "-", "-", e["error"].get<std::string>()}
                   : std::vector<std::string>{o.first, "-", "-", e["error"].get<std::string>()});
      continue;
    }
    for (const auto& p : plan.parameters) {
      const json& v = e[p.option];
      if (morris)
        t.add({o.first, p.option, with_interval(v, "mu_star_over_range", true),
               significant(v["mu"].get<double>(), 4), significant(v["sigma"].get<double>(), 4)});
      else
        t.add({o.first, p.option, with_interval(v, "first", false),
               with_interval(v, "total", false)});
    }
  }
  t.print(std::cout, false);
  std::cout << "\n";
}

namespace {

const char* const kSummaryKeys[] = {"mean", "sd", "q05", "q50", "q95"};

}  // namespace

std::string uncertainty_csv(const studies::SweepPlan& plan, const json& summary) {
  const json& u = summary["uncertainty"];
  std::ostringstream csv;
  csv << "# provenance: " << summary["provenance"].dump() << "\n# "
      << u["method"].get<std::string>() << "; " << u.value("points_used", 0) << " of "
      << u["points"] << " points used, effective "
      << "sample size " << csv_cell(u.value("effective_sample_size", json())) << "\n";
  csv << "kind,name";
  for (const char* when : {"prior", "posterior"})
    for (const char* k : kSummaryKeys) csv << "," << when << "_" << k;
  csv << ",error\n";
  auto rows = [&](const char* kind, const json& group) {
    for (const auto& [name, e] : group.items()) {
      csv << kind << "," << csv_cell(name);
      for (const char* when : {"prior", "posterior"})
        for (const char* k : kSummaryKeys)
          csv << "," << (e.contains(when) ? csv_cell(e[when][k]) : "");
      csv << "," << csv_cell(e.value("error", json())) << "\n";
    }
  };
  if (u.contains("error")) {
    csv << ",,,,,,,,,,," << csv_cell(u["error"]) << "\n";
    return csv.str();
  }
  rows("parameter", u["parameters"]);
  rows("output", u["outputs"]);
  (void)plan;
  return csv.str();
}

void print_uncertainty(const studies::SweepPlan& plan, const json& summary) {
  const json& u = summary["uncertainty"];
  if (u.is_null()) return;
  if (u.contains("error")) {
    std::cout << "\nUncertainty: " << u["error"].get<std::string>() << "\n";
    return;
  }
  std::cout << "\nUncertainty: " << u["points_used"] << " of " << u["points"]
            << " points weighted by the windows' likelihood; effective sample size "
            << significant(u["effective_sample_size"].get<double>(), 3)
            << " (the best point's misfit sum r^2/2 = "
            << significant(u["best_misfit"].get<double>(), 3) << "; 0: inside every window)\n";
  TextTable t({"", "window", "prior: mean", "5 … 95 %", "posterior: mean", "5 … 95 %"});
  auto add = [&](const std::string& name, const json& e, const std::string& window) {
    if (e.contains("error"))
      return t.add({name, window, "-", "-", "-", e["error"].get<std::string>()});
    auto range = [](const json& x) {
      return significant(x["q05"].get<double>(), 3) + " … " +
             significant(x["q95"].get<double>(), 3);
    };
    t.add({name, window, significant(e["prior"]["mean"].get<double>(), 4), range(e["prior"]),
           significant(e["posterior"]["mean"].get<double>(), 4), range(e["posterior"])});
  };
  for (const auto& p : plan.parameters) add(p.option, u["parameters"][p.option], "");
  for (const auto& o : plan.outputs) {
    const json& w = u["windows"];
    add(o.first, u["outputs"][o.first],
        w.contains(o.first) ? significant(w[o.first]["low"].get<double>(), 3) + " … " +
                                  significant(w[o.first]["high"].get<double>(), 3)
                            : "");
  }
  t.print(std::cout, false);
}

}  // namespace spinesim::cli

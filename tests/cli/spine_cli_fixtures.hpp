// Shared by the spine CLI tests: run `spinesim spine solve` / `study NAME` with --json.
#pragma once

#include "cli_runner.hpp"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

namespace spinesim::test_cli {

inline std::string in_quotes(const std::string& path) { return "'" + path + "'"; }

/// One column of a CSV whose first row not starting with '#' names the columns (a spine
/// recording, say), row by row; a failure and nothing when there is no such column.
inline std::vector<double> csv_column(const std::string& csv, const std::string& column) {
  std::ifstream in(csv);
  std::string line;
  int col = -1;
  std::vector<double> out;
  while (std::getline(in, line)) {
    if (line.empty() || line[0] == '#') continue;
    std::stringstream ss(line);
    std::string cell;
    std::vector<std::string> cells;
    while (std::getline(ss, cell, ',')) cells.push_back(cell);
    if (col >= 0) {
      out.push_back(std::stod(cells.at(std::size_t(col))));
      continue;
    }
    const auto at = std::find(cells.begin(), cells.end(), column);
    if (at == cells.end()) {
      ADD_FAILURE() << column << " is not a column of " << csv;
      return out;
    }
    col = int(at - cells.begin());
  }
  return out;
}

inline double max_abs(const std::vector<double>& v) {
  double most = 0;
  for (double x : v) most = std::max(most, std::abs(x));
  return most;
}

/// `spinesim spine solve ARGS --json`, parsed; an empty object (and a failure) on a non-zero exit.
inline nlohmann::json solve_json(const std::string& args) {
  const CliRun r = run_spinesim("spine solve " + args + " --json");
  EXPECT_EQ(r.status, 0) << r.err;
  if (r.status != 0) return nlohmann::json::object();
  return nlohmann::json::parse(r.out);
}

/// One run of a study's --json per process.
inline const nlohmann::json& study(const std::string& name) {
  static std::map<std::string, nlohmann::json> made;
  auto it = made.find(name);
  if (it != made.end()) return it->second;
  const CliRun r = run_spinesim("study " + name + " --json");
  EXPECT_EQ(r.status, 0) << r.err;
  return made.emplace(name, r.status == 0 ? nlohmann::json::parse(r.out) : nlohmann::json::object())
      .first->second;
}

/// One run of `study fusion --json` by fusion ("normal", "L3-L4", …) and load ("forward", …).
inline const nlohmann::json& fusion_run(const std::string& fusion, const std::string& load) {
  for (const auto& r : study("fusion")["runs"])
    if (r["fusion"] == fusion && r["load"] == load) return r;
  ADD_FAILURE() << "fusion run " << fusion << " / " << load << " missing";
  static const nlohmann::json none;
  return none;
}

/// |T1 translation| (mm) in a fusion run.
inline double t1_motion(const std::string& fusion, const std::string& load) {
  return fusion_run(fusion, load)["t1_translation_norm_mm"];
}

inline const std::vector<std::string>& fused_levels() {
  static const std::vector<std::string> levels = {"L3-L4", "L4-L5", "L3-L4-L5"};
  return levels;
}

}  // namespace spinesim::test_cli

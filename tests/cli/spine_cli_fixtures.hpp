// Shared by the spine CLI tests: run `spinesim spine solve` / `study NAME` with --json.
#pragma once

#include "cli_runner.hpp"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <cmath>
#include <map>
#include <string>
#include <vector>

namespace spinesim::test_cli {

inline std::string in_quotes(const std::string& path) { return "'" + path + "'"; }

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

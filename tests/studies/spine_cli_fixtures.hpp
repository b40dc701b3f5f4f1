// Shared by the spine CLI tests: run `spinesim spine solve` / `study NAME` with --json.
#pragma once

#include "cli_runner.hpp"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <cmath>
#include <map>
#include <string>

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
  return made.emplace(name, r.status == 0 ? nlohmann::json::parse(r.out) : nlohmann::json::object()).first->second;
}

}  // namespace spinesim::test_cli

// The machine a timing was measured on, for reports: timings mean little without the CPU.
#pragma once

#include <fstream>
#include <string>
#include <thread>

namespace spinesim {

/// "AMD EPYC 7B13 (2 CPUs, AVX2, AVX-512)" from /proc/cpuinfo; "unknown CPU (N CPUs)" elsewhere.
inline std::string cpu_description() {
  std::ifstream in("/proc/cpuinfo");
  std::string line, model, flags;
  while (std::getline(in, line) && (model.empty() || flags.empty())) {
    const auto colon = line.find(':');
    if (colon == std::string::npos) continue;
    const std::string key = line.substr(0, line.find_last_not_of(" \t", colon - 1) + 1);
    const std::string value = colon + 2 <= line.size() ? line.substr(colon + 2) : "";
    if (key == "model name" && model.empty()) model = value;
    if (key == "flags" && flags.empty()) flags = " " + value + " ";
  }
  std::string d = model.empty() ? "unknown CPU" : model;
  d += " (" + std::to_string(std::thread::hardware_concurrency()) + " CPUs";
  if (flags.find(" avx2 ") != std::string::npos) d += ", AVX2";
  if (flags.find(" avx512f ") != std::string::npos) d += ", AVX-512";
  return d + ")";
}

}  // namespace spinesim

// Reading the calibration's JSON files: one place for the I/O and for naming the file in errors.
#pragma once

#include "spinesim/common/input_file.hpp"

#include <nlohmann/json.hpp>

#include <stdexcept>
#include <string>

namespace spinesim::calibration::detail {

/// The parsed contents of `path` (spinesim::read_json_file: a regular file, bounded in size and
/// depth, strict JSON); std::invalid_argument naming the file and the cause.
inline nlohmann::json read_json_file(const std::string& path, const std::string& what) {
  return spinesim::read_json_file(path, what);
}

/// f(), with the file's name put in front of any refusal it throws.
template <class F>
auto naming_file(const std::string& path, F&& f) {
  try {
    return f();
  } catch (const std::invalid_argument& e) {
    throw std::invalid_argument("'" + path + "': " + e.what());
  } catch (const nlohmann::json::exception& e) {
    std::string what = e.what();  // "[json.exception.type_error.302] type must be ...": the reason
    if (!what.empty() && what[0] == '[' && what.find("] ") != std::string::npos)
      what = what.substr(what.find("] ") + 2);
    throw std::invalid_argument("'" + path + "': missing or malformed field (" + what + ")");
  }
}

}  // namespace spinesim::calibration::detail

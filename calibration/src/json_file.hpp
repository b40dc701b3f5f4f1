// Reading the calibration's JSON files: one place for the I/O and for naming the file in errors.
#pragma once

#include <nlohmann/json.hpp>

#include <fstream>
#include <stdexcept>
#include <string>

namespace spinesim::calibration::detail {

/// The parsed contents of `path`; std::invalid_argument "cannot read <what> '<path>'" or
/// "'<path>' is not valid JSON".
inline nlohmann::json read_json_file(const std::string& path, const std::string& what) {
  std::ifstream in(path);
  if (!in) throw std::invalid_argument("cannot read " + what + " '" + path + "'");
  try {
    nlohmann::json j;
    in >> j;
    return j;
  } catch (const nlohmann::json::exception&) {
    throw std::invalid_argument("'" + path + "' is not valid JSON");
  }
}

/// f(), with the file's name put in front of any refusal it throws.
template <class F>
auto naming_file(const std::string& path, F&& f) {
  try {
    return f();
  } catch (const std::invalid_argument& e) {
    throw std::invalid_argument("'" + path + "': " + e.what());
  } catch (const nlohmann::json::exception& e) {
    throw std::invalid_argument("'" + path + "': missing or malformed field (" +
                                std::string(e.what()) + ")");
  }
}

}  // namespace spinesim::calibration::detail

#include "json_fields.hpp"

#include "spinesim/common/input_file.hpp"

#include <cmath>
#include <stdexcept>

namespace spinesim::spine::detail {

nlohmann::json read_json(const std::string& path) {
  try {
    return read_json_file(path, "model file");
  } catch (const std::invalid_argument& e) {  // broken data: the model's contract is runtime_error
    throw std::runtime_error(e.what());
  }
}

double number(const nlohmann::json& j, const std::string& key, const std::string& file) {
  if (!j.contains(key) || !j.at(key).is_number())
    throw std::runtime_error(file + ": missing number '" + key + "'");
  const double v = j.at(key).get<double>();
  if (!std::isfinite(v)) throw std::runtime_error(file + ": '" + key + "' is not finite");
  return v;
}

Eigen::Vector3d vec3(const nlohmann::json& j, const std::string& key, const std::string& file) {
  if (!j.contains(key) || !j.at(key).is_array() || j.at(key).size() != 3)
    throw std::runtime_error(file + ": '" + key + "' must be an array of 3 numbers");
  Eigen::Vector3d v;
  for (int i = 0; i < 3; ++i) {
    const auto& e = j.at(key).at(std::size_t(i));
    if (!e.is_number()) throw std::runtime_error(file + ": '" + key + "' must hold numbers");
    v[i] = e.get<double>();
  }
  if (!v.allFinite()) throw std::runtime_error(file + ": '" + key + "' is not finite");
  return v;
}

}  // namespace spinesim::spine::detail

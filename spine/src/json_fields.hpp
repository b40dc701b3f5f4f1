// Reading the spine's data files (data/spine/*.json): numbers and 3-vectors by key, each failure
// one std::runtime_error naming the file and the field (the model's contract for broken data).
#pragma once

#include <Eigen/Core>
#include <nlohmann/json.hpp>

#include <string>

namespace spinesim::spine::detail {

nlohmann::json read_json(const std::string& path);
/// Value at `key` of `j` as a finite number.
double number(const nlohmann::json& j, const std::string& key, const std::string& file);
/// Value at `key` of `j` as an array of 3 finite numbers.
Eigen::Vector3d vec3(const nlohmann::json& j, const std::string& key, const std::string& file);

}  // namespace spinesim::spine::detail

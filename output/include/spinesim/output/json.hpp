// JSON for Eigen values (nlohmann::json): vectors as arrays, matrices as row-major nested arrays,
// and printing one JSON object as the only thing on stdout.
#pragma once

#include <Eigen/Core>
#include <nlohmann/json.hpp>

namespace spinesim::output {

/// Row-major nested arrays [[m00, m01, …], …], also for a matrix with one row or column.
template <class Derived>
nlohmann::json matrix_to_json(const Eigen::MatrixBase<Derived>& m) {
  nlohmann::json a = nlohmann::json::array();
  for (Eigen::Index i = 0; i < m.rows(); ++i) {
    nlohmann::json row = nlohmann::json::array();
    for (Eigen::Index j = 0; j < m.cols(); ++j) row.push_back(double(m(i, j)));
    a.push_back(row);
  }
  return a;
}

/// A vector (one row or one column) as [v0, v1, …]; any other matrix as matrix_to_json.
template <class Derived>
nlohmann::json to_json(const Eigen::MatrixBase<Derived>& v) {
  if (v.cols() != 1 && v.rows() != 1) return matrix_to_json(v);
  nlohmann::json a = nlohmann::json::array();
  for (Eigen::Index i = 0; i < v.size(); ++i) a.push_back(double(v(i)));
  return a;
}

/// A path or nothing: the string, or null when empty.
inline nlohmann::json path_or_null(const std::string& path) {
  return path.empty() ? nlohmann::json(nullptr) : nlohmann::json(path);
}

/// Prints `j` as the only thing on stdout (pretty, one object), with the run's provenance
/// (spinesim/common/provenance.hpp) under "provenance" when `j` is an object.
void print_json(const nlohmann::json& j);
/// Whether print_json has printed (the program's last word with --json: a run that failed
/// after its work began still prints one object, saying so).
bool json_printed();
/// Forgets that print_json printed: a new run in the same process (the Python module).
void reset_json_printed();

}  // namespace spinesim::output

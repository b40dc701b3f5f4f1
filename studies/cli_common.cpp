#include "cli_common.hpp"

#include <unistd.h>

#include <cmath>
#include <cstdlib>
#include <iostream>
#include <sstream>
#include <stdexcept>

namespace spinesim::cli {

std::string data_dir() {
  if (const char* env = std::getenv("SPINESIM_DATA_DIR"); env && *env) return env;
  return SPINESIM_DATA_DIR;
}

Eigen::VectorXd parse_numbers(const std::string& text, int n, const std::string& what) {
  std::vector<double> values;
  std::stringstream ss(text);
  std::string item;
  while (std::getline(ss, item, ',')) {
    std::size_t used = 0;
    double v = 0;
    try {
      v = std::stod(item, &used);
    } catch (const std::exception&) {
      throw std::invalid_argument(what + ": '" + item + "' is not a number");
    }
    while (used < item.size() && std::isspace(static_cast<unsigned char>(item[used]))) ++used;
    if (used != item.size()) throw std::invalid_argument(what + ": '" + item + "' is not a number");
    if (!std::isfinite(v)) throw std::invalid_argument(what + ": non-finite value '" + item + "'");
    values.push_back(v);
  }
  if (int(values.size()) != n)
    throw std::invalid_argument(what + ": expected " + std::to_string(n) + " comma-separated numbers, got " +
                                std::to_string(values.size()));
  return Eigen::Map<Eigen::VectorXd>(values.data(), n);
}

nlohmann::json to_json(const Eigen::VectorXd& v) {
  nlohmann::json a = nlohmann::json::array();
  for (Eigen::Index i = 0; i < v.size(); ++i) a.push_back(v(i));
  return a;
}

nlohmann::json to_json(const Eigen::MatrixXd& m) {
  nlohmann::json a = nlohmann::json::array();
  for (Eigen::Index i = 0; i < m.rows(); ++i) a.push_back(to_json(Eigen::VectorXd(m.row(i).transpose())));
  return a;
}

void print_json(const nlohmann::json& j) { std::cout << j.dump(2) << std::endl; }

double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

Progress::Progress(int stages, bool quiet) : stages_(stages), quiet_(quiet || !isatty(STDERR_FILENO)) {}

void Progress::begin(const std::string& what) {
  ++current_;
  start_ = std::chrono::steady_clock::now();
  if (!quiet_) std::cerr << "[" << current_ << "/" << stages_ << "] " << what << " ..." << std::flush;
}

double Progress::end(const std::string& detail) {
  const double s = seconds_since(start_);
  if (!quiet_) {
    std::ostringstream os;
    os.setf(std::ios::fixed);
    os.precision(2);
    os << " done, " << s << " s";
    if (!detail.empty()) os << " (" << detail << ")";
    std::cerr << os.str() << std::endl;
  }
  return s;
}

}  // namespace spinesim::cli

#include "cli_common.hpp"

#include <cmath>
#include <cstdlib>
#include <iostream>
#include <sstream>
#include <stdexcept>

namespace spinesim::cli {

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

std::vector<std::string> split_list(const std::string& text) {
  std::vector<std::string> out;
  std::stringstream ss(text);
  for (std::string item; std::getline(ss, item, ',');)
    if (!item.empty()) out.push_back(item);
  return out;
}

}  // namespace spinesim::cli

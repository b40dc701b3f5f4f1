#include "spinesim/fem/load_cases.hpp"

#include <algorithm>
#include <cctype>
#include <sstream>
#include <stdexcept>

namespace spinesim::fem {
namespace {

LoadCase make(const char* name, int component, double value) {
  LoadCase c{name, Eigen::Matrix<double, 6, 1>::Zero()};
  c.wrench_local(component) = value;
  return c;
}

}  // namespace

const std::vector<LoadCase>& standard_load_cases() {
  static const std::vector<LoadCase> cases = {
      make("compression", 1, -500.0),     make("tension", 1, 200.0),  make("shear-ap", 2, 100.0),
      make("shear-lat", 0, 100.0),        make("flexion", 3, 7500.0), make("extension", 3, -7500.0),
      make("lateral-bending", 5, 7500.0), make("torsion", 4, 7500.0)};
  return cases;
}

const LoadCase& load_case(const std::string& name) {
  for (const auto& c : standard_load_cases())
    if (c.name == name) return c;
  std::string known;
  for (const auto& c : standard_load_cases()) known += (known.empty() ? "" : ", ") + c.name;
  throw std::invalid_argument("unknown load case '" + name + "' (known: " + known + ")");
}

std::vector<LoadCase> parse_load_cases(const std::string& list) {
  if (list == "all") return standard_load_cases();
  std::vector<LoadCase> out;
  std::stringstream ss(list);
  std::string item;
  while (std::getline(ss, item, ',')) {
    item.erase(
        std::remove_if(item.begin(), item.end(), [](unsigned char ch) { return std::isspace(ch); }),
        item.end());
    if (!item.empty()) out.push_back(load_case(item));
  }
  if (out.empty()) throw std::invalid_argument("no load case given");
  return out;
}

Eigen::Matrix<double, 6, 1> global_wrench(const LoadCase& c, const mesh::DiscFrame& frame) {
  Eigen::Matrix<double, 6, 1> w;
  w.head<3>() = frame.axes * c.wrench_local.head<3>();
  w.tail<3>() = frame.axes * c.wrench_local.tail<3>();
  return w;
}

}  // namespace spinesim::fem

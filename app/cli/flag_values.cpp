#include "flag_values.hpp"
#include "spinesim/mss/simulator.hpp"

#include "spinesim/common/numbers.hpp"
#include "spinesim/spine/model.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <map>
#include <sstream>
#include <stdexcept>

namespace spinesim::cli {

Eigen::VectorXd parse_numbers(const std::string& text, int n, const std::string& what) {
  std::vector<double> values;
  std::stringstream ss(text);
  std::string item;
  while (std::getline(ss, item, ',')) {
    const auto first = item.find_first_not_of(" \t"), last = item.find_last_not_of(" \t");
    const std::string trimmed =
        first == std::string::npos ? std::string() : item.substr(first, last - first + 1);
    values.push_back(to_double(trimmed, what));
  }
  if (!text.empty() && text.back() == ',')
    throw std::invalid_argument(what + ": '' is not a finite number");
  if (int(values.size()) != n)
    throw std::invalid_argument(what + ": expected " + std::to_string(n) +
                                " comma-separated numbers, got " + std::to_string(values.size()));
  return Eigen::Map<Eigen::VectorXd>(values.data(), n);
}

std::vector<double> parse_number_list(const std::string& text, const std::string& what) {
  const auto n = std::count(text.begin(), text.end(), ',') + 1;
  const Eigen::VectorXd v = parse_numbers(text, int(n), what);
  return std::vector<double>(v.data(), v.data() + v.size());
}

std::vector<std::string> split_list(const std::string& text) {
  std::vector<std::string> out;
  std::stringstream ss(text);
  for (std::string item; std::getline(ss, item, ',');)
    if (!item.empty()) out.push_back(item);
  return out;
}

std::pair<int, Eigen::Vector3d> parse_vertebra_vector(const std::string& text,
                                                      const std::string& option,
                                                      const std::string& what) {
  const auto colon = text.find(':');
  if (colon == std::string::npos)
    throw std::invalid_argument(option + " '" + text + "': expected VERTEBRA:" + what +
                                " (e.g. T7:0,0,300)");
  int vertebra = 0;
  try {
    vertebra = spine::vertebra_index(text.substr(0, colon));
  } catch (const std::invalid_argument& e) {
    throw std::invalid_argument(option + " '" + text + "': " + e.what());
  }
  const Eigen::VectorXd v =
      parse_numbers(text.substr(colon + 1), 3, option + " " + text.substr(0, colon));
  return {vertebra, Eigen::Vector3d(v)};
}

double units_to_mm(const std::string& units) {
  static const std::map<std::string, double> table = {{"mm", 1.0}, {"cm", 10.0}, {"m", 1000.0}};
  auto it = table.find(units);
  if (it == table.end())
    throw std::invalid_argument("unknown --units '" + units + "' (use mm, cm or m)");
  return it->second;
}

mesh::UpAxis up_axis(const std::string& up) {
  static const std::map<std::string, mesh::UpAxis> table = {
      {"x", mesh::UpAxis::x},        {"y", mesh::UpAxis::y},        {"z", mesh::UpAxis::z},
      {"-x", mesh::UpAxis::minus_x}, {"-y", mesh::UpAxis::minus_y}, {"-z", mesh::UpAxis::minus_z}};
  auto it = table.find(up);
  if (it == table.end())
    throw std::invalid_argument("unknown --up '" + up + "' (use x, y, z, -x, -y or -z)");
  return it->second;
}

mss::Integrator parse_integrator(const std::string& name) {
  if (name == "implicit") return mss::Integrator::implicit_euler;
  if (name == "symplectic") return mss::Integrator::symplectic_euler;
  if (name == "explicit") return mss::Integrator::explicit_euler;
  throw std::invalid_argument("unknown --integrator '" + name +
                              "' (implicit, symplectic, explicit)");
}

}  // namespace spinesim::cli

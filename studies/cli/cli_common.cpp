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
    throw std::invalid_argument(what + ": expected " + std::to_string(n) +
                                " comma-separated numbers, got " + std::to_string(values.size()));
  return Eigen::Map<Eigen::VectorXd>(values.data(), n);
}

void add_output_flags(CLI::App* cmd, bool& json, bool& quiet, const std::string& what) {
  cmd->add_flag("--json", json, "Print " + what + " on stdout");
  cmd->add_flag("--quiet", quiet, "No progress on stderr");
}

void add_plate_load_options(CLI::App* cmd, std::string& motion, std::string& wrench,
                            std::string& load_case, std::string& center) {
  cmd->add_option("--motion", motion, "Plate motion tx,ty,tz,rx,ry,rz (mm, degrees)");
  cmd->add_option("--wrench", wrench,
                  "Applied wrench Fx,Fy,Fz,Mx,My,Mz (N, N·mm) about the centre");
  cmd->add_option(
      "--case", load_case,
      "Named load case in the disc frame: compression, tension, shear-ap, shear-lat, flexion, "
      "extension, lateral-bending, torsion");
  cmd->add_option("--center", center,
                  "Plate centre x,y,z (mm); default: mean of the superior endplate nodes");
}

std::vector<std::string> split_list(const std::string& text) {
  std::vector<std::string> out;
  std::stringstream ss(text);
  for (std::string item; std::getline(ss, item, ',');)
    if (!item.empty()) out.push_back(item);
  return out;
}

}  // namespace spinesim::cli

// The command line's values: the text of a flag turned into what a verb needs ("0,-500,0,0,0,0"
// -> six numbers, "T7:0,0,300" -> a vertebra and a vector, "z" -> an axis). Each parser refuses
// anything else with std::invalid_argument naming the flag, and nothing else escapes it: the
// fuzz target fuzz/fuzz_flag_values.cpp holds them to that on arbitrary text, together with the
// library parsers behind other flags (load cases, fusion levels, vertebra names, presets).
#pragma once

#include "spinesim/mesh/io.hpp"
#include "spinesim/mss/simulator.hpp"
#include "spinesim/mss/solver.hpp"

#include <Eigen/Core>

#include <string>
#include <utility>
#include <vector>

namespace spinesim::cli {

/// Parses "a,b,c" into exactly n finite numbers; throws std::invalid_argument naming `what`.
Eigen::VectorXd parse_numbers(const std::string& text, int n, const std::string& what);

/// "a,b,c" -> as many finite numbers as there are items; throws std::invalid_argument naming
/// `what` for a non-number or an empty item.
std::vector<double> parse_number_list(const std::string& text, const std::string& what);

/// "a,b,,c" -> {"a", "b", "c"} (empty items dropped).
std::vector<std::string> split_list(const std::string& text);

/// "T7:0,0,300" -> vertebra index (spine model order) and three finite numbers; errors name
/// `option` and give `what` ("Fx,Fy,Fz") in the expected form.
std::pair<int, Eigen::Vector3d> parse_vertebra_vector(const std::string& text,
                                                      const std::string& option,
                                                      const std::string& what);

/// --units: "mm", "cm" or "m" -> millimetres per file unit.
double units_to_mm(const std::string& units);

/// --up: "x", "y", "z", "-x", "-y" or "-z" -> the file's up axis.
mesh::UpAxis up_axis(const std::string& up);

/// --integrator: "implicit", "symplectic" or "explicit"; throws naming the choices.
mss::Integrator parse_integrator(const std::string& name);

}  // namespace spinesim::cli

#include "spinesim/studies/fem_report.hpp"

#include "spinesim/studies/format.hpp"
#include "spinesim/studies/table.hpp"

#include <cmath>
#include <iomanip>
#include <string>
#include <vector>

namespace spinesim::studies {

namespace {
constexpr double kDegToRad = M_PI / 180.0;
}

fem::Vector6d motion_deg_to_rad(const fem::Vector6d& q_deg) {
  fem::Vector6d q = q_deg;
  q.tail<3>() *= kDegToRad;
  return q;
}

fem::Vector6d motion_rad_to_deg(const fem::Vector6d& q_rad) {
  fem::Vector6d q = q_rad;
  q.tail<3>() /= kDegToRad;
  return q;
}

fem::Matrix6d stiffness_per_degree(const fem::Matrix6d& k_rad) {
  fem::Matrix6d k = k_rad;
  k.rightCols<3>() *= kDegToRad;
  return k;
}

void print_stiffness(std::ostream& os, const fem::Matrix6d& k_rad) {
  const fem::Matrix6d k = stiffness_per_degree(k_rad);
  static const char* rows[] = {"Fx [N]", "Fy [N]", "Fz [N]", "Mx [N·mm]", "My [N·mm]", "Mz [N·mm]"};
  os << "  6x6 stiffness about the plate centre (columns: tx ty tz per mm, rx ry rz per degree)\n";
  TextTable t({"", "tx", "ty", "tz", "rx", "ry", "rz"});
  for (int i = 0; i < 6; ++i) {
    std::vector<std::string> row{rows[i]};
    for (int c = 0; c < 6; ++c) row.push_back(significant(k(i, c), 4));
    t.add(row);
  }
  t.print(os, false);
}

}  // namespace spinesim::studies

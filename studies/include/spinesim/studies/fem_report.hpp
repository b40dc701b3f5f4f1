// Unit conversions and readable output of the FEM plate results (shared by `fem` and `demo`).
// The command line speaks degrees; the solver speaks radians.
#pragma once

#include "spinesim/fem/disc_fem.hpp"

#include <nlohmann/json.hpp>

#include <ostream>

namespace spinesim::studies {

/// (t mm, theta deg) -> (t mm, theta rad), and back.
fem::Vector6d motion_deg_to_rad(const fem::Vector6d& q_deg);
fem::Vector6d motion_rad_to_deg(const fem::Vector6d& q_rad);

/// The 6x6 stiffness with rotation columns per degree: rows (F N, M N·mm), columns
/// (t mm, theta deg).
fem::Matrix6d stiffness_per_degree(const fem::Matrix6d& k_rad);

inline constexpr const char* kStiffnessUnits =
    "rows Fx,Fy,Fz [N], Mx,My,Mz [N·mm]; columns tx,ty,tz [mm], rx,ry,rz [deg]";

void print_stiffness(std::ostream& os, const fem::Matrix6d& k_rad);

}  // namespace spinesim::studies

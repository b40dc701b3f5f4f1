#include "spinesim/studies/comparison_report.hpp"

#include "spinesim/studies/fem_reference.hpp"
#include "spinesim/studies/toolkit.hpp"

#include <iomanip>
#include <sstream>

namespace spinesim::studies {

nlohmann::json comparison_json(const MssFemComparison& c) {
  nlohmann::json cases = nlohmann::json::array();
  double sum_u = 0, sum_r = 0;
  for (const CaseComparison& r : c.cases) {
    nlohmann::json j = {{"name", r.name},
                        {"wrench", to_json((r.wrench))},
                        {"displacement_error", r.displacement_error},
                        {"plate_motion_error", r.plate_motion_error},
                        {"inverted_tets", r.inverted_tets},
                        {"plate_motion_fem", to_json((motion_rad_to_deg(r.plate_motion_fem)))},
                        {"plate_motion_mss", to_json((motion_rad_to_deg(r.plate_motion_mss)))},
                        {"reaction_error", r.reaction_error},
                        {"reaction_force_error", r.reaction_force_error},
                        {"reaction_moment_error", r.reaction_moment_error},
                        {"reaction_wrench_fem", to_json((r.reaction_fem))},
                        {"reaction_wrench_mss", to_json((r.reaction_mss))},
                        {"max_displacement_fem_mm", r.max_displacement_fem_mm},
                        {"max_displacement_mss_mm", r.max_displacement_mss_mm},
                        {"converged", r.converged},
                        {"newton_iterations", r.iterations}};
    if (!r.message.empty()) j["message"] = r.message;
    cases.push_back(j);
    sum_u += r.displacement_error;
    sum_r += r.reaction_error;
  }
  const double n = c.cases.empty() ? 1.0 : double(c.cases.size());
  const fem::Vector6d kf = stiffness_per_degree(c.k6_fem).diagonal();
  const fem::Vector6d km = stiffness_per_degree(c.k6_mss).diagonal();
  return {{"material", c.material},
          {"fem_order", c.fem_order},
          {"nodes", c.nodes},
          {"tets", c.tets},
          {"mss_constants", c.constants},
          {"load_scale", c.load_scale},
          {"plate_rms_radius_mm", c.plate_rms_radius_mm},
          {"units",
           {{"wrench", "Fx,Fy,Fz [N], Mx,My,Mz [N·mm], global frame"},
            {"plate_motion", "tx,ty,tz [mm], rx,ry,rz [deg]"},
            {"errors", "relative (dimensionless); see `spinesim mss compare --help`"}}},
          {"cases", cases},
          {"mean_displacement_error", sum_u / n},
          {"mean_reaction_error", sum_r / n},
          {"stiffness_diagonal",
           {{"fem", to_json((kf))},
            {"mss", to_json((km))},
            {"ratio_mss_over_fem", to_json((km.cwiseQuotient(kf)))},
            {"units", "tx,ty,tz [N/mm], rx,ry,rz [N·mm/deg]"}}},
          {"timings",
           {{"fem_solves_s", c.fem_seconds},
            {"mss_static_s", c.mss_seconds},
            {"stiffness_s", c.stiffness_seconds}}}};
}

void print_comparison(std::ostream& os, const MssFemComparison& c, bool markdown) {
  TextTable cases({"case", "displacement error", "plate-motion error", "reaction error",
                   "force part", "moment part", "max |u| FEM (mm)", "max |u| MSS (mm)"});
  cases.set_plain_markdown(true);
  for (const CaseComparison& r : c.cases)
    cases.add({r.name + (r.converged ? "" : " (not converged)") +
                   (r.inverted_tets > 0 ? " (" + std::to_string(r.inverted_tets) + " tets inverted)"
                                        : ""),
               percent(r.displacement_error), percent(r.plate_motion_error),
               percent(r.reaction_error), percent(r.reaction_force_error),
               percent(r.reaction_moment_error), fixed(r.max_displacement_fem_mm, 3),
               fixed(r.max_displacement_mss_mm, 3)});
  cases.print(os, markdown, "");

  const fem::Vector6d kf = stiffness_per_degree(c.k6_fem).diagonal();
  const fem::Vector6d km = stiffness_per_degree(c.k6_mss).diagonal();
  static const char* dof[] = {"tx [N/mm]",     "ty [N/mm]",     "tz [N/mm]",
                              "rx [N·mm/deg]", "ry [N·mm/deg]", "rz [N·mm/deg]"};
  os << "\n"
     << (markdown ? "" : "  ")
     << "6x6 plate stiffness diagonal (global frame), MSS (rest, condensed) vs FEM P" << c.fem_order
     << ":\n\n";
  TextTable k6({"DOF", "FEM", "MSS", "MSS / FEM"});
  k6.set_plain_markdown(true);
  for (int i = 0; i < 6; ++i)
    k6.add({dof[i], significant(kf(i), 4), significant(km(i), 4), fixed(km(i) / kf(i), 3)});
  k6.print(os, markdown);
}

std::string comparison_csv(const MssFemComparison& c) {
  std::ostringstream os;
  os << std::setprecision(17);
  os << "case,displacement_error,plate_motion_error,reaction_error,reaction_force_error,reaction_"
        "moment_error,"
        "converged";
  for (const char* who : {"fem", "mss"})
    for (const char* comp : {"Fx_N", "Fy_N", "Fz_N", "Mx_Nmm", "My_Nmm", "Mz_Nmm"})
      os << ",reaction_" << who << "_" << comp;
  os << "\n";
  for (const CaseComparison& r : c.cases) {
    os << r.name << "," << r.displacement_error << "," << r.plate_motion_error << ","
       << r.reaction_error << "," << r.reaction_force_error << "," << r.reaction_moment_error << ","
       << (r.converged ? 1 : 0);
    for (int i = 0; i < 6; ++i) os << "," << r.reaction_fem(i);
    for (int i = 0; i < 6; ++i) os << "," << r.reaction_mss(i);
    os << "\n";
  }
  return os.str();
}

}  // namespace spinesim::studies

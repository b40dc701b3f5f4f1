#include "spinesim/studies/mesh_report.hpp"

#include <cmath>
#include <iomanip>

namespace spinesim::studies {

nlohmann::json quality_json(const mesh::QualityReport& q) {
  nlohmann::json j = {{"nodes", q.vertices},
                      {"tets", q.tets},
                      {"annulus_tets", q.annulus_tets},
                      {"nucleus_tets", q.nucleus_tets},
                      {"inferior_nodes", q.inferior_nodes},
                      {"superior_nodes", q.superior_nodes},
                      {"wall_nodes", q.wall_nodes},
                      {"min_dihedral_deg", q.min_dihedral_deg},
                      {"max_dihedral_deg", q.max_dihedral_deg},
                      {"max_radius_edge_ratio", q.max_radius_edge_ratio},
                      {"mean_radius_edge_ratio", q.mean_radius_edge_ratio},
                      {"min_edge_mm", q.min_edge_mm},
                      {"mean_edge_mm", q.mean_edge_mm},
                      {"max_edge_mm", q.max_edge_mm},
                      {"volume_mm3", q.volume_mm3}};
  if (q.exact_volume_mm3 > 0) {
    j["exact_volume_mm3"] = q.exact_volume_mm3;
    j["volume_error"] = q.volume_error();
  }
  return j;
}

void print_quality(std::ostream& os, const mesh::QualityReport& q, const std::string& title) {
  os << std::fixed << std::setprecision(2);
  os << "Mesh " << title << "\n"
     << "  nodes " << q.vertices << ", tets " << q.tets << " (annulus " << q.annulus_tets
     << ", nucleus " << q.nucleus_tets << ")\n"
     << "  endplate nodes: inferior " << q.inferior_nodes << ", superior " << q.superior_nodes
     << "; wall " << q.wall_nodes << "\n"
     << "  dihedral angle  min " << q.min_dihedral_deg << " deg, max " << q.max_dihedral_deg
     << " deg\n"
     << "  radius-edge     max " << q.max_radius_edge_ratio << ", mean " << q.mean_radius_edge_ratio
     << "\n"
     << "  edge length     min " << q.min_edge_mm << " mm, mean " << q.mean_edge_mm << " mm, max "
     << q.max_edge_mm << " mm\n"
     << "  volume          " << q.volume_mm3 << " mm^3";
  if (q.exact_volume_mm3 > 0)
    os << " (exact " << q.exact_volume_mm3 << " mm^3, error " << std::setprecision(3)
       << 100.0 * q.volume_error() << " %)";
  os << std::endl;
}

}  // namespace spinesim::studies

// The disc problem as an FEBio input file; contents in febio_deck.hpp.
#include "spinesim/fem/febio_deck.hpp"

#include "spinesim/fem/assembly.hpp"
#include "spinesim/fem/elasticity.hpp"
#include "spinesim/fem/fe_space.hpp"
#include "spinesim/fem/fibres.hpp"
#include "spinesim/fem/orthotropic.hpp"

#include <iomanip>
#include <map>
#include <stdexcept>
#include <vector>

namespace spinesim::fem {
namespace {

std::string xml_escaped(const std::string& s) {
  std::string out;
  for (char ch : s) {
    if (ch == '&') out += "&amp;";
    else if (ch == '<') out += "&lt;";
    else if (ch == '>') out += "&gt;";
    else if (ch == '-' && !out.empty() && out.back() == '-') out += " -";  // no "--" in a comment
    else out += ch;
  }
  return out;
}

void check(const mesh::TetMesh& mesh, const FebioDeck& deck) {
  if (deck.order != 1 && deck.order != 2)
    throw std::invalid_argument("febio deck: order must be 1 (tet4) or 2 (tet10), not " +
                                std::to_string(deck.order));
  if (!deck.motion.allFinite() || !deck.plate_center_mm.allFinite())
    throw std::invalid_argument("febio deck: the plate motion and centre must be finite");
  if ((mesh.surface.array() == 1).count() == 0 || (mesh.surface.array() == 2).count() == 0)
    throw std::invalid_argument(
        "febio deck: the mesh needs both endplate labels (surface 1 fixed, 2 the plate)");
}

void write_ids(std::ostream& os, const std::vector<Eigen::Index>& ids) {
  for (std::size_t k = 0; k < ids.size(); ++k) os << (k ? "," : "") << ids[k] + 1;
}

/// One <Elements> part of the tets `tets` (ids from 1, as the mesh's order).
void write_part(std::ostream& os, const FeSpace& space, const std::string& name,
                const std::vector<Eigen::Index>& tets) {
  os << "    <Elements type=\"" << (space.nodes_per_element() == 4 ? "tet4" : "tet10")
     << "\" name=\"" << name << "\">\n";
  for (Eigen::Index t : tets) {
    os << "      <elem id=\"" << t + 1 << "\">";
    for (int a = 0; a < space.nodes_per_element(); ++a)
      os << (a ? "," : "") << space.elements(t, a) + 1;
    os << "</elem>\n";
  }
  os << "    </Elements>\n";
}

void write_orthotropic(std::ostream& os, int id, const std::string& name,
                       const OrthotropicConstants& c) {
  const Eigen::Vector3d a = c.axes.col(0), d = c.axes.col(1);
  os << "    <material id=\"" << id << "\" name=\"" << name << "\" type=\"orthotropic elastic\">\n"
     << "      <density>1</density>\n"
     << "      <E1>" << c.E1 << "</E1><E2>" << c.E2 << "</E2><E3>" << c.E3 << "</E3>\n"
     << "      <G12>" << c.G12 << "</G12><G23>" << c.G23 << "</G23><G31>" << c.G31 << "</G31>\n"
     << "      <v12>" << c.v12 << "</v12><v23>" << c.v23 << "</v23><v31>" << c.v31 << "</v31>\n"
     << "      <mat_axis type=\"vector\"><a>" << a.x() << "," << a.y() << "," << a.z()
     << "</a><d>" << d.x() << "," << d.y() << "," << d.z() << "</d></mat_axis>\n"
     << "    </material>\n";
}

struct Parts {
  std::map<int, std::vector<Eigen::Index>> plain;  ///< region -> tets without fibres
  std::vector<Eigen::Index> with_fibres;
};

Parts split_parts(const mesh::TetMesh& mesh, const ElementFibres& fibres) {
  Parts p;
  for (Eigen::Index t = 0; t < mesh.num_tets(); ++t) {
    if (!fibres.empty() && fibres.stiffness_mpa(t) > 0)
      p.with_fibres.push_back(t);
    else
      p.plain[mesh.region(t)].push_back(t);
  }
  return p;
}

/// The <Material> section: ids 1… for the regions, then one per fibre tet ("fibre_<tet id>").
void write_materials(std::ostream& os, const mesh::TetMesh& mesh,
                     const mesh::RegionMaterials& materials, const ElementFibres& fibres,
                     const Parts& parts) {
  os << "  <Material>\n";
  int id = 0;
  for (const auto& [region, tets] : parts.plain) {
    const mesh::IsotropicMaterial& m = materials.at(region);
    os << "    <material id=\"" << ++id << "\" name=\"region_" << region
       << "\" type=\"isotropic elastic\">\n      <density>1</density>\n      <E>"
       << m.youngs_modulus_mpa << "</E>\n      <v>" << m.poisson_ratio << "</v>\n    </material>\n";
  }
  for (Eigen::Index t : parts.with_fibres) {
    const Eigen::Vector3d a1 = fibres.direction_1.row(t).transpose();
    const Eigen::Vector3d a2 = fibres.direction_2.row(t).transpose();
    Matrix6d D = isotropic_elasticity(materials.at(mesh.region(t)));
    D += fibre_elasticity(a1, fibres.stiffness_mpa(t)) + fibre_elasticity(a2, fibres.stiffness_mpa(t));
    write_orthotropic(os, ++id, "fibre_" + std::to_string(t + 1),
                      orthotropic_constants(D, fibre_pair_axes(a1, a2)));
  }
  os << "  </Material>\n";
}

}  // namespace

void write_febio_deck(std::ostream& os, const mesh::TetMesh& mesh,
                      const mesh::RegionMaterials& materials, const FebioDeck& deck) {
  check(mesh, deck);
  const FeSpace space = make_fe_space(mesh, deck.order);
  const Eigen::VectorXi labels = node_surface_labels(space, mesh);
  const ElementFibres fibres = fibre_field(mesh, materials);
  const Parts parts = split_parts(mesh, fibres);
  os << std::setprecision(15) << "<?xml version=\"1.0\" encoding=\"ISO-8859-1\"?>\n"
     << "<!-- " << xml_escaped(deck.title) << "\n"
     << "     Written by spinesim: the linear disc problem (mm, N, MPa). Inferior endplate fixed,\n"
     << "     superior endplate moved as a rigid plate about its centre. -->\n"
     << "<febio_spec version=\"4.0\">\n  <Module type=\"solid\"/>\n"
     << "  <Control>\n    <analysis>STATIC</analysis>\n    <time_steps>1</time_steps>\n"
     << "    <step_size>1</step_size>\n  </Control>\n";
  write_materials(os, mesh, materials, fibres, parts);
  // Mesh: nodes, parts, node sets.
  os << "  <Mesh>\n    <Nodes name=\"disc\">\n";
  for (Eigen::Index i = 0; i < space.num_nodes(); ++i)
    os << "      <node id=\"" << i + 1 << "\">" << space.X(i, 0) << "," << space.X(i, 1) << ","
       << space.X(i, 2) << "</node>\n";
  os << "    </Nodes>\n";
  for (const auto& [region, tets] : parts.plain)
    write_part(os, space, "region_" + std::to_string(region), tets);
  for (Eigen::Index t : parts.with_fibres) write_part(os, space, "fibre_" + std::to_string(t + 1), {t});
  std::vector<Eigen::Index> inferior, superior;
  for (Eigen::Index i = 0; i < space.num_nodes(); ++i) {
    if (labels(i) == 1) inferior.push_back(i);
    if (labels(i) == 2) superior.push_back(i);
  }
  os << "    <NodeSet name=\"inferior\">";
  write_ids(os, inferior);
  os << "</NodeSet>\n    <NodeSet name=\"superior\">";
  write_ids(os, superior);
  os << "</NodeSet>\n  </Mesh>\n  <MeshDomains>\n";
  for (const auto& [region, tets] : parts.plain)
    os << "    <SolidDomain name=\"region_" << region << "\" mat=\"region_" << region << "\"/>\n";
  for (Eigen::Index t : parts.with_fibres)
    os << "    <SolidDomain name=\"fibre_" << t + 1 << "\" mat=\"fibre_" << t + 1 << "\"/>\n";
  os << "  </MeshDomains>\n";
  // The plate motion at every superior node, one table per dof.
  os << "  <MeshData>\n";
  for (int d = 0; d < 3; ++d) {
    os << "    <NodeData name=\"u" << "xyz"[d] << "\" node_set=\"superior\" data_type=\"scalar\">\n";
    for (std::size_t k = 0; k < superior.size(); ++k) {
      const Eigen::Vector3d x = space.X.row(superior[k]).transpose();
      const Eigen::Vector3d u = plate_map(x - deck.plate_center_mm) * deck.motion;
      os << "      <node lid=\"" << k + 1 << "\">" << u(d) << "</node>\n";
    }
    os << "    </NodeData>\n";
  }
  os << "  </MeshData>\n  <Boundary>\n"
     << "    <bc name=\"inferior_fixed\" type=\"zero displacement\" node_set=\"inferior\">\n"
     << "      <x_dof>1</x_dof><y_dof>1</y_dof><z_dof>1</z_dof>\n    </bc>\n";
  for (char c : {'x', 'y', 'z'})
    os << "    <bc name=\"plate_u" << c << "\" type=\"prescribed displacement\" node_set=\"superior\">\n"
       << "      <dof>" << c << "</dof><value lc=\"1\" type=\"map\">u" << c << "</value>"
       << "<relative>0</relative>\n    </bc>\n";
  os << "  </Boundary>\n  <LoadData>\n"
     << "    <load_controller id=\"1\" name=\"ramp\" type=\"loadcurve\">\n"
     << "      <interpolate>LINEAR</interpolate>\n"
     << "      <points><pt>0,0</pt><pt>1,1</pt></points>\n    </load_controller>\n  </LoadData>\n"
     << "  <Output>\n    <plotfile type=\"febio\">\n      <var type=\"displacement\"/>\n"
     << "      <var type=\"stress\"/>\n      <var type=\"Lagrange strain\"/>\n"
     << "      <var type=\"reaction forces\"/>\n    </plotfile>\n"
     << "    <logfile>\n      <node_data data=\"Rx;Ry;Rz\" node_set=\"superior\" delim=\",\" "
        "file=\"superior_reactions.csv\"/>\n    </logfile>\n  </Output>\n</febio_spec>\n";
}

}  // namespace spinesim::fem

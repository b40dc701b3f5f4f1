// The disc problem as an Abaqus/CalculiX input deck; contents in abaqus_deck.hpp.
#include "spinesim/fem/abaqus_deck.hpp"

#include "spinesim/fem/assembly.hpp"
#include "spinesim/fem/elasticity.hpp"
#include "spinesim/fem/fe_space.hpp"
#include "spinesim/fem/fibres.hpp"

#include <iomanip>
#include <map>
#include <stdexcept>
#include <vector>

namespace spinesim::fem {
namespace {

/// Writes ids 16 a line (the Abaqus limit for data lines of sets).
void write_ids(std::ostream& os, const std::vector<Eigen::Index>& ids) {
  for (std::size_t k = 0; k < ids.size(); ++k)
    os << ids[k] + 1 << (k + 1 == ids.size() || (k + 1) % 16 == 0 ? "\n" : ", ");
}

/// The 21 constants of *ELASTIC, TYPE=ANISO (D1111, D1122, D2222, D1133, D2233, D3333, D1112,
/// D2212, D3312, D1212, D1113, D2213, D3313, D1213, D1313, D1123, D2223, D3323, D1223, D1323,
/// D2323) from our Voigt matrix (xx, yy, zz, yz, xz, xy; engineering shears, as Abaqus uses).
void write_aniso(std::ostream& os, const Matrix6d& D) {
  // Tensor index pair -> our Voigt row: 11 0, 22 1, 33 2, 12 5, 13 4, 23 3.
  static const int order[21][2] = {{0, 0}, {0, 1}, {1, 1}, {0, 2}, {1, 2}, {2, 2}, {0, 5},
                                   {1, 5}, {2, 5}, {5, 5}, {0, 4}, {1, 4}, {2, 4}, {5, 4},
                                   {4, 4}, {0, 3}, {1, 3}, {2, 3}, {5, 3}, {4, 3}, {3, 3}};
  os << "*ELASTIC, TYPE=ANISO\n";
  for (int k = 0; k < 21; ++k)
    os << D(order[k][0], order[k][1]) << (k == 20 || (k + 1) % 8 == 0 ? ",\n" : ", ");
}

void check(const mesh::TetMesh& mesh, const AbaqusDeck& deck) {
  if (deck.order != 1 && deck.order != 2)
    throw std::invalid_argument("abaqus deck: order must be 1 (C3D4) or 2 (C3D10), not " +
                                std::to_string(deck.order));
  if (!deck.load.allFinite() || !deck.plate_center_mm.allFinite())
    throw std::invalid_argument("abaqus deck: the load and the plate centre must be finite");
  if ((mesh.surface.array() == 1).count() == 0 || (mesh.surface.array() == 2).count() == 0)
    throw std::invalid_argument(
        "abaqus deck: the mesh needs both endplate labels (surface 1 fixed, 2 the plate)");
}

}  // namespace

void write_abaqus_deck(std::ostream& os, const mesh::TetMesh& mesh,
                       const mesh::RegionMaterials& materials, const AbaqusDeck& deck) {
  check(mesh, deck);
  const FeSpace space = make_fe_space(mesh, deck.order);
  const Eigen::VectorXi labels = node_surface_labels(space, mesh);
  const ElementFibres fibres = fibre_field(mesh, materials);
  const Eigen::Index n = space.num_nodes(), nt = mesh.num_tets();
  // 13 significant digits: CalculiX reads at most 20 characters a number (-d.dddddddddddde-ddd).
  os << std::setprecision(13) << "*HEADING\n" << deck.title << "\n"
     << "** Written by spinesim: the linear disc problem (mm, N, MPa). Inferior endplate fixed,\n"
     << "** superior endplate moved by a rigid plate about its centre.\n";
  // 1. Nodes (and the rigid body's two nodes at the plate centre for a wrench).
  os << "*NODE, NSET=NALL\n";
  for (Eigen::Index i = 0; i < n; ++i)
    os << i + 1 << ", " << space.X(i, 0) << ", " << space.X(i, 1) << ", " << space.X(i, 2) << "\n";
  const Eigen::Index ref = n + 1, rot = n + 2;  // 1-based ids
  if (!deck.prescribed_motion) {
    os << "*NODE, NSET=PLATE\n";
    for (Eigen::Index id : {ref, rot})
      os << id << ", " << deck.plate_center_mm.x() << ", " << deck.plate_center_mm.y() << ", "
         << deck.plate_center_mm.z() << "\n";
  }
  // 2. Elements and their sets.
  os << "*ELEMENT, TYPE=" << (deck.order == 1 ? "C3D4" : "C3D10") << ", ELSET=EALL\n";
  for (Eigen::Index t = 0; t < nt; ++t) {
    os << t + 1;
    for (int a = 0; a < space.nodes_per_element(); ++a) os << ", " << space.elements(t, a) + 1;
    os << "\n";
  }
  std::map<int, std::vector<Eigen::Index>> plain;  // region -> tets without fibres
  std::vector<Eigen::Index> with_fibres;
  for (Eigen::Index t = 0; t < nt; ++t) {
    if (!fibres.empty() && fibres.stiffness_mpa(t) > 0)
      with_fibres.push_back(t);
    else
      plain[mesh.region(t)].push_back(t);
  }
  for (const auto& [region, tets] : plain) {
    const mesh::IsotropicMaterial& m = materials.at(region);
    os << "*ELSET, ELSET=REGION_" << region << "\n";
    write_ids(os, tets);
    os << "*MATERIAL, NAME=REGION_" << region << "\n*ELASTIC\n"
       << m.youngs_modulus_mpa << ", " << m.poisson_ratio << "\n"
       << "*SOLID SECTION, ELSET=REGION_" << region << ", MATERIAL=REGION_" << region << "\n";
  }
  if (!with_fibres.empty())
    os << "** Fibre-reinforced tets: each its own anisotropic material, D = D_iso + sum k m m^T.\n";
  for (Eigen::Index t : with_fibres) {
    Matrix6d D = isotropic_elasticity(materials.at(mesh.region(t)));
    D += fibre_elasticity(fibres.direction_1.row(t).transpose(), fibres.stiffness_mpa(t));
    D += fibre_elasticity(fibres.direction_2.row(t).transpose(), fibres.stiffness_mpa(t));
    os << "*ELSET, ELSET=F" << t + 1 << "\n" << t + 1 << "\n*MATERIAL, NAME=F" << t + 1 << "\n";
    write_aniso(os, D);
    os << "*SOLID SECTION, ELSET=F" << t + 1 << ", MATERIAL=F" << t + 1 << "\n";
  }
  // 3. Endplates.
  std::vector<Eigen::Index> inferior, superior;
  for (Eigen::Index i = 0; i < n; ++i) {
    if (labels(i) == 1) inferior.push_back(i);
    if (labels(i) == 2) superior.push_back(i);
  }
  os << "*NSET, NSET=INFERIOR\n";
  write_ids(os, inferior);
  os << "*NSET, NSET=SUPERIOR\n";
  write_ids(os, superior);
  os << "*BOUNDARY\nINFERIOR, 1, 3\n";
  if (!deck.prescribed_motion)
    os << "*RIGID BODY, NSET=SUPERIOR, REF NODE=" << ref << ", ROT NODE=" << rot << "\n";
  // 4. The step: the load and the output.
  os << "*STEP\n*STATIC\n";
  if (deck.prescribed_motion) {
    os << "** Prescribed plate motion t = (" << deck.load.head<3>().transpose()
       << ") mm, theta = (" << deck.load.tail<3>().transpose() << ") rad about the centre\n"
       << "*BOUNDARY\n";
    for (Eigen::Index i : superior) {
      const Eigen::Vector3d u =
          plate_map(space.X.row(i).transpose() - deck.plate_center_mm) * deck.load;
      for (int d = 0; d < 3; ++d) os << i + 1 << ", " << d + 1 << ", " << d + 1 << ", " << u(d) << "\n";
    }
  } else {
    os << "** Applied wrench F (N) on the reference node, M (N mm) on the rotation node\n*CLOAD\n";
    for (int d = 0; d < 3; ++d) os << ref << ", " << d + 1 << ", " << deck.load(d) << "\n";
    for (int d = 0; d < 3; ++d) os << rot << ", " << d + 1 << ", " << deck.load(3 + d) << "\n";
    os << "*NODE PRINT, NSET=PLATE\nU\n";
  }
  os << "*NODE PRINT, NSET=NALL\nU\n*EL PRINT, ELSET=EALL\nS, E, ENER\n"
     << "*NODE FILE\nU\n*EL FILE\nS, E\n*END STEP\n";
}

}  // namespace spinesim::fem

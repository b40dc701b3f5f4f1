// A peer model's hexahedral disc read as a spinesim disc: the ArtiSynth lumbosacral spine's
// meshed discs (Remus et al. 2021; the folder layout of its fe-discs export).
//
// Per level (L12, L23, L34, L45, L51) the folder holds the annulus in rings LXX_AN_R1 … R4 and
// the nucleus LXX_NP, each a `.node` file (id x y z, metres, z superior; one numbering shared by
// all parts) and an `.elem` file (eight node ids of a hexahedron, then flags and the element id),
// with node lists of each part's faces: `*O.txt` upper (the vertebra above), `*U.txt` lower,
// `*A.txt` outer lateral. What becomes of them:
//   - nodes: metres to mm and the z-up frame to ours (io.hpp to_spinesim_frame, as the
//     vertebra surfaces of the same model are read), renumbered in id order;
//   - each hexahedron: six tetrahedra by the pulling triangulation from its lowest-numbered
//     vertex — every quad face is cut along the diagonal through its own lowest-numbered vertex,
//     so two hexahedra sharing a face cut it alike and the tet mesh is conforming without extra
//     nodes; a tet of the wrong orientation is turned, a degenerate one refused;
//   - regions: the rings annulus (1), the nucleus nucleus (2);
//   - labels: upper faces the superior endplate (2), lower faces the inferior endplate (1), the
//     outer ring's outer face the outer wall (3); endplate labels win on the rims;
//   - the disc frame: origin midway between the area centroids of the two endplates, y from the
//     inferior to the superior one, z the global anterior made normal to y, x = y × z.
// The fibre polylines (`*.fiber`) are read by read_artisynth_fibres.
#pragma once

#include "spinesim/mesh/tet_mesh.hpp"

#include <Eigen/Core>

#include <string>
#include <vector>

namespace spinesim::mesh {

/// "L4-L5" or "L45" -> the file prefix "L45" (L5-S1 is "L51"). Throws std::invalid_argument
/// for a level the model does not have.
std::string artisynth_level_prefix(const std::string& level);

/// Reads the level's disc from `folder`. Throws std::invalid_argument (one line naming the file)
/// for a missing or malformed file, a node id used but not given, two parts giving one id
/// different coordinates, or a degenerate tetrahedron.
TetMesh read_artisynth_disc(const std::string& folder, const std::string& level);

/// The peer's collagen fibres of the level as polylines in the spinesim frame (mm), one
/// std::vector of via points per fibre, with the ring (1 … 4) each belongs to.
struct PeerFibres {
  std::vector<std::vector<Eigen::Vector3d>> paths;
  std::vector<int> ring;
};
PeerFibres read_artisynth_fibres(const std::string& folder, const std::string& level);

/// For every tet of `m` in the annulus, the unit directions of the nearest segments of the
/// peer's fibres (#T×3 each): `direction_1` the nearest, `direction_2` the nearest whose line
/// crosses it at more than 20° (the other family); zero rows outside the annulus.
struct PeerFibreField {
  Eigen::MatrixX3d direction_1, direction_2;
};
PeerFibreField peer_fibre_field(const TetMesh& m, const PeerFibres& fibres);

}  // namespace spinesim::mesh

// `spinesim mesh import`: a peer model's meshed disc (the ArtiSynth lumbosacral spine's,
// mesh/artisynth_disc.hpp) as a spinesim disc, with its quality, and its collagen fibres beside
// the fibre field our fibre-reinforced material lays on the same mesh.
#pragma once

#include "spinesim/mesh/artisynth_disc.hpp"
#include "spinesim/mesh/quality.hpp"

#include <nlohmann/json.hpp>

#include <string>

namespace spinesim::studies {

struct PeerDiscRequest {
  std::string folder;  ///< the model's fe-discs folder
  std::string level;   ///< L1-L2 … L5-S1
  std::string out;     ///< the VTU (empty: nothing written)
  /// Whether the mesh carries the peer's fibres (TetMesh::fibre_paths), so that a fibre
  /// material lays its fibres along them; without, it lays them along the annulus geometry.
  bool fibre_paths = true;
};

struct PeerDiscResult {
  mesh::TetMesh mesh;  ///< with the peer's fibres as fibre_paths when the request asks
  mesh::QualityReport quality;
  mesh::PeerFibreField fibres;  ///< the peer's fibres per annulus tet
  /// Per annulus tet, the angle between the peer's fibre pair and the fibre-reinforced preset's
  /// (lines, the better of the two pairings, mean of the two families), deg; and the fibres'
  /// inclination to the disc's transverse plane, peer's and ours (means over the annulus).
  double mean_pair_angle_deg = 0, peer_inclination_deg = 0, our_inclination_deg = 0;
  Eigen::Index hexahedra = 0;
};

/// Reads, checks and (with `out`) writes the disc, with the peer's fibres as its fibre paths
/// (cell data `fibre_path_direction_1/2`) unless the request leaves them out.
/// Throws std::invalid_argument (one line) for a missing folder or file, or a bad level.
PeerDiscResult import_peer_disc(const PeerDiscRequest& request, const std::string& data_dir);

nlohmann::json peer_disc_json(const PeerDiscResult& r, const PeerDiscRequest& request);

}  // namespace spinesim::studies

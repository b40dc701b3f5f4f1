// Tetrahedral meshing of discs with CGAL Mesh_3 (CGAL stays inside mesh/src).
#pragma once

#include "spinesim/mesh/disc_geometry.hpp"
#include "spinesim/mesh/tet_mesh.hpp"

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

namespace spinesim::mesh {

/// Mesh_3 criteria and optimisers; defaults run out of the box on a lumbar disc.
struct MeshOptions {
  double cell_size_mm = 2.0;       ///< upper bound on tet circumradius
  double facet_distance_mm = 0.1;  ///< boundary approximation error bound
  double facet_size_mm = 0.0;      ///< 0: same as cell_size_mm
  double edge_size_mm = 0.0;       ///< protected sharp edges (rims); 0: same as cell_size_mm
  double facet_angle_deg = 25.0;
  double radius_edge_ratio = 2.5;  ///< cell_radius_edge_ratio
  // Optimisers, run after refinement in CGAL's order with no time limit (reproducible):
  // ODT / Lloyd at most 20 iterations; perturb and exude target a 12° minimum dihedral.
  // Measured on L4-L5 (47 × 35 × 11.3 mm): perturb + exude give min dihedral ≥ 12° from
  // 2 mm cells down; at 3 mm (a quarter of the disc height) slivers pinned to the protected
  // rims stay (6.5°) unless `odt` is on (12°, but ODT costs 2-5× the meshing time).
  bool odt = false;
  bool lloyd = false;
  bool perturb = true;
  bool exude = true;
  std::uint32_t seed = 0;  ///< CGAL random seed, for reproducible meshes
  /// Refuse (before meshing) when the expected element count exceeds this: an absurd resolution
  /// or a surface in the wrong units must not run a machine out of memory. See
  /// expected_elements.
  double max_elements = 2e6;
};

/// Expected number of elements (tetrahedra + boundary triangles) of a body of volume
/// `volume_mm3` within a sphere of `bounding_radius_mm` meshed with `opt`: 6 V / r³ tetrahedra
/// for cell size r (a regular tetrahedron of circumradius r has 0.51 r³; CGAL's cells average
/// about a third of that: 3133 tetrahedra for L4-L5 at 3 mm, estimate 3353), and A / (0.43 e²)
/// triangles of edge e = min(facet size, √(8 R · facet distance)) (the chord of a curvature
/// radius R within the facet distance) over the area A = 6 V^(2/3) of a cube of that volume.
double expected_elements(double volume_mm3, double bounding_radius_mm, const MeshOptions& opt);

/// A body given by a labelling function: 0 outside, positive label inside (the tet `region`).
/// `bounding_radius_mm` and `center_mm` bound the body; `exact_volume_mm3` (if known, else <0)
/// is reported against the mesh volume.
struct LabeledBody {
  std::function<int(const Eigen::Vector3d&)> label;
  Eigen::Vector3d center_mm = Eigen::Vector3d::Zero();
  double bounding_radius_mm = 0.0;
  double exact_volume_mm3 = -1.0;
  /// Classifies a boundary facet (centroid, outward unit normal) into a Surface label;
  /// may be empty (then every boundary node is labelled outer wall).
  std::function<Surface(const Eigen::Vector3d&, const Eigen::Vector3d&)> classify_facet;
  /// Sharp edges to protect (CGAL 1D features): polylines of points exactly on the boundary,
  /// closed ones with the first point repeated last. Keeps rims crisp and volumes accurate.
  std::vector<std::vector<Eigen::Vector3d>> features;
  std::string name = "labeled body";  ///< provenance, copied to TetMesh::source
};

/// Generic labelled-domain mesher (discs, test cylinders, ...). Throws std::runtime_error if
/// CGAL produces no tetrahedra.
TetMesh mesh_labeled_body(const LabeledBody& body, const MeshOptions& opt);

/// The parametric disc (ParametricDisc) meshed upright at the origin in its local frame, rims
/// protected as sharp features, then placed by `placement` (x' = origin + axes x); the
/// returned mesh carries that frame. Pass disc_frame_in_spine(level) to put it in the spine.
TetMesh mesh_parametric_disc(const DiscDimensions& dims, const MeshOptions& opt,
                             const DiscFrame& placement = DiscFrame());

/// Exact volume (mm^3) of the parametric disc, for the quality report.
double parametric_disc_volume(const DiscDimensions& dims);

}  // namespace spinesim::mesh

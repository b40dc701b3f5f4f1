// Structured (sweep) tetrahedral mesh of the parametric disc, for haptic-resolution
// mass-spring discs of a few hundred tets.
//
// Why: CGAL Mesh_3 (mesher.hpp) cannot go below ~900 tets on a thin thoracic disc (its
// radius-edge and facet criteria on 4.5-7 mm thick discs), but the 17-disc mass-spring spine
// must step at 1 kHz on one core (~0.14 µs per tet and step), which leaves ~400 tets a disc.
//
// Construction (local frame, then placed like mesh_parametric_disc):
//   1. Layer heights y_l = -h/2 + l h / layers, l = 0..layers. At each height the
//      ParametricDisc outline (the linear loft of the lower and upper outline) is sampled at
//      `sectors` curve parameters θ_i, equally spaced in arc length on the mid-height outline
//      and counter-clockwise from the posterior midpoint (the bottom of the notch). The same
//      θ_i serve every layer, so every section is one polygon stretched in x and z.
//   2. Rings: `rings` scaled copies of that polygon about the area centroid (which lies on
//      the y axis at every height), scales 0 < s_1 < ... < s_rings = 1. One ring sits exactly
//      at s = sqrt(kNucleusAreaFraction), so the nucleus/annulus interface is conforming and
//      the nucleus holds exactly 40 % of the mesh volume. The nucleus has
//      n_n = clamp(round(rings · sqrt(0.4)), 1, rings - 1) rings of equal area
//      (s_k = sqrt(0.4 k / n_n)); the annulus the rest, evenly spaced in s on (sqrt(0.4), 1].
//   3. Cross-section triangulation (the same at every layer): a fan from the centre point to
//      ring 1, and every quad between rings k and k+1 split along its shorter diagonal
//      (measured at mid-height). Triangles inside the nucleus ring are region 2, others 1.
//      The outline is star-shaped about its centroid, so the rings are nested and every
//      triangle is non-degenerate (checked; std::runtime_error otherwise).
//   4. Sweep: each triangle × each layer is a prism, split into 3 tets by the global-index
//      rule (each vertical quad's diagonal starts at its lowest-index vertex), so neighbouring
//      prisms share diagonals and the mesh is conforming (Dompierre et al. 1999, "How to
//      subdivide pyramids, prisms and hexahedra into tetrahedra"). Tets are positively
//      oriented.
//
// Counts: nodes = (layers + 1)(1 + rings · sectors),
//         tets  = 3 · layers · sectors · (2 rings - 1).
// Labels (tet_mesh.hpp): every node of the bottom layer is 1 (inferior endplate, rim
// included), every node of the top layer 2, outer-ring nodes of the intermediate layers 3,
// the rest 0. With layers = 1 every node is on an endplate (no free node).
//
// With the defaults 12 × 3 × 2: 360 tets and 111 nodes a disc on every level; its quality and
// volume error per level are checked by tests/mesh/test_structured_disc.cpp and listed in
// docs/benchmarks.md ("Structured discs").
// Other resolutions, worst min dihedral over the 17 levels [tets a disc, volume error]:
//   12×2×2 14.7° [216, -5.1 %]   14×3×2 20.2° [420, -3.7 %]   16×3×2 20.0° [480, -2.8 %]
//   16×2×2 14.4° [288, -2.8 %]   12×3×3 13.2° [540, -5.1 %]   20×3×2 16.3° [600, -1.8 %]
// More layers make thin thoracic discs' tets flat; rings = 2 leaves the nucleus one fan of
// long triangles. The volume error is O(1/sectors^2) (-0.69 % at 32); `match_area` removes it.
#pragma once

#include "spinesim/mesh/disc_geometry.hpp"
#include "spinesim/mesh/tet_mesh.hpp"

#include <vector>

namespace spinesim::mesh {

/// Resolution of the structured disc mesh. The defaults keep 17 discs under ~7000 tets (the
/// 1 kHz mass-spring budget) with the best minimum dihedral angle found at that size.
struct StructuredDiscOptions {
  int sectors = 12;  ///< samples around the outline, >= 6
  int rings = 3;     ///< point rings (outer rim and nucleus boundary included), >= 2
  int layers = 2;    ///< tet layers through the height, >= 1 (>= 2 for any free node)
  /// false: rim nodes exactly on the outline, volume short by the inscribed-polygon error
  /// (O(1/sectors^2)). true: every section stretched about its centroid so the rim polygon
  /// has the outline's exact area (rim nodes up to ~3 % of the radius outside at 12 sectors).
  bool match_area = false;
  double max_elements = 2e6;  ///< refused above this many tetrahedra (before any allocation)
};

/// Throws std::invalid_argument (one line) unless sectors >= 6, rings >= 2, layers >= 1 and the
/// tetrahedron count is within max_elements.
void validate(const StructuredDiscOptions& opt);

/// Ring scales s_1 < ... < s_rings = 1 about the centroid (see the header comment, step 2);
/// one of them is exactly sqrt(kNucleusAreaFraction).
std::vector<double> structured_ring_scales(int rings);

/// The parametric disc meshed by the sweep above, upright at the origin in its local frame,
/// then placed by `placement` (x' = origin + axes x); the returned mesh carries that frame.
/// Pass disc_frame_in_spine(level) to put it in the spine. Throws std::invalid_argument for
/// bad options or dimensions.
TetMesh mesh_structured_disc(const DiscDimensions& dims, const StructuredDiscOptions& opt = {},
                             const DiscFrame& placement = DiscFrame());

}  // namespace spinesim::mesh

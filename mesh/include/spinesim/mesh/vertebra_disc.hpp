// A disc between two user-supplied vertebrae (a patient-specific disc).
//
// Input: the inferior and the superior vertebra as triangle surfaces in mm with +y up
// (read_surface has done units and axes) — endplate patches, vertebral bodies or whole
// vertebrae; surfaces need not be closed or manifold, nor consistently oriented.
//
// Construction (frame: y = disc axis from the inferior surface's area centroid towards the
// superior's, x = global x made orthogonal to it, z = x × y):
//   1. on a grid of columns parallel to the axis (step `grid_step_mm`), the top-most hit on the
//      inferior surface and the bottom-most hit on the superior surface (CGAL AABB ray
//      queries); a column *faces* when both hit triangles are within `facing_angle_deg` of
//      the axis and the gap lies in (0, max_gap_mm];
//   2. footprint = largest connected set of facing columns, holes filled; its outline is the
//      polar radius about its centre, smoothed to `outline_harmonics` Fourier terms and moved
//      `rim_margin_mm` inwards;
//   3. disc = points whose column lies inside the outline, between the two endplate height
//      fields (bilinear on the grid); nucleus = columns inside the outline scaled by
//      sqrt(nucleus_area_fraction) about its area centroid (thesis 5.2.5: 40 %).
//   4. Mesh_3 with the rims (outline on both endplates, nucleus junctions) as sharp features;
//      boundary facets nearest the inferior endplate -> 1, superior -> 2, wall -> 3.
#pragma once

#include "spinesim/mesh/io.hpp"
#include "spinesim/mesh/mesher.hpp"
#include "spinesim/mesh/tet_mesh.hpp"

namespace spinesim::mesh {

struct VertebraDiscOptions {
  double facing_angle_deg = 40.0;  ///< endplate triangles: normal within this of the axis
  double max_gap_mm = 30.0;        ///< larger endplate gaps are refused as absurd
  double grid_step_mm = 0.25;      ///< column spacing of the height fields
  double max_footprint_mm = 200;   ///< facing extents beyond this are refused (wrong units)
  double rim_margin_mm = 0.5;      ///< wall placed this far inside the facing footprint
  int outline_harmonics = 12;      ///< Fourier terms kept in the smoothed outline
  double nucleus_area_fraction = 0.4;
};

/// What was found between the vertebrae (all in mm, global frame unless stated).
struct VertebraDiscInfo {
  DiscFrame frame;                ///< origin mid-disc at the footprint's area centroid
  double footprint_area_mm2 = 0;  ///< area of the disc cross-section (smoothed outline)
  double center_height_mm = 0;    ///< endplate gap at the frame origin
  double min_height_mm = 0, max_height_mm = 0;  ///< over the footprint
  double volume_mm3 = 0;                        ///< ∫ gap dA over the footprint (quadrature)
  double width_mm = 0, depth_mm = 0;            ///< extents of the outline along frame x and z
  /// Footprint columns whose endplate heights were interpolated: a hole in an endplate (the ray
  /// missed it or hit the far side of the vertebra). 0 for closed endplates.
  long filled_columns = 0;
  double filled_area_mm2 = 0;
};

/// Finds the facing endplates and the disc body without meshing. Throws
/// std::invalid_argument with a one-line message for empty surfaces or vertebrae that do not
/// face each other (superior not above inferior, no overlapping endplates, gap <= 0 or
/// > max_gap_mm).
VertebraDiscInfo analyse_vertebra_pair(const TriSurface& inferior_vertebra,
                                       const TriSurface& superior_vertebra,
                                       const VertebraDiscOptions& opt = {});

/// Meshes the disc; the mesh is in the vertebrae's frame (between them) and carries `frame`.
/// `info`, if given, receives the analysis. Throws as analyse_vertebra_pair.
TetMesh mesh_disc_between_vertebrae(const TriSurface& inferior_vertebra,
                                    const TriSurface& superior_vertebra,
                                    const MeshOptions& mesh_opt,
                                    const VertebraDiscOptions& opt = {},
                                    VertebraDiscInfo* info = nullptr);

}  // namespace spinesim::mesh

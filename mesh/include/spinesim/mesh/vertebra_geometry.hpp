// Parametric vertebrae T1…L5 and a schematic sacrum for the haptic scene: watertight triangle
// surfaces, placed at the spine model's reference posture.
//
// A vertebra is the union of simple solids in its own frame (origin at the body centre, y along
// the body axis, z anterior, x lateral):
//   - the body: the disc outline (KidneyOutline) lofted from the lower to the upper endplate
//     with a 6 % waist, so that its endplates are exactly the outlines of the discs above and
//     below it; it fills the gap between the two discs (F.2 joint points, disc heights);
//   - the neural arch: two pedicles, two laminae meeting at the midline behind the canal,
//     the spinous process, two transverse processes and four articular processes, each a
//     rounded box swept along a segment.
// Dimensions of the arch come from data/vertebra_morphometry.csv (a source or a labelled
// assumption for each column). The union is meshed by CGAL Mesh_3 (mesh_labeled_body) and its
// boundary taken, so the surface is closed and consistently oriented by construction.
#pragma once

#include "spinesim/mesh/io.hpp"
#include "spinesim/mesh/tet_mesh.hpp"

#include <Eigen/Core>

#include <string>
#include <vector>

namespace spinesim::mesh {

/// One row of data/vertebra_morphometry.csv (mm, degrees).
struct VertebraMorphometry {
  std::string level;
  double pedicle_width_mm = 0, pedicle_height_mm = 0;
  double canal_width_mm = 0, canal_depth_mm = 0;
  double lamina_thickness_mm = 0, lamina_height_fraction = 0;
  double spinous_length_mm = 0, spinous_height_mm = 0, spinous_thickness_mm = 0;
  double spinous_angle_deg = 0;  ///< below the body's transverse plane, pointing posterior
  double transverse_span_mm = 0, transverse_sweep_deg = 0, transverse_rise_deg = 0;
  double facet_radius_mm = 0, facet_length_mm = 0;
};

/// The 18 rigid bodies of the scene, top to bottom: "T1" … "L5", "S1" (the sacrum).
const std::vector<std::string>& scene_body_names();

/// Reads one level (T1…L5) of data/vertebra_morphometry.csv. Throws std::invalid_argument for an
/// unknown level (listing the known ones) or a malformed file.
VertebraMorphometry vertebra_morphometry(const std::string& level, const std::string& data_dir);

/// A solid given by rounded boxes swept along segments, plus an optional lofted body.
/// `contains` is exact for the solid it describes; the mesher samples it.
struct SweptBox {
  Eigen::Vector3d a, b;  ///< segment ends, mm
  Eigen::Vector3d up;    ///< approximate "height" direction (orthogonalised against b − a)
  double half_width_mm = 0, half_height_mm = 0, rounding_mm = 0;
  /// Signed distance (mm; < 0 inside) of p to the box swept from a to b.
  double signed_distance(const Eigen::Vector3d& p) const;
};

/// A vertebra (or the sacrum) in its own frame, and where that frame sits in the spine.
struct ParametricVertebra {
  std::string name;
  DiscFrame frame;  ///< origin = body centre; axes as a disc's (lateral, axial, anterior)
  double body_height_mm = 0;
  double lower_width_mm = 0, lower_depth_mm = 0, upper_width_mm = 0, upper_depth_mm = 0;
  double waist = 0.06;          ///< the body's mid-height outline is (1 − waist) of the loft
  std::vector<SweptBox> parts;  ///< the neural arch (or the sacral wings and plate), local mm
  /// Inside test in the local frame (mm).
  bool contains(const Eigen::Vector3d& p_local_mm) const;
  /// Centre and radius of a sphere (local frame) holding the whole solid.
  Eigen::Vector3d bounding_center_mm() const;
  double bounding_radius_mm() const;
};

/// Builds the parametric vertebra `name` ("T1"…"L5", or "S1" for the sacrum) at the spine
/// model's reference posture from data/ (disc_morphometry.csv, the thesis's F.1/F.2 tables and
/// vertebra_morphometry.csv). Throws std::invalid_argument for an unknown name.
ParametricVertebra parametric_vertebra(const std::string& name, const std::string& data_dir);

/// A closed triangle surface of one rigid body, in the global frame at the reference posture.
struct VertebraSurface {
  std::string name;  ///< "T1" … "L5", "S1"
  TriSurface surface;
  DiscFrame frame;  ///< the body's frame at the reference posture (origin = body centre)
};

/// Meshes `v` with about `target_triangles` boundary triangles (Mesh_3 facet size chosen from
/// the solid's area; the count lands within about ±30 % of the target) and maps it to the
/// global frame. Throws std::invalid_argument for target_triangles < 100 or > 2,000,000.
VertebraSurface mesh_vertebra(const ParametricVertebra& v, int target_triangles = 8000);

/// The boundary of a tetrahedral mesh: faces used by exactly one tetrahedron, oriented outward
/// (tetrahedra are positively oriented), with only the vertices they use.
TriSurface boundary_surface(const TetMesh& m);

/// Writes a triangle surface as an OBJ file (vertices in mm, 1-based faces), atomically.
void write_obj(const std::string& path, const TriSurface& s, const std::string& comment = "");

/// Checks of a closed surface: every edge shared by exactly two faces with opposite
/// orientations (closed, consistently oriented, edge-manifold), and the enclosed volume (mm³,
/// positive for outward normals).
struct SurfaceCheck {
  bool closed = false;    ///< every edge in exactly two faces
  bool oriented = false;  ///< ... which traverse it in opposite directions
  double volume_mm3 = 0;
  double area_mm2 = 0;
  int boundary_edges = 0, nonmanifold_edges = 0;
};
SurfaceCheck check_surface(const TriSurface& s);

/// Area-weighted centroid of the triangles (mm); the surface need not be closed. Throws
/// std::invalid_argument for a surface of zero area.
Eigen::Vector3d surface_centroid(const TriSurface& s);

}  // namespace spinesim::mesh

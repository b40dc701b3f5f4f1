// TetMesh — the tetrahedral disc mesh every module shares.
//
// Conventions (docs/units-and-frame.md):
//   - coordinates in mm, frame x lateral (body's right is -x), y superior, z anterior;
//   - tets are positively oriented: det[v1-v0, v2-v0, v3-v0] > 0;
//   - cell label `region`: 1 annulus, 2 nucleus (other positive labels allowed for
//     non-disc test bodies);
//   - point label `surface`: 0 interior, 1 inferior endplate (fixed), 2 superior endplate
//     (rigid plate), 3 outer wall. Rim nodes shared by an endplate and the wall carry the
//     endplate label.
#pragma once

#include <Eigen/Core>

#include <string>

namespace spinesim::mesh {

enum class Region : int { annulus = 1, nucleus = 2 };
enum class Surface : int {
  interior = 0,
  inferior_endplate = 1,
  superior_endplate = 2,
  outer_wall = 3
};

/// Rigid frame of a disc: origin at the mid-disc centre, columns of `axes` are the disc's
/// lateral (x), axial (y, inferior -> superior) and anterior (z) unit vectors, in the global
/// frame. Identity axes for a disc built upright at the origin.
struct DiscFrame {
  Eigen::Vector3d origin_mm = Eigen::Vector3d::Zero();
  Eigen::Matrix3d axes = Eigen::Matrix3d::Identity();
};

/// Collagen fibre directions a mesh brings with it, per tet: a peer model's fibre paths, say.
/// Both #T×3 with unit rows (zero rows where the tet has none), or both empty when the mesh
/// brings none. A fibre-reinforced material then lays its two families along these instead of
/// along the annulus geometry; stiffness, toe and depth still come from the material
/// (fibre_field.hpp). VTU cell data `fibre_path_direction_1/2` (io.hpp).
struct FibrePaths {
  Eigen::MatrixX3d direction_1, direction_2;
  bool empty() const { return direction_1.rows() == 0 && direction_2.rows() == 0; }
};

struct TetMesh {
  Eigen::MatrixX3d V;       ///< #V×3 vertex positions, mm
  Eigen::MatrixX4i T;       ///< #T×4 vertex indices, positively oriented
  Eigen::VectorXi region;   ///< #T cell labels (Region)
  Eigen::VectorXi surface;  ///< #V point labels (Surface)
  DiscFrame frame;          ///< disc frame (identity when unknown)
  std::string source;       ///< provenance, e.g. "parametric L4-L5" or a file name
  FibrePaths fibre_paths;   ///< fibre directions given with the mesh (usually none)

  Eigen::Index num_vertices() const { return V.rows(); }
  Eigen::Index num_tets() const { return T.rows(); }
};

/// Signed volume of tet t, mm^3 (positive when correctly oriented).
double tet_volume(const TetMesh& m, Eigen::Index t);

/// Sum of signed tet volumes, mm^3.
double mesh_volume(const TetMesh& m);

/// Throws std::invalid_argument with a one-line message when the mesh is unusable:
/// empty, index out of range, non-finite coordinates, inverted or zero-volume tets
/// (relative to the mean edge length cubed), label arrays of the wrong size, a disc frame whose
/// axes are not orthonormal (validate_frame), fibre paths that are not one unit or zero row per
/// tet in both families (validate_fibre_paths).
void validate(const TetMesh& m);

/// Throws std::invalid_argument (one line, naming `what`) unless the frame's axes are orthonormal
/// to 1e-6 (a rotation, or a mirror for a mirrored disc) and its origin finite and within 1e6 mm.
/// A frame of zero, scaled or skewed axes would turn every load case into another load (a zero
/// load, a 1000-fold one, a sideways one) without an error.
void validate_frame(const DiscFrame& frame, const std::string& what = "disc frame");

/// Throws std::invalid_argument (one line) unless `m.fibre_paths` is empty, or both families have
/// one row per tet, each row finite and either zero or of unit length to 1e-4 (Float32 copies
/// pass; fibre_field normalises them).
void validate_fibre_paths(const TetMesh& m);

/// The boundary of tetrahedra `T` (#T×4): the faces used by exactly one tet, oriented outward
/// (for positively oriented tets), in the order their tets come; `owner` (when not null) gets
/// each face's tet.
Eigen::MatrixX3i boundary_faces(const Eigen::MatrixXi& T, Eigen::VectorXi* owner = nullptr);

/// Throws std::invalid_argument unless both endplate labels (1 and 2) are present.
void require_endplate_labels(const TetMesh& m);

}  // namespace spinesim::mesh

// The nonlinear disc reference: the disc problem of disc_fem.hpp (inferior endplate fixed,
// superior endplate on a rigid plate driven by a motion q = (t mm, θ rad)) with the material of
// hyperelastic.hpp, finite strain and a finite plate rotation:
//
//   plate nodes:  x = c + t + R(θ) (X − c),  R(θ) the rotation by the vector θ (axis θ/|θ|,
//                 angle |θ|), which is t + θ × (X − c) to first order (mesh/rigid_plate.hpp);
//
// solved by hyperelastic_body.hpp (load increments, Newton, line search). The reaction is the
// wrench the disc exerts on the plate, force and moment about the moved centre c + t (N, N·mm),
// the sign convention of disc_fem.hpp: a compressive motion gives F_y > 0. At small motions it
// is the linear FEM's −K6 q (tested).
#pragma once

#include "spinesim/fem/hyperelastic.hpp"
#include "spinesim/fem/hyperelastic_body.hpp"
#include "spinesim/mesh/material.hpp"
#include "spinesim/mesh/tet_mesh.hpp"

#include <Eigen/Core>

#include <array>
#include <limits>
#include <optional>
#include <vector>

namespace spinesim::fem {

/// Each tet's material from `materials`: its region's matrix with the small-strain moduli of
/// its (E, ν) (neo_hookean_from_linear), and in a fibre-reinforced region the two families of
/// fibre_field (fibres.hpp) with k1 = k/4 — the tension stiffness of the linear fibres at small
/// isochoric strain (hyperelastic.hpp) — and the toe exponent `fibre_k2`.
/// The toe exponent k2 of the material's fibres (all fibre regions share it; 10 without fibres,
/// where it is unused).
double material_fibre_k2(const mesh::RegionMaterials& materials);

std::vector<FibreHyperelastic> disc_element_materials(const mesh::TetMesh& mesh,
                                                      const mesh::RegionMaterials& materials,
                                                      double fibre_k2);

/// What drives the plate, per DOF (t_x, t_y, t_z, θ_x, θ_y, θ_z): a motion (mm, rad) or a load
/// the plate applies to the disc (N, N·mm about the moved centre). A moment does the work M·θ
/// (θ the rotation vector): exact for a rotation about the moment's axis, as in the in-vitro
/// tests; a second-order approximation of a fixed-direction moment otherwise.
struct PlateLoad {
  std::array<bool, 6> motion_given{};  ///< true: `value` is the motion; false: the load
  Eigen::Matrix<double, 6, 1> value = Eigen::Matrix<double, 6, 1>::Zero();
};

/// One converged load increment of a plate solve: the fraction of the load (or motion) reached
/// and the plate motion there — the load–displacement path, e.g. a moment–rotation curve.
struct PlatePathPoint {
  double load_fraction = 0;
  Eigen::Matrix<double, 6, 1> plate_motion;  ///< (t mm, θ rad)
};

struct NonlinearPlateSolution {
  HyperelasticSolution body;  ///< nodal displacements, reactions, Newton counts, convergence
  Eigen::Matrix<double, 6, 1> plate_motion;     ///< (t mm, θ rad)
  Eigen::Matrix<double, 6, 1> reaction_wrench;  ///< (F N, M N·mm about c + t)
  std::vector<PlatePathPoint> path;  ///< solve(): every converged increment, from the first
  /// Volume mean (reference volumes) of the hydrostatic pressure over the nucleus tets (region
  /// 2), MPa, positive in compression; NaN without a nucleus.
  double nucleus_pressure_mpa = std::numeric_limits<double>::quiet_NaN();
};

class NonlinearDisc {
 public:
  /// Throws std::invalid_argument for a mesh without endplate labels, a bad order or material
  /// count.
  /// `form`: how the elements take the volume change (hyperelastic_element.hpp); by default
  /// the one that keeps a nearly incompressible nucleus from locking on that order —
  /// nodal_average on P1, mean_dilatation on P2. `pointwise` is CalculiX's C3D4/C3D10.
  NonlinearDisc(const mesh::TetMesh& mesh, std::vector<FibreHyperelastic> element_materials,
                int order, const Eigen::Vector3d& plate_center_mm,
                std::optional<VolumetricForm> form = std::nullopt);

  NonlinearPlateSolution solve_motion(const Eigen::Matrix<double, 6, 1>& motion,
                                      const NewtonOptions& options = NewtonOptions()) const;

  /// The plate driven and loaded per DOF (the plate's six unknowns solved with the disc).
  NonlinearPlateSolution solve(const PlateLoad& load,
                               const NewtonOptions& options = NewtonOptions()) const;

  const Eigen::Vector3d& plate_center() const { return center_; }
  const HyperelasticBody& body() const { return body_; }

 private:
  Eigen::Matrix<double, 6, 1> plate_reaction(const HyperelasticSolution& body,
                                             const Eigen::Vector3d& t) const;
  double nucleus_pressure(const HyperelasticSolution& body) const;

  Eigen::VectorXi labels_;
  Eigen::VectorXi region_;  ///< per tet
  HyperelasticBody body_;
  Eigen::Vector3d center_;
};

}  // namespace spinesim::fem

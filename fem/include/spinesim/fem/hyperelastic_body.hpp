// A hyperelastic body (hyperelastic_element.hpp on every tet, a material per tet) held by
// prescribed nodal displacements, solved for equilibrium by Newton's method:
//
//   the prescribed values are ramped in load increments; in each, Newton on the free DOF
//   (K_ff Δu = −r_f, K_ff the tangent, CHOLMOD LLᵀ on the pattern analysed once) with a
//   backtracking line search on the total energy (Armijo; near the solution, where the energy's
//   rounding hides the predicted decrease, on the residual norm — fem/src/newton_steps.hpp; a
//   state with an inverted quadrature point has no energy and is stepped back from); an
//   increment that does not converge is halved, at most `max_cutbacks` times in a row, and then
//   the solve fails with the reason — a failed solve never reports `converged`.
//
// Convergence of an increment: the last correction ‖Δu‖∞ ≤ tolerance · max(‖u‖∞, 1 mm) and
// ‖r_f‖ ≤ tolerance · max(‖f‖, 1 N) (f the internal force of the prescribed DOF, i.e. the
// reaction), or ‖r_f‖ within a thousand times that once the correction is at rounding (the
// residual's floor with a nearly incompressible region; newton_steps.hpp measures it).
// Units: mm, N, mJ (N·mm).
#pragma once

#include "spinesim/fem/fe_space.hpp"
#include "spinesim/fem/hyperelastic.hpp"
#include "spinesim/fem/hyperelastic_element.hpp"

#include <Eigen/Core>
#include <Eigen/SparseCore>

#include <memory>
#include <string>
#include <vector>

namespace spinesim::fem {

namespace detail {
class NodalVolumes;
}

struct PrescribedDisplacement {
  Eigen::Index node = 0;
  int dof = 0;  ///< 0, 1, 2 = x, y, z
  double value_mm = 0;
};

struct NewtonOptions {
  int load_increments = 4;   ///< equal increments of the prescribed values (>= 1)
  int max_iterations = 30;   ///< Newton iterations per increment
  double tolerance = 1e-10;  ///< relative residual and correction (see header)
  int max_cutbacks = 8;      ///< successive halvings of a failing increment
};

struct HyperelasticSolution {
  Eigen::MatrixX3d displacement_mm;  ///< #nodes×3
  Eigen::MatrixX3d reaction_n;       ///< #nodes×3 internal force at prescribed DOF (0 elsewhere)
  double energy_mj = 0;
  bool converged = false;
  std::string failure;  ///< why it did not converge (empty when it did)
  int increments = 0, newton_iterations = 0, factorisations = 0, cutbacks = 0;
  double residual_n = 0;  ///< ‖r_f‖ at the end
  double seconds = 0;
};

class HyperelasticBody {
 public:
  /// One material per tet (validated). Throws std::invalid_argument for a count that does not
  /// match the elements or a bad material.
  HyperelasticBody(FeSpace space, std::vector<FibreHyperelastic> element_materials,
                   VolumetricForm form = VolumetricForm::pointwise);

  /// Energy, internal force (3·#nodes) and, if asked, the full tangent (lower triangle) at the
  /// nodal displacements u (3·#nodes, node-major). `inverted` counts quadrature points with
  /// det F <= 0 (the energy is then NaN).
  struct Evaluation {
    double energy = 0;
    Eigen::VectorXd force;
    Eigen::SparseMatrix<double> tangent_lower;
    int inverted = 0;
  };
  Evaluation evaluate(const Eigen::VectorXd& u, bool with_tangent) const;

  /// Per tet, the hydrostatic pressure −tr σ / 3 (MPa, positive in compression) at nodal
  /// displacements u, as the volumetric form takes it: −U'(J̄) with J̄ the tet's mean dilatation
  /// (pointwise and mean dilatation: U is quadratic, so the mean of −U'(J) over the points is
  /// −U'(J̄)), the mean of its nodes' −U'(J_n) for the nodal average. The isochoric part adds
  /// nothing to the trace (S̄ : C = 0).
  Eigen::VectorXd element_pressures_mpa(const Eigen::VectorXd& u) const;

  /// Equilibrium with the prescribed DOF (each at most once; throws std::invalid_argument
  /// otherwise or for a node out of range).
  HyperelasticSolution solve(const std::vector<PrescribedDisplacement>& prescribed,
                             const NewtonOptions& options = NewtonOptions()) const;

  const FeSpace& space() const { return space_; }
  const std::vector<FibreHyperelastic>& materials() const { return materials_; }
  VolumetricForm form() const { return form_; }

 private:
  FeSpace space_;
  std::vector<FibreHyperelastic> materials_;
  VolumetricForm form_ = VolumetricForm::pointwise;
  std::shared_ptr<const detail::NodalVolumes> nodal_;  ///< the nodal-average form's fixed data
};

}  // namespace spinesim::fem

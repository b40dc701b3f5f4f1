// Muscle recruitment by static optimisation (Ipopt, private): at a posture, find fascicle forces
// 0 ≤ F_i ≤ pcsa_i·σmax_i and passive joint moments r whose sum balances the load moments about
// every recruited joint. The passive joint is one more actuator per axis, whose "strength" is the
// moment its F.4 spring carries at the F.5 range-of-motion limit (R = k·ROM, flexion and
// extension apart): the criterion shares the load between muscles and the joint by the same
// activation measure (a_i = F_i/F_max,i for muscles, |r|/R for a joint axis),
//   polynomial: minimise Σ a^p over muscles and joint axes (p = 3 by default: AnyBody's default),
//   min–max:    minimise t with every a ≤ t (+ 1e-3·Σ a_i² to make the optimum unique).
// Joint activations may exceed 1 (beyond the range the ROM bump carries it); muscles may not. The
// joint's share r is not a force anybody applies: the equilibrium solve leaves it unbalanced,
// so the joint deforms until its spring carries it.
#pragma once

#include "spinesim/spine/model.hpp"

#include <Eigen/Core>

#include <string>
#include <vector>

namespace spinesim::spine {

enum class Criterion { Polynomial, MinMax };

struct RecruitmentOptions {
  Criterion criterion = Criterion::Polynomial;
  double power = 3;                   ///< p of the polynomial criterion (≥ 1)
  double passive_strength_scale = 1;  ///< multiplies every joint strength R = k·ROM (> 0)
  int max_iterations = 200;
  double tolerance = 1e-9;
};

struct Recruitment {
  bool success = false;
  std::string status;  ///< Ipopt's return status
  int iterations = 0;
  double objective = 0;
  Eigen::VectorXd force_n;      ///< per muscle, N
  Eigen::VectorXd activation;   ///< F / F_max
  Eigen::VectorXd reserve_nmm;  ///< the joints' share r: 3 per recruited joint (x, y, z), N·mm
  Eigen::VectorXd passive_activation;  ///< |r| / R per recruited joint axis
  double max_constraint_violation_nmm = 0;
  double seconds = 0;
};

/// `load_moment_nmm` holds, per recruited joint (order of m.recruited_joints, fused ones
/// skipped, as recruitment_problem() builds it), the world moment about the joint point that
/// muscles and joint must supply; `arm` (3·joints × muscles) the moment of a unit tension of each
/// muscle about each joint (zero where a muscle does not cross it). Throws std::invalid_argument
/// for bad options or sizes.
Recruitment recruit(const SpineModel& m, const Eigen::MatrixXd& arm,
                    const Eigen::VectorXd& load_moment_nmm,
                    const RecruitmentOptions& options = RecruitmentOptions());

}  // namespace spinesim::spine

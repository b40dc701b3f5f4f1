// Muscle recruitment by static optimisation (Ipopt, private): at a posture, find fascicle forces
// 0 ≤ F_i ≤ pcsa_i·σmax_i whose moments balance the load moments about every recruited joint,
//   polynomial: minimise Σ (F_i / F_max,i)^p   (p = 3 by default; AnyBody's default criterion),
//   min–max:    minimise t  with F_i / F_max,i ≤ t  (+ 1e-3·Σ a_i² to make the optimum unique),
// plus a "reserve" moment r_j per recruited joint axis, heavily penalised (w_r Σ (r/1 N·m)²), that
// the joint's passive spring must carry when the muscles cannot (capacity, or no lever arm).
#pragma once

#include "spinesim/spine/model.hpp"

#include <Eigen/Core>

#include <string>
#include <vector>

namespace spinesim::spine {

enum class Criterion { Polynomial, MinMax };

struct RecruitmentOptions {
  Criterion criterion = Criterion::Polynomial;
  double power = 3;             ///< p of the polynomial criterion (≥ 1)
  double reserve_weight = 1e3;  ///< w_r, per (N·m)² of reserve moment
  int max_iterations = 200;
  double tolerance = 1e-9;
};

struct Recruitment {
  bool success = false;
  std::string status;                 ///< Ipopt's return status
  int iterations = 0;
  double objective = 0;
  Eigen::VectorXd force_n;            ///< per muscle, N
  Eigen::VectorXd activation;         ///< F / F_max
  Eigen::VectorXd reserve_nmm;        ///< 3 per recruited joint (world axes), N·mm
  double max_constraint_violation_nmm = 0;
  double seconds = 0;
};

/// `load_moment_nmm` holds, per recruited joint (order of m.recruited_joints, fused ones
/// skipped by the caller), the world moment about the joint point that the muscles must
/// supply; `arm` (3·joints × muscles) the moment of a unit tension of each muscle about each
/// joint (zero where a muscle does not cross it). Throws std::invalid_argument for bad options.
Recruitment recruit(const SpineModel& m, const Eigen::MatrixXd& arm, const Eigen::VectorXd& load_moment_nmm,
                    const RecruitmentOptions& options = RecruitmentOptions());

}  // namespace spinesim::spine

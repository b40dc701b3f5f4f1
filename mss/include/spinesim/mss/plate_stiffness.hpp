// The MSS disc's 6×6 plate stiffness at rest: the linear response of the superior plate's six
// rigid DOF q = (t mm, theta rad) about a centre c with the inferior endplate fixed — the same
// quantity as fem::DiscFem::stiffness_6x6, so the two models compare entry by entry.
//
// With the rest Hessian H split into free DOF f and plate nodes p, and the plate nodes slaved
// by the rigid map u_p = T q (T stacks mesh::plate_map(X_i − c) over the plate nodes):
//     K6 = T'K_pp T − (K_fp T)' K_ff^-1 (K_fp T)        (static condensation).
// The whole-disc volume term's Hessian has a dense rank-one part k_g u u' (model.hpp); it is
// kept out of the sparse K_ff and added by Sherman–Morrison.
#pragma once

#include "spinesim/mss/boundary.hpp"
#include "spinesim/mss/elements.hpp"
#include "spinesim/mss/model.hpp"

#include <Eigen/Core>

namespace spinesim::mss {

/// K6 at rest about `center_mm`: rows (F N, M N·mm), columns (t mm, theta rad), symmetric.
/// Throws std::runtime_error if the free-node stiffness does not factorise (an unconstrained
/// mesh) or the result is not finite.
Matrix6d plate_stiffness(const MssModel& model, const Eigen::Vector3d& center_mm);

}  // namespace spinesim::mss

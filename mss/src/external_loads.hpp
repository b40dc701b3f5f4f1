// External loads of a Boundary as a potential (private to mss/):
//   V_ext(x) = sum_probes sum_nodes E_probe(x_i) - f . x        (W_ext = -V_ext, plus w . q)
// The plate wrench's work w . q is added by the callers on the reduced plate DOF.
#pragma once

#include "reduced_space.hpp"
#include "spinesim/mss/boundary.hpp"
#include "spinesim/mss/model.hpp"

#include <Eigen/Core>
#include <Eigen/SparseCore>

#include <vector>

namespace spinesim::mss::detail {

/// 100 k̄, k̄ = trace(K_rest) / (2 #edge springs) (boundary.hpp, Probe::stiffness_n_per_mm),
/// from the full rest Hessian of the model.
double default_probe_stiffness(const MssModel& model,
                               const Eigen::SparseMatrix<double>& rest_hessian);

class ExternalLoads {
 public:
  /// `default_probe_k`: used for probes whose stiffness is 0. `surface` (#nodes labels, may be
  /// null): probes touch only nodes with a non-zero surface label — contact is a surface effect,
  /// and a probe pressed deep must not grab interior nodes directly.
  ExternalLoads(const Boundary& bc, double default_probe_k,
                const Eigen::VectorXi* surface = nullptr);
  ExternalLoads() = default;  ///< no loads

  bool empty() const { return probes_.empty() && forces_ == nullptr; }
  /// V_ext(x), N·mm.
  double energy(const Eigen::VectorXd& x) const;
  /// g += dV_ext/dx; returns V_ext(x).
  double add_gradient(const Eigen::VectorXd& x, Eigen::VectorXd& g) const;
  /// A += P^T d2V_ext/dx2 P (probe contact blocks of the unknown nodes).
  void add_hessian(const Eigen::VectorXd& x, HessianMode mode, const ReducedSpace& space,
                   Eigen::SparseMatrix<double>& A) const;
  /// Nodes inside some probe at x (sorted, unique).
  void contact_nodes(const Eigen::VectorXd& x, std::vector<int>& nodes) const;
  const std::vector<Probe>& probes() const { return probes_; }  ///< stiffness resolved
  /// |f| + |probe forces at x|, N (a force scale for convergence tests).
  double force_scale(const Eigen::VectorXd& x) const;
  /// May probes touch node i?
  bool touchable(Eigen::Index i) const { return surface_ == nullptr || (*surface_)(i) != 0; }

 private:
  std::vector<Probe> probes_;
  const Eigen::VectorXd* forces_ = nullptr;   ///< points into the Boundary, or null
  const Eigen::VectorXi* surface_ = nullptr;  ///< the mesh's surface labels, or null (all nodes)
};

}  // namespace spinesim::mss::detail

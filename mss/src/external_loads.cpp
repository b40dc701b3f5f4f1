#include "external_loads.hpp"

#include <algorithm>
#include <cmath>

namespace spinesim::mss::detail {

double default_probe_stiffness(const MssModel& model, const Eigen::SparseMatrix<double>& H) {
  const double edges = double(std::max<Eigen::Index>(1, model.num_edge_springs()));
  return 100.0 * H.diagonal().sum() / (2.0 * edges);
}

ExternalLoads::ExternalLoads(const Boundary& bc, double default_probe_k,
                             const Eigen::VectorXi* surface)
    : probes_(bc.probes), surface_(surface) {
  for (Probe& p : probes_)
    if (p.stiffness_n_per_mm == 0.0) p.stiffness_n_per_mm = default_probe_k;
  if (bc.nodal_forces_n.size() > 0) forces_ = &bc.nodal_forces_n;
}

double ExternalLoads::energy(const Eigen::VectorXd& x) const {
  double e = 0;
  const Eigen::Index n = x.size() / 3;
  for (const Probe& p : probes_)
    for (Eigen::Index i = 0; i < n; ++i)
      if (touchable(i))
        e += probe_contact(x.segment<3>(3 * i), p.center_mm, p.radius_mm, p.stiffness_n_per_mm);
  if (forces_) e -= forces_->dot(x);
  return e;
}

double ExternalLoads::add_gradient(const Eigen::VectorXd& x, Eigen::VectorXd& g) const {
  double e = 0;
  const Eigen::Index n = x.size() / 3;
  Eigen::Vector3d gi;
  for (const Probe& p : probes_) {
    const double r2 = p.radius_mm * p.radius_mm;
    for (Eigen::Index i = 0; i < n; ++i) {
      if ((x.segment<3>(3 * i) - p.center_mm).squaredNorm() >= r2 || !touchable(i)) continue;
      e += probe_contact(x.segment<3>(3 * i), p.center_mm, p.radius_mm, p.stiffness_n_per_mm, &gi);
      g.segment<3>(3 * i) += gi;
    }
  }
  if (forces_) {
    e -= forces_->dot(x);
    g -= *forces_;
  }
  return e;
}

void ExternalLoads::add_hessian(const Eigen::VectorXd& x, HessianMode mode,
                                const ReducedSpace& space, Eigen::SparseMatrix<double>& A) const {
  const Eigen::Index n = x.size() / 3;
  Eigen::Vector3d gi;
  Eigen::Matrix3d hi;
  for (const Probe& p : probes_) {
    const double r2 = p.radius_mm * p.radius_mm;
    for (Eigen::Index i = 0; i < n; ++i) {
      if ((x.segment<3>(3 * i) - p.center_mm).squaredNorm() >= r2 || !space.is_unknown(int(i)) ||
          !touchable(i))
        continue;
      probe_contact(x.segment<3>(3 * i), p.center_mm, p.radius_mm, p.stiffness_n_per_mm, &gi, &hi,
                    mode);
      space.add_node_block(int(i), hi, A);
    }
  }
}

void ExternalLoads::contact_nodes(const Eigen::VectorXd& x, std::vector<int>& nodes) const {
  nodes.clear();
  const Eigen::Index n = x.size() / 3;
  for (const Probe& p : probes_) {
    const double r2 = p.radius_mm * p.radius_mm;
    for (Eigen::Index i = 0; i < n; ++i)
      if ((x.segment<3>(3 * i) - p.center_mm).squaredNorm() < r2 && touchable(i))
        nodes.push_back(int(i));
  }
  std::sort(nodes.begin(), nodes.end());
  nodes.erase(std::unique(nodes.begin(), nodes.end()), nodes.end());
}

double ExternalLoads::force_scale(const Eigen::VectorXd& x) const {
  double s = forces_ ? forces_->norm() : 0.0;
  const Eigen::Index n = x.size() / 3;
  Eigen::Vector3d gi;
  for (const Probe& p : probes_) {
    Eigen::Vector3d f = Eigen::Vector3d::Zero();
    for (Eigen::Index i = 0; i < n; ++i) {
      if (!touchable(i)) continue;
      probe_contact(x.segment<3>(3 * i), p.center_mm, p.radius_mm, p.stiffness_n_per_mm, &gi);
      f += gi.cwiseAbs();
    }
    s += f.norm();
  }
  return s;
}

}  // namespace spinesim::mss::detail

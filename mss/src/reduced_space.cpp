#include "reduced_space.hpp"

#include <Eigen/Cholesky>

#include <cassert>
#include <cmath>
#include <stdexcept>

namespace spinesim::mss::detail {

void LumpedReduced::apply(const Eigen::VectorXd& y, Eigen::VectorXd& out) const {
  out.noalias() = diagonal.cwiseProduct(y);
  if (y.size() >= 6 && !plate.isZero(0.0)) out.tail<6>().noalias() += plate * y.tail<6>();
}

double LumpedReduced::quadratic_form(const Eigen::VectorXd& y) const {
  double s = y.dot(diagonal.cwiseProduct(y));
  if (y.size() >= 6 && !plate.isZero(0.0)) s += y.tail<6>().dot(plate * y.tail<6>());
  return s;
}

ReducedSpace::ReducedSpace(const MssModel& model, const Eigen::SparseMatrix<double>& H,
                           PlateMode mode, const Eigen::Vector3d& c)
    : mode_(mode), center_(c), X_(model.rest_positions_mm()) {
  const int nn = int(model.num_nodes());
  if (H.rows() != 3 * nn || H.cols() != 3 * nn || !H.isCompressed())
    throw std::logic_error("mss: reduced space needs the model's compressed Hessian pattern");
  classify_nodes(model.mesh(), nn);
  const std::vector<int> outer = build_pattern(H);
  build_scatter(H, outer);
}

// 1. Node roles and numbering (free nodes in node order, so reduced rows stay sorted), the
//    plate maps and the moment length.
void ReducedSpace::classify_nodes(const mesh::TetMesh& m, int nn) {
  const Eigen::Vector3d& c = center_;
  role_.assign(std::size_t(nn), NodeRole::free);
  free_index_.assign(std::size_t(nn), -1);
  plate_index_.assign(std::size_t(nn), -1);
  for (int i = 0; i < nn; ++i) {
    const int label = i < m.surface.size() ? m.surface(i) : 0;
    if (label == int(mesh::Surface::inferior_endplate)) {
      role_[std::size_t(i)] = NodeRole::inferior;
      inferior_nodes_.push_back(i);
    } else if (label == int(mesh::Surface::superior_endplate)) {
      role_[std::size_t(i)] = NodeRole::superior;
      plate_index_[std::size_t(i)] = int(superior_nodes_.size());
      superior_nodes_.push_back(i);
    } else {
      free_index_[std::size_t(i)] = int(free_nodes_.size());
      free_nodes_.push_back(i);
    }
  }
  if (mode_ == PlateMode::wrench && superior_nodes_.empty())
    throw std::invalid_argument("mss: a plate wrench needs superior endplate nodes (surface = 2)");
  double arm2 = 0;
  for (int i : superior_nodes_) {
    const Eigen::Vector3d arm = X_.segment<3>(3 * i) - c;
    plate_maps_.push_back(plate_map(arm));
    arm2 += arm.squaredNorm();
  }
  if (!superior_nodes_.empty() && arm2 > 0)
    moment_length_ = std::sqrt(arm2 / double(superior_nodes_.size()));
  const int nf3 = 3 * int(free_nodes_.size());
  const bool plate = has_plate_dofs();
  n_ = nf3 + (plate ? 6 : 0);
}

// 2. Pattern of the lower triangle of P^T H P; returns its column starts.
std::vector<int> ReducedSpace::build_pattern(const Eigen::SparseMatrix<double>& H) {
  const int nf3 = 3 * int(free_nodes_.size());
  const bool plate = has_plate_dofs();
  const int* Hout = H.outerIndexPtr();
  const int* Hin = H.innerIndexPtr();
  std::vector<int> outer(std::size_t(n_) + 1, 0);
  std::vector<int> inner;
  inner.reserve(std::size_t(H.nonZeros() / 2 + 6 * nf3 + 21));
  std::vector<char> touches_plate(std::size_t(nf3), 0);
  for (int k = 0; k < int(free_nodes_.size()); ++k) {
    const int j = free_nodes_[std::size_t(k)];
    for (int d = 0; d < 3; ++d) {
      const int C = 3 * k + d, c_full = 3 * j + d;
      outer[std::size_t(C)] = int(inner.size());
      for (int p = Hout[c_full]; p < Hout[c_full + 1]; ++p) {
        const int i = Hin[p] / 3, e = Hin[p] % 3;
        if (role(i) == NodeRole::free) {
          const int R = 3 * free_index(i) + e;
          if (R >= C) inner.push_back(R);
        } else if (plate && role(i) == NodeRole::superior) {
          touches_plate[std::size_t(C)] = 1;
        }
      }
      if (touches_plate[std::size_t(C)])
        for (int q = 0; q < 6; ++q) inner.push_back(nf3 + q);
    }
  }
  if (plate)
    for (int q = 0; q < 6; ++q) {
      outer[std::size_t(nf3 + q)] = int(inner.size());
      for (int p = q; p < 6; ++p) {
        plate_slot_[p][q] = int(inner.size());
        inner.push_back(nf3 + p);
      }
    }
  outer[std::size_t(n_)] = int(inner.size());
  pattern_.resize(n_, n_);
  pattern_.resizeNonZeros(Eigen::Index(inner.size()));
  std::copy(outer.begin(), outer.end(), pattern_.outerIndexPtr());
  std::copy(inner.begin(), inner.end(), pattern_.innerIndexPtr());
  std::fill_n(pattern_.valuePtr(), inner.size(), 0.0);

  diag_slot_.resize(std::size_t(n_));
  for (int C = 0; C < nf3; ++C) {
    assert(inner[std::size_t(outer[std::size_t(C)])] == C);
    diag_slot_[std::size_t(C)] = outer[std::size_t(C)];
  }
  if (plate)
    for (int q = 0; q < 6; ++q) diag_slot_[std::size_t(nf3 + q)] = plate_slot_[q][q];

  return outer;
}

// 3. Scatter operations from the full Hessian's value array.
void ReducedSpace::build_scatter(const Eigen::SparseMatrix<double>& H,
                                 const std::vector<int>& outer) {
  const bool plate = has_plate_dofs();
  const int* Hout = H.outerIndexPtr();
  const int* Hin = H.innerIndexPtr();
  for (int k = 0; k < int(free_nodes_.size()); ++k) {
    const int j = free_nodes_[std::size_t(k)];
    for (int d = 0; d < 3; ++d) {
      const int C = 3 * k + d, c_full = 3 * j + d;
      int slot = outer[std::size_t(C)];
      for (int p = Hout[c_full]; p < Hout[c_full + 1]; ++p) {
        const int i = Hin[p] / 3, e = Hin[p] % 3;
        if (role(i) == NodeRole::free) {
          if (3 * free_index(i) + e >= C) ff_.push_back({p, slot++});
        } else if (plate && role(i) == NodeRole::superior) {
          fp_.push_back({p, outer[std::size_t(C) + 1] - 6, plate_index_[std::size_t(i)], e});
        }
      }
    }
  }
  if (plate)
    for (int j : superior_nodes_)
      for (int d = 0; d < 3; ++d) {
        const int c_full = 3 * j + d;
        for (int p = Hout[c_full]; p < Hout[c_full + 1]; ++p) {
          const int i = Hin[p] / 3, e = Hin[p] % 3;
          if (role(i) == NodeRole::superior)
            pp_.push_back({p, plate_index_[std::size_t(i)], e, plate_index_[std::size_t(j)], d});
        }
      }
}

void ReducedSpace::set_dirichlet_positions(const Boundary& bc, Eigen::VectorXd& x) const {
  for (int i : inferior_nodes_) x.segment<3>(3 * i) = bc.inferior.apply(X_.segment<3>(3 * i));
  if (!has_plate_dofs())
    for (int i : superior_nodes_) x.segment<3>(3 * i) = bc.superior.apply(X_.segment<3>(3 * i));
}

void ReducedSpace::set_unknown_positions(const Eigen::VectorXd& y, Eigen::VectorXd& x) const {
  for (std::size_t k = 0; k < free_nodes_.size(); ++k)
    x.segment<3>(3 * free_nodes_[k]) = y.segment<3>(3 * Eigen::Index(k));
  if (has_plate_dofs()) {
    const Vector6d q = y.tail<6>();
    for (std::size_t a = 0; a < superior_nodes_.size(); ++a) {
      const int i = superior_nodes_[a];
      x.segment<3>(3 * i) = X_.segment<3>(3 * i) + plate_maps_[a] * q;
    }
  }
}

void ReducedSpace::set_unknown_rates(const Eigen::VectorXd& dy, Eigen::VectorXd& v) const {
  for (std::size_t k = 0; k < free_nodes_.size(); ++k)
    v.segment<3>(3 * free_nodes_[k]) = dy.segment<3>(3 * Eigen::Index(k));
  if (has_plate_dofs()) {
    const Vector6d qdot = dy.tail<6>();
    for (std::size_t a = 0; a < superior_nodes_.size(); ++a)
      v.segment<3>(3 * superior_nodes_[a]) = plate_maps_[a] * qdot;
  }
}

void ReducedSpace::gather(const Eigen::VectorXd& x, const Vector6d& q, Eigen::VectorXd& y) const {
  for (std::size_t k = 0; k < free_nodes_.size(); ++k)
    y.segment<3>(3 * Eigen::Index(k)) = x.segment<3>(3 * free_nodes_[k]);
  if (has_plate_dofs()) y.tail<6>() = q;
}

Vector6d ReducedSpace::fit_plate_motion(const Eigen::VectorXd& x) const {
  Matrix6d N = Matrix6d::Zero();
  Vector6d b = Vector6d::Zero();
  for (std::size_t a = 0; a < superior_nodes_.size(); ++a) {
    const int i = superior_nodes_[a];
    N.noalias() += plate_maps_[a].transpose() * plate_maps_[a];
    b.noalias() += plate_maps_[a].transpose() * (x.segment<3>(3 * i) - X_.segment<3>(3 * i));
  }
  if (superior_nodes_.empty()) return Vector6d::Zero();
  return N.ldlt().solve(b);
}

void ReducedSpace::reduce_vector(const Eigen::VectorXd& g, Eigen::VectorXd& r) const {
  for (std::size_t k = 0; k < free_nodes_.size(); ++k)
    r.segment<3>(3 * Eigen::Index(k)) = g.segment<3>(3 * free_nodes_[k]);
  if (has_plate_dofs()) {
    Vector6d s = Vector6d::Zero();
    for (std::size_t a = 0; a < superior_nodes_.size(); ++a)
      s.noalias() += plate_maps_[a].transpose() * g.segment<3>(3 * superior_nodes_[a]);
    r.tail<6>() = s;
  }
}

void ReducedSpace::add_plate_block(const Matrix6d& B, double* val) const {
  for (int q = 0; q < 6; ++q)
    for (int p = q; p < 6; ++p) val[plate_slot_[p][q]] += B(p, q);
}

void ReducedSpace::reduce_matrix(const Eigen::SparseMatrix<double>& H,
                                 Eigen::SparseMatrix<double>& A) const {
  assert(A.nonZeros() == pattern_.nonZeros() && A.rows() == n_);
  const double* h = H.valuePtr();
  double* val = A.valuePtr();
  std::fill_n(val, A.nonZeros(), 0.0);
  for (const FreeFree& o : ff_) val[o.dst] += h[o.src];
  if (!has_plate_dofs()) return;
  for (const FreePlate& o : fp_) {
    const double v = h[o.src];
    const auto row = plate_maps_[std::size_t(o.plate)].row(o.comp);
    for (int p = 0; p < 6; ++p) val[o.dst + p] += v * row(p);
  }
  Matrix6d B = Matrix6d::Zero();
  for (const PlatePlate& o : pp_)
    B.noalias() += plate_maps_[std::size_t(o.plate_row)].row(o.comp_row).transpose() * h[o.src] *
                   plate_maps_[std::size_t(o.plate_col)].row(o.comp_col);
  add_plate_block(B, val);
}

void ReducedSpace::add_node_block(int node, const Eigen::Matrix3d& h,
                                  Eigen::SparseMatrix<double>& A) const {
  double* val = A.valuePtr();
  if (role(node) == NodeRole::free) {
    const int base = 3 * free_index(node);
    for (int d = 0; d < 3; ++d)
      for (int e = d; e < 3; ++e) val[diag_slot_[std::size_t(base + d)] + (e - d)] += h(e, d);
  } else if (role(node) == NodeRole::superior && has_plate_dofs()) {
    const Matrix36d& R = plate_maps_[std::size_t(plate_index_[std::size_t(node)])];
    add_plate_block(R.transpose() * h * R, val);
  }
}

void ReducedSpace::add_lumped(const LumpedReduced& L, double scale,
                              Eigen::SparseMatrix<double>& A) const {
  double* val = A.valuePtr();
  const Eigen::Index nf3 = plate_offset();
  for (Eigen::Index k = 0; k < nf3; ++k) val[diag_slot_[std::size_t(k)]] += scale * L.diagonal(k);
  if (has_plate_dofs()) add_plate_block(scale * L.plate, val);
}

LumpedReduced ReducedSpace::lumped(const Eigen::VectorXd& w) const {
  LumpedReduced L;
  L.diagonal.setZero(n_);
  for (std::size_t k = 0; k < free_nodes_.size(); ++k)
    L.diagonal.segment<3>(3 * Eigen::Index(k)).setConstant(w(free_nodes_[k]));
  if (has_plate_dofs())
    for (std::size_t a = 0; a < superior_nodes_.size(); ++a)
      L.plate.noalias() += w(superior_nodes_[a]) * plate_maps_[a].transpose() * plate_maps_[a];
  return L;
}

double ReducedSpace::force_norm(const Eigen::VectorXd& r) const {
  const Eigen::Index nf3 = plate_offset();
  double s = r.head(nf3).squaredNorm();
  if (has_plate_dofs())
    s += r.segment<3>(nf3).squaredNorm() +
         r.tail<3>().squaredNorm() / (moment_length_ * moment_length_);
  return std::sqrt(s);
}

}  // namespace spinesim::mss::detail

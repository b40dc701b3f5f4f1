// Reduced coordinates of the MSS disc under a Boundary (private to mss/).
//
// Unknowns y = (x_f, q): the positions of the free nodes (surface label neither 1 nor 2), in node
// order, 3 per node, then for PlateMode::wrench the six plate DOF q = (t mm, theta rad). The
// superior-endplate nodes are slaved by the FEM's small-rotation map
//     x_i = X_i + R_i q,   R_i = [I | -[X_i - c]x]   (x_i = X_i + t + theta x (X_i - c)),
// so x = x_D + P y with a constant P, and the reduced gradient and Hessian are exactly P^T g
// and P^T H P. In PlateMode::pose both endplates are Dirichlet and y = x_f.
//
// The reduced matrix is stored as its lower triangle (CHOLMOD/Eigen's `Lower`), with a pattern
// built once from the model's fixed Hessian pattern: column 3k+d of a free node holds its own
// lower diagonal block, its higher free neighbours and — in wrench mode, for nodes next to the
// plate — the six plate rows at the bottom; the last six columns hold the lower 6x6 plate block.
// reduce_matrix() refills values through precomputed slots: no search, no allocation.
#pragma once

#include "spinesim/mesh/rigid_plate.hpp"
#include "spinesim/mss/boundary.hpp"
#include "spinesim/mss/model.hpp"

#include <Eigen/Core>
#include <Eigen/SparseCore>

#include <vector>

namespace spinesim::mss::detail {

using Matrix36d = Eigen::Matrix<double, 3, 6>;

enum class NodeRole : signed char { free, inferior, superior };

/// R_i of the small-rotation plate map for the arm r = X_i - c: R q = t + theta x r.
using mesh::plate_map;

/// Mass-like reduced matrix P^T diag(w) P for per-node weights w (masses, or ones for the
/// ambient damping): a diagonal over the free DOF and a dense 6x6 plate block.
struct LumpedReduced {
  Eigen::VectorXd diagonal;           ///< size(); zero on the plate DOF
  Matrix6d plate = Matrix6d::Zero();  ///< zero in pose mode
  /// out = this * y (out preallocated, no aliasing with y).
  void apply(const Eigen::VectorXd& y, Eigen::VectorXd& out) const;
  double quadratic_form(const Eigen::VectorXd& y) const;  ///< y^T this y
};

class ReducedSpace {
 public:
  ReducedSpace() = default;
  /// `hessian_pattern`: any matrix with the model's full Hessian pattern (3#nodes square, both
  /// triangles, compressed, sorted).
  ReducedSpace(const MssModel& model, const Eigen::SparseMatrix<double>& hessian_pattern,
               PlateMode mode, const Eigen::Vector3d& plate_center_mm);

  PlateMode mode() const { return mode_; }
  const Eigen::Vector3d& center() const { return center_; }
  bool has_plate_dofs() const { return mode_ == PlateMode::wrench; }
  Eigen::Index size() const { return n_; }
  Eigen::Index plate_offset() const { return 3 * Eigen::Index(free_nodes_.size()); }
  NodeRole role(int node) const { return role_[std::size_t(node)]; }
  int free_index(int node) const { return free_index_[std::size_t(node)]; }
  const std::vector<int>& free_nodes() const { return free_nodes_; }
  const std::vector<int>& superior_nodes() const { return superior_nodes_; }
  const std::vector<int>& inferior_nodes() const { return inferior_nodes_; }
  /// True if the node's position is one of the unknowns (free, or plate node in wrench mode).
  bool is_unknown(int node) const {
    return role(node) == NodeRole::free || (role(node) == NodeRole::superior && has_plate_dofs());
  }

  /// x <- the prescribed positions: label-1 nodes at bc.inferior, and in pose mode label-2 nodes
  /// at bc.superior (x = R X + t).
  void set_dirichlet_positions(const Boundary& bc, Eigen::VectorXd& x) const;
  /// x <- positions of the unknown nodes from y (free: y; plate nodes: X + R q). Dirichlet
  /// nodes of x are not touched.
  void set_unknown_positions(const Eigen::VectorXd& y, Eigen::VectorXd& x) const;
  /// Same for a rate: v <- P dy on the unknown nodes (free: dy; plate: R qdot).
  void set_unknown_rates(const Eigen::VectorXd& dy, Eigen::VectorXd& v) const;
  /// y <- (free part of x, q).
  void gather(const Eigen::VectorXd& x, const Vector6d& q, Eigen::VectorXd& y) const;
  /// Least-squares plate DOF of the superior nodes of x: argmin_q sum |X_i + R_i q - x_i|^2.
  Vector6d fit_plate_motion(const Eigen::VectorXd& x) const;
  /// r <- P^T g (g: 3#nodes).
  void reduce_vector(const Eigen::VectorXd& g, Eigen::VectorXd& r) const;

  /// The reduced matrix pattern (lower triangle, zero values).
  const Eigen::SparseMatrix<double>& pattern() const { return pattern_; }
  /// A <- lower(P^T H P); A must have pattern() (copy it once).
  void reduce_matrix(const Eigen::SparseMatrix<double>& H, Eigen::SparseMatrix<double>& A) const;
  /// A += P_i^T h P_i for one node (nothing for a Dirichlet node).
  void add_node_block(int node, const Eigen::Matrix3d& h, Eigen::SparseMatrix<double>& A) const;
  /// A += scale * L for a lumped reduced matrix L.
  void add_lumped(const LumpedReduced& L, double scale, Eigen::SparseMatrix<double>& A) const;
  /// P^T diag(w) P for per-node weights w (#nodes).
  LumpedReduced lumped(const Eigen::VectorXd& node_weights) const;

  /// Scale for residual norms: plate moments (N·mm) are divided by this length (mm) so that
  /// every component of a reduced gradient reads in N.
  double moment_length_mm() const { return moment_length_; }
  /// |r| with the plate-moment components divided by moment_length_mm(), N.
  double force_norm(const Eigen::VectorXd& r) const;

 private:
  void classify_nodes(const mesh::TetMesh& m, int num_nodes);
  std::vector<int> build_pattern(const Eigen::SparseMatrix<double>& H);
  void build_scatter(const Eigen::SparseMatrix<double>& H, const std::vector<int>& outer);
  void add_plate_block(const Matrix6d& B, double* val) const;

  PlateMode mode_ = PlateMode::pose;
  Eigen::Vector3d center_ = Eigen::Vector3d::Zero();
  Eigen::Index n_ = 0;
  double moment_length_ = 1.0;
  Eigen::VectorXd X_;  ///< rest positions, 3#nodes
  std::vector<NodeRole> role_;
  std::vector<int> free_index_;  ///< node -> free node index, -1 if not free
  std::vector<int> free_nodes_, superior_nodes_, inferior_nodes_;
  std::vector<int> plate_index_;       ///< node -> index into superior_nodes_, -1 otherwise
  std::vector<Matrix36d> plate_maps_;  ///< R_i per superior node (wrench mode)

  Eigen::SparseMatrix<double> pattern_;
  std::vector<int> diag_slot_;  ///< value index of (k, k) for every reduced DOF k
  int plate_slot_[6][6] = {};   ///< value index of (3nf+p, 3nf+q), p >= q
  struct FreeFree {
    int src, dst;
  };
  struct FreePlate {
    int src, dst, plate, comp;
  };  ///< dst: first of 6 plate rows
  struct PlatePlate {
    int src, plate_row, comp_row, plate_col, comp_col;
  };
  std::vector<FreeFree> ff_;
  std::vector<FreePlate> fp_;
  std::vector<PlatePlate> pp_;
};

}  // namespace spinesim::mss::detail

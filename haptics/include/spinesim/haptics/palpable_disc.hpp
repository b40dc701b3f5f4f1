// What disc palpation (disc_palpation.hpp) asks of a disc, and the tuned mass-spring disc behind
// that interface. A probe sphere of a fixed radius presses the disc's surface nodes by a penalty
// (N/mm per node); each step places the sphere's centre and advances the disc: the mass-spring
// disc by one implicit step of its dynamics, a static disc (the linear FEM disc of the studies
// layer) to its equilibrium with the sphere there. The disc answers with its force on the sphere
// and that force's stiffness (the multirate local model), its node positions and its volume.
#pragma once

#include "spinesim/mesh/tet_mesh.hpp"
#include "spinesim/mss/boundary.hpp"
#include "spinesim/mss/model.hpp"
#include "spinesim/mss/simulator.hpp"

#include <Eigen/Core>

namespace spinesim::haptics {

class PalpableDisc {
 public:
  virtual ~PalpableDisc() = default;
  /// "mass-spring", "linear FEM": what the run reports.
  virtual const char* name() const = 0;
  virtual const mesh::TetMesh& mesh() const = 0;
  virtual const Eigen::VectorXd& rest_positions_mm() const = 0;  ///< 3 #nodes
  virtual const Eigen::VectorXd& positions_mm() const = 0;       ///< 3 #nodes, now
  virtual double probe_radius_mm() const = 0;
  virtual double probe_penalty_n_per_mm() const = 0;
  /// Advances the disc with the sphere's centre at `center_mm`. False: the step was rejected and
  /// the disc is held as it was.
  virtual bool step(const Eigen::Vector3d& center_mm) = 0;
  /// After a step: the disc's force on the sphere (N) and -dF/dc (N/mm, symmetric; its negative
  /// directions, a sphere sliding across the wall, are the caller's to drop).
  virtual Eigen::Vector3d probe_force_n() const = 0;
  virtual Eigen::Matrix3d probe_stiffness() const = 0;
  virtual double volume_change() const = 0;  ///< (V - V0) / V0
};

/// The tuned mass-spring disc with both endplates held by `plates`: frozen implicit Euler at
/// `dynamics.dt_s` (mss/simulator.hpp), its probe contacts resolved inside the step.
class MssPalpableDisc final : public PalpableDisc {
 public:
  /// `penalty` 0: mss::default_probe_stiffness. Throws std::invalid_argument if the implicit
  /// matrix is not positive definite (its factorisation is made here, not in the first step).
  MssPalpableDisc(const mss::MssModel& model, const mss::Boundary& plates, double radius_mm,
                  double penalty_n_per_mm, const mss::DynamicsOptions& dynamics);
  const char* name() const override { return "mass-spring"; }
  const mesh::TetMesh& mesh() const override { return model_.mesh(); }
  const Eigen::VectorXd& rest_positions_mm() const override { return model_.rest_positions_mm(); }
  const Eigen::VectorXd& positions_mm() const override { return state_.x_mm; }
  double probe_radius_mm() const override { return bc_.probes[0].radius_mm; }
  double probe_penalty_n_per_mm() const override { return bc_.probes[0].stiffness_n_per_mm; }
  bool step(const Eigen::Vector3d& center_mm) override;
  Eigen::Vector3d probe_force_n() const override { return force_; }
  Eigen::Matrix3d probe_stiffness() const override { return sim_.probe_stiffness(0); }
  double volume_change() const override;

 private:
  const mss::MssModel& model_;
  mss::Simulator sim_;
  mss::State state_;
  mss::Boundary bc_;
  Eigen::Vector3d force_ = Eigen::Vector3d::Zero();
};

}  // namespace spinesim::haptics

// Disc palpation: the probe presses into a tuned mass-spring disc simulated at 1 kHz.
//
// The disc runs in its own thread, not in the servo thread: its implicit step allocates (CHOLMOD's
// solves) and takes a few hundred microseconds, and the servo tick must stay allocation-free and
// short. The two meet through a virtual coupling (Colgate, Stanley & Brown 1995):
//
//   disc thread, every 1 ms:  read the device position x_d (latest the servo published);
//     place the simulated probe p_s (a massless sphere of radius r) where the coupling spring
//     k_c (x_d - p_s) balances the disc's contact force on it with the disc as it is,
//       p_s = argmin_p  k_c/2 |p - x_d|^2 + sum_i k_p/2 max(0, r - |p - x_i|)^2
//     (x_i the disc's surface nodes, k_p the MSS probe penalty; Gauss-Newton with backtracking);
//     step the disc (implicit Euler, frozen rest factorisation, both endplates held by their
//     vertebrae) with the spherical probe at p_s; publish p_s, the contact force and the disc's
//     volume change.
//   servo thread, every tick:  F = k_c (p_s - x_d) - b v_d while the disc reports contact,
//     plus the rigid stage's force from the two vertebrae.
//
// The hand feels the disc through a spring of stiffness k_c (<= the device's usable stiffness) in
// series with the disc, whatever the disc's own contact stiffness: the coupling bounds the felt
// stiffness, and the implicit disc step dissipates, so the loop stays passive (the servo's
// passivity observer measures it). Free of the disc, p_s = x_d and no force is rendered. The
// probe is moved towards its new place in steps of r/4 from where it was, so it cannot jump over
// the wall's nodes; and until the device has once been outside the disc (a start inside it), the
// probe is not put in at all.
#pragma once

#include "spinesim/haptics/renderer.hpp"
#include "spinesim/haptics/triple_buffer.hpp"
#include "spinesim/mss/model.hpp"
#include "spinesim/mss/simulator.hpp"
#include "spinesim/mss/solver.hpp"

#include <Eigen/Core>

#include <atomic>
#include <cstdint>
#include <memory>
#include <string>
#include <thread>
#include <vector>

namespace spinesim::haptics {

struct DiscPalpationOptions {
  double coupling_stiffness_n_per_mm = 0.5;  ///< k_c, within the device's usable stiffness
  double coupling_damping_n_s_per_mm = 0;    ///< b, on the device velocity while in contact
  double probe_radius_mm = 4;
  double probe_penalty_n_per_mm = 0;  ///< k_p per node; 0: mss::default_probe_stiffness
  double dt_s = 1e-3;
  int newton_iterations = 1;
  bool realtime_priority = true;  ///< SCHED_FIFO for the disc thread (below the servo's)
  int priority = 70;
};

/// What the disc thread publishes after each step.
struct DiscContact {
  std::int64_t step = 0;
  Eigen::Vector3d probe_mm = Eigen::Vector3d::Zero();  ///< the simulated probe p_s
  Eigen::Vector3d force_n = Eigen::Vector3d::Zero();   ///< the disc's force on the probe
  bool contact = false;
  double volume_change = 0;  ///< (V - V0) / V0
  double step_us = 0;        ///< this step's compute time
  bool failed = false;       ///< a step was rejected (the disc is held as it was)
};

/// The contact is node-based (the MSS's spherical probe pushes surface nodes): a probe smaller
/// than the gaps between surface nodes slips through the wall. This is the largest circumradius
/// of the outer wall's boundary triangles (mm; the endplates are covered by the vertebrae): the
/// probe radius must exceed it.
double surface_gap_mm(const mesh::TetMesh& mesh);

class DiscPalpation {
 public:
  /// `plates`: the endplates' poses (both held; the disc between its vertebrae). Throws
  /// std::invalid_argument for bad options or a probe radius within surface_gap_mm (one line).
  DiscPalpation(const mss::MssModel& model, const mss::Boundary& plates,
                const DiscPalpationOptions& options);
  ~DiscPalpation();
  DiscPalpation(const DiscPalpation&) = delete;
  DiscPalpation& operator=(const DiscPalpation&) = delete;

  /// One step for the device at `device_mm` on the calling thread (the thread's body; tests and
  /// the budget check call it directly). Returns what it publishes.
  const DiscContact& step(const Eigen::Vector3d& device_mm);

  /// The disc thread at 1/dt (absolute deadlines); stop() joins it.
  void start();
  void stop();

  /// Servo side: publish the device position / read the latest contact. No allocation, no wait.
  void set_device(const Eigen::Vector3d& device_mm) { device_.write(device_mm); }
  const DiscContact& latest() { return out_.read(); }
  /// Graphics side (one reader): the disc's node positions (3 #nodes, mm), published by the disc
  /// thread every `kPositionsEvery` steps (a copy of ~100 kB is not made every millisecond).
  /// No allocation, no wait.
  const Eigen::VectorXd& latest_positions() { return positions_.read(); }
  static constexpr int kPositionsEvery = 10;

  const mss::MssModel& model() const { return model_; }
  const mss::State& state() const { return state_; }
  double probe_penalty_n_per_mm() const { return k_p_; }
  const DiscPalpationOptions& options() const { return options_; }

  struct Stats {
    std::int64_t steps = 0, overruns = 0, failed_steps = 0;  ///< overrun: ended past its deadline
    std::vector<float> step_us;                              ///< every step (thread runs)
    double max_force_n = 0, min_volume_change = 0, max_volume_change = 0;
    bool realtime_priority = false;
    std::string realtime_reason;
  };
  /// After stop().
  const Stats& stats() const { return stats_; }

 private:
  void run();
  Eigen::Vector3d place_probe(const Eigen::Vector3d& device_mm) const;
  /// The probe at `point` overlaps a surface node, or `point` is inside a tetrahedron.
  bool touches_disc(const Eigen::Vector3d& point) const;

  const mss::MssModel& model_;
  DiscPalpationOptions options_;
  mss::Simulator sim_;
  mss::State state_;
  mss::Boundary bc_;
  double k_p_ = 0;
  std::vector<Eigen::Index> surface_nodes_;
  bool armed_ = false;  ///< the device has been outside the disc since the start
  DiscContact last_;
  TripleBuffer<Eigen::Vector3d> device_;
  TripleBuffer<DiscContact> out_;
  TripleBuffer<Eigen::VectorXd> positions_;  ///< every slot sized at construction
  std::atomic<bool> stop_{false};
  std::thread thread_;
  Stats stats_;
};

/// The servo's renderer for the disc scene: the rigid stage (the two vertebrae, by `rigid`) plus
/// the coupling force to the disc thread's probe. Allocation-free.
class DiscCouplingRenderer final : public ForceRenderer {
 public:
  DiscCouplingRenderer(ForceRenderer& rigid, DiscPalpation& disc);
  const char* name() const override { return "proxy + disc coupling"; }
  void reset(const Eigen::Vector3d& device_mm) override;
  RenderOutput render(const ProbeState& probe, const Scene& scene, const ScenePoses& poses,
                      double dt_s) override;
  /// The disc state the last render used.
  const DiscContact& disc() const { return disc_; }

 private:
  ForceRenderer& rigid_;
  DiscPalpation& palpation_;
  DiscContact disc_;
};

}  // namespace spinesim::haptics

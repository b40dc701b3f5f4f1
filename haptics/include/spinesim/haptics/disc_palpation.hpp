// Disc palpation: the probe presses into a disc simulated beside the servo — the tuned
// mass-spring disc, or any disc behind palpable_disc.hpp (the studies layer puts the linear FEM
// disc there). Below, "step the disc" is the mass-spring disc's implicit step; a static disc
// is solved to its equilibrium with the probe where the step places it.
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
//
// Force scale s (disc N per felt N): the disc meets a coupling spring s k_c while the hand
// feels k_c (p_s - x_d), the disc's force divided by s, so a device's few newtons stand for the
// hundreds of newtons a disc meets and the disc visibly deforms. The felt stiffness stays
// within k_c (k_c s K (s k_c + K)^-1 for a disc contact stiffness K).
//
// Multirate (options.multirate): a disc whose step does not fit a millisecond (the FEM
// resolution, >= 20,000 tets, takes ~5 ms here) is stepped every dt (up to 10 ms) on its thread,
// which after each step also publishes a local contact model that the servo evaluates every
// tick (Cavusoglu & Tendick's multirate local model; the contact compliance of Courtecuisse et
// al.): the disc's force on the probe near the step's probe position p0,
//     F(p) = F0 - K (p - p0),   K = mss::Simulator::probe_stiffness (the step's linearisation,
//                                   its negative tangential part, a sliding sphere, dropped)
// and the coupling's balance s k_c (x_d - p) + F(p) = 0 solved for p each tick in closed form,
// p = (s k_c I + K)^-1 (s k_c x_d + F0 + K p0). Out of contact the model is the plane of the
// nearest surface node (F0 = 0, K = k_n n n^T with the last contact's normal stiffness k_n), so
// a touch is felt within the tick, not a worker period later. Contact holds while F(p).n > 0; a
// model older than kStaleSteps worker periods renders no disc force.
#pragma once

#include "spinesim/haptics/palpable_disc.hpp"
#include "spinesim/haptics/renderer.hpp"
#include "spinesim/haptics/triple_buffer.hpp"
#include "spinesim/mss/model.hpp"
#include "spinesim/mss/simulator.hpp"
#include "spinesim/mss/solver.hpp"

#include <Eigen/Core>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdint>
#include <functional>
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
  double dt_s = 1e-3;  ///< the disc's step (multirate: its worker period, up to 10 ms)
  int newton_iterations = 1;
  double force_scale = 1;  ///< s: disc N per felt N (>= 1)
  bool multirate = false;  ///< the servo evaluates the worker's local contact model each tick
  bool realtime_priority = true;  ///< SCHED_FIFO for the disc thread (below the servo's)
  int priority = 70;
};

/// The tuned mass-spring disc of `model` held by `plates`, stepped as the options say (frozen
/// implicit Euler at dt_s). Throws std::invalid_argument (one line) for bad options.
std::unique_ptr<PalpableDisc> make_mss_palpable_disc(const mss::MssModel& model,
                                                     const mss::Boundary& plates,
                                                     const DiscPalpationOptions& options);

/// What the disc thread publishes after each step.
struct DiscContact {
  std::int64_t step = 0;
  Eigen::Vector3d probe_mm = Eigen::Vector3d::Zero();  ///< the simulated probe p_s
  Eigen::Vector3d force_n = Eigen::Vector3d::Zero();   ///< the disc's force on the probe
  bool contact = false;
  double volume_change = 0;   ///< (V - V0) / V0
  double step_us = 0;         ///< this step's compute time
  bool failed = false;        ///< a step was rejected (the disc is held as it was)
  double indentation_mm = 0;  ///< the touched wall nodes' largest displacement from rest
  Eigen::Vector3d device_mm = Eigen::Vector3d::Zero();  ///< the device position the step used
  /// The local contact model (multirate): p = inverse (s k_c x_d + offset); contact while
  /// s k_c (p - x_d).normal > 0. model = false: none (no force).
  bool model = false;
  Eigen::Matrix3d model_inverse = Eigen::Matrix3d::Zero();
  Eigen::Vector3d model_offset = Eigen::Vector3d::Zero();
  Eigen::Vector3d model_normal = Eigen::Vector3d::Zero();
};

/// The local model evaluated at the device position `device_mm` (multirate servo side): the
/// simulated probe (`probe_mm`), the disc's force on it (disc N) and whether it touches; free of
/// the disc the probe is the device. Allocation-free.
struct LocalContact {
  Eigen::Vector3d probe_mm, force_n;
  bool contact = false;
};
LocalContact evaluate_local_model(const DiscContact& c, double disc_coupling_n_per_mm,
                                  const Eigen::Vector3d& device_mm);

/// The contact is node-based (the MSS's spherical probe pushes surface nodes): a probe smaller
/// than the gaps between surface nodes slips through the wall. This is the largest circumradius
/// of the outer wall's boundary triangles (mm; the endplates are covered by the vertebrae): the
/// probe radius must exceed it.
double surface_gap_mm(const mesh::TetMesh& mesh);

class DiscPalpation {
 public:
  /// The tuned mass-spring disc. `plates`: the endplates' poses (both held; the disc between its
  /// vertebrae). Throws std::invalid_argument for bad options or a probe radius within
  /// surface_gap_mm (one line).
  DiscPalpation(const mss::MssModel& model, const mss::Boundary& plates,
                const DiscPalpationOptions& options);
  /// Any disc (palpable_disc.hpp) made with options.probe_radius_mm; the same refusals.
  DiscPalpation(std::unique_ptr<PalpableDisc> disc, const DiscPalpationOptions& options);
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
  /// thread every `positions_every()` steps (a copy of ~100 kB is not made every millisecond).
  /// No allocation, no wait.
  const Eigen::VectorXd& latest_positions() { return positions_.read(); }
  static constexpr int kPositionsEvery = 10;
  /// Steps between two publications: every 10 ms of the disc's time (every step of a multirate
  /// worker, whose step is 10 ms).
  int positions_every() const {
    return std::max(1, int(std::lround(kPositionsEvery * 1e-3 / options_.dt_s)));
  }

  const PalpableDisc& disc() const { return *disc_; }
  double probe_penalty_n_per_mm() const { return disc_->probe_penalty_n_per_mm(); }
  /// s k_c: the coupling the disc meets (disc N/mm).
  double disc_coupling_n_per_mm() const {
    return options_.force_scale * options_.coupling_stiffness_n_per_mm;
  }
  /// A local model older than this many worker steps renders no disc force.
  static constexpr int kStaleSteps = 10;
  const DiscPalpationOptions& options() const { return options_; }

  struct Stats {
    std::int64_t steps = 0, overruns = 0, failed_steps = 0;  ///< overrun: ended past its deadline
    /// Worker periods given up because the steps fell more than a period behind the clock.
    std::int64_t dropped_periods = 0;
    std::vector<float> step_us;                              ///< every step (thread runs)
    double max_force_n = 0, min_volume_change = 0, max_volume_change = 0;
    double max_indentation_mm = 0;
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
  /// The touched wall nodes' largest displacement from rest with the probe at `p` (mm).
  double indentation_mm(const Eigen::Vector3d& p) const;
  /// last_'s local contact model after a step for the device at `device_mm`.
  void update_local_model(const Eigen::Vector3d& device_mm);

  DiscPalpationOptions options_;
  std::unique_ptr<PalpableDisc> disc_;
  std::vector<Eigen::Index> surface_nodes_;
  bool armed_ = false;           ///< the device has been outside the disc since the start
  double normal_stiffness_ = 0;  ///< the last contact's n.K.n (the onset plane's), disc N/mm
  bool model_trusted_ = false;   ///< the last contact's model places the next step's probe
  DiscContact last_;
  TripleBuffer<Eigen::Vector3d> device_;
  TripleBuffer<DiscContact> out_;
  TripleBuffer<Eigen::VectorXd> positions_;  ///< every slot sized at construction
  std::atomic<bool> stop_{false};
  std::thread thread_;
  Stats stats_;
};

/// Palpation off the clock, for checks: the device at `device_mm[k]` at tick k (period
/// `tick_s`); returns the coupling force s k_c (p_s - x_d) on the disc's probe per tick (disc N,
/// zero out of contact). Direct (options.multirate false): the disc stepped every tick (dt_s
/// must equal tick_s), as the synchronous reference. Multirate: the disc stepped every
/// dt_s / tick_s ticks with the device where it is then, its local model evaluated every tick
/// from the next one on (the servo sees a step once it is done).
std::vector<Eigen::Vector3d> palpate_offline(const mss::MssModel& model,
                                             const mss::Boundary& plates,
                                             const DiscPalpationOptions& options,
                                             const std::vector<Eigen::Vector3d>& device_mm,
                                             double tick_s);
/// The same for any disc, made afresh by `make_disc`.
std::vector<Eigen::Vector3d> palpate_offline(
    const std::function<std::unique_ptr<PalpableDisc>()>& make_disc,
    const DiscPalpationOptions& options, const std::vector<Eigen::Vector3d>& device_mm,
    double tick_s);

/// Force error of a run against a reference, relative to the reference's peak |F|.
struct ForceError {
  double rms_n = 0, max_n = 0, peak_n = 0;
  double relative_rms() const { return peak_n > 0 ? rms_n / peak_n : 0; }
  double relative_max() const { return peak_n > 0 ? max_n / peak_n : 0; }
};
/// Over the common length of `run` and `reference`.
ForceError force_error(const std::vector<Eigen::Vector3d>& run,
                       const std::vector<Eigen::Vector3d>& reference);

/// The servo's renderer for the disc scene: the rigid stage (the two vertebrae, by `rigid`) plus
/// the coupling force to the disc thread's probe. Allocation-free.
class DiscCouplingRenderer final : public ForceRenderer {
 public:
  DiscCouplingRenderer(ForceRenderer& rigid, DiscPalpation& disc);
  /// Ticks that rendered no disc force because the local model was stale (multirate).
  std::int64_t stale_ticks() const { return stale_ticks_; }
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
  std::int64_t model_step_ = -1, ticks_on_model_ = 0, stale_ticks_ = 0;
};

}  // namespace spinesim::haptics

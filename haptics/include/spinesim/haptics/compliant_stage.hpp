// The compliant stage (thesis 4.5): with the stylus button pressed while the probe touches a
// vertebra, a virtual spring joins the probe to a hook point fixed in that vertebra; the spring's
// force (scaled up: a desktop device gives a few newtons, the spine is dragged with hundreds)
// loads the spine at the hook point, every vertebra moves, and the rigid stage's surfaces and the
// proxy move with them, so the user feels the spine give. Releasing the button ends it.
//
// How the vertebrae follow the hook force is a SpineResponse, evaluated in every servo tick:
//   - DatabaseResponse: the thesis's method — the displacement–force polynomials
//     (spine/database.hpp), the force taken at the vertebra's centre, oblique forces by
//     superposition of the axis fits;
//   - MultirateSpine (default): the full equilibrium solver (spine/equilibrium.hpp) runs
//     continuously in a worker thread with the latest hook force and point, and hands the servo
//     loop its solution d0 at force F0 and the sensitivity S = ∂d/∂F there (a "local model",
//     Çavuşoğlu & Tendick 2000); each tick predicts d = d0 + S (F − F0).
// Both give each vertebra's motion relative to the spine under gravity alone (the scene shows
// the vertebrae at the reference posture, so at zero hook force nothing moves).
//
// On a 6-DOF device the hook also holds the vertebra's orientation: a torsional spring joins the
// stylus's turn since the press to the vertebra's, its moment (scaled as the force) loads the
// spine, and the hand feels the reaction as a torque (needs a response that takes moments: the
// multirate spine; the database knows forces only).
//
// Units: mm, N, s. Frame: the spine's (x lateral, y superior, z anterior).
#pragma once

#include "spinesim/haptics/device.hpp"
#include "spinesim/haptics/renderer.hpp"
#include "spinesim/haptics/scene.hpp"
#include "spinesim/haptics/triple_buffer.hpp"
#include "spinesim/spine/database.hpp"
#include "spinesim/spine/equilibrium.hpp"
#include "spinesim/spine/rib_cage.hpp"

#include <Eigen/Core>

#include <array>
#include <atomic>
#include <cstdint>
#include <memory>
#include <string>
#include <thread>

namespace spinesim::haptics {

inline constexpr int kSpineVertebrae = 17;  ///< T1…L5

/// Per vertebra T1…L5: translation of its F.1 centre (mm) and rotation vector (deg, world axes)
/// — spine::SpineSolution::displacement's layout.
using SpineDisplacement = Eigen::Matrix<double, kSpineVertebrae, 6>;

/// The load the hook puts on the spine: a force (N, world) at a point fixed in a vertebra
/// (reference coordinates, mm) and a couple (N·mm, world). vertebra −1: no load. `twist`: the
/// hook holds the orientation too (the couple may be non-zero; the worker then differentiates
/// with respect to it).
struct HookLoad {
  int vertebra = -1;
  Eigen::Vector3d point_mm = Eigen::Vector3d::Zero();
  Eigen::Vector3d force_n = Eigen::Vector3d::Zero();
  Eigen::Vector3d moment_nmm = Eigen::Vector3d::Zero();
  bool twist = false;
};

/// The rigid motion that takes the spine from displacement `from` to displacement `to` (both
/// absolute, from the reference posture): per vertebra x ↦ R x + t with R = R_to R_fromᵀ,
/// written into poses.pose[body_of[i]]. No allocation.
void relative_poses(const std::vector<Eigen::Vector3d>& centres_mm, const SpineDisplacement& from,
                    const SpineDisplacement& to, const std::array<int, kSpineVertebrae>& body_of,
                    ScenePoses& poses);

class SpineResponse {
 public:
  virtual ~SpineResponse() = default;
  virtual const char* name() const = 0;
  /// Displacement of every vertebra relative to gravity alone under `load` (zero for no load).
  /// Called in the servo tick, several times (the stage solves for the force that is in
  /// equilibrium with its spring): no allocation, no lock, no wait.
  virtual void predict(const HookLoad& load, SpineDisplacement& relative) = 0;
  /// The tick's final load, once per tick (a worker solves for it).
  virtual void publish(const HookLoad&) {}
  /// The absolute displacement under gravity alone (what `relative` is relative to).
  virtual const SpineDisplacement& baseline() const = 0;
  /// Largest hook force (N) this answers for; the stage clamps the force to it.
  virtual double max_force_n() const = 0;
  /// Largest hook moment (N·mm) this answers for; 0: it knows no moments (the hook holds no
  /// orientation, and a 6-DOF hand feels no torque).
  virtual double max_moment_nmm() const { return 0; }
  /// Starts and stops a worker thread, if there is one.
  virtual void start() {}
  virtual void stop() {}
};

/// The thesis's displacement–force database. The hook point is not used (the database knows
/// forces at the vertebra centres); each force component is clamped to the largest force its
/// axis fit was solved for, so the polynomials are never extrapolated.
class DatabaseResponse final : public SpineResponse {
 public:
  explicit DatabaseResponse(const spine::DisplacementDatabase& db);
  const char* name() const override { return "database"; }
  void predict(const HookLoad& load, SpineDisplacement& relative) override;
  const SpineDisplacement& baseline() const override { return baseline_; }
  double max_force_n() const override { return db_.force_max_n(); }

 private:
  const spine::DisplacementDatabase& db_;
  SpineDisplacement baseline_;
};

/// The worker's latest linearisation: the solution at the load (F0, M0) and ∂d/∂(F, M) there.
struct LocalSpineModel {
  int vertebra = -1;  ///< −1: nothing solved yet
  Eigen::Vector3d point_mm = Eigen::Vector3d::Zero(), force_n = Eigen::Vector3d::Zero();
  Eigen::Vector3d moment_nmm = Eigen::Vector3d::Zero();
  SpineDisplacement relative = SpineDisplacement::Zero();  ///< at force_n, moment_nmm
  /// Columns 0–2: mm/N, deg/N; columns 3–5 (a twisting hook; else zero): mm/(N·mm), deg/(N·mm);
  /// rows 6 i + c.
  Eigen::Matrix<double, 6 * kSpineVertebrae, 6> sensitivity =
      Eigen::Matrix<double, 6 * kSpineVertebrae, 6>::Zero();
  std::int64_t solve = 0;  ///< sequence number
  double solved_at_s = 0;  ///< on the worker's clock
};

struct MultirateOptions {
  spine::SolveOptions solve;  ///< recruitment on by default, as the database was made
  double max_force_n = 600;   ///< the thesis's validated range (3.3.5)
  /// Forward-difference step of the sensitivity (spine::displacement_sensitivity), N.
  double sensitivity_step_n = 5;
  /// Forward-difference step of the sensitivity to the hook's moment (whole solves), N·mm.
  double sensitivity_step_nmm = 500;
  /// Largest hook moment (N·mm): 15 N·m, the largest pure moment of the in-vitro tests the
  /// spine is validated against is 10 N·m.
  double max_moment_nmm = 15000;
  /// With recruitment, the full sensitivity (three extra solves) every this many updates; in
  /// between, Broyden's secant update from consecutive solves keeps it current at one solve per
  /// update.
  int full_sensitivity_every = 8;
  /// A new local model of the same hook takes over from the previous one over this many ticks
  /// (the two predictions blended linearly), so that a worker update does not step the spine:
  /// without it T1 jumped by up to 0.6 mm in one tick when a new solve arrived (measured on the
  /// lateral drag). 0: switch at once.
  int handover_ticks = 20;
};

/// The worker: solve at the latest hook load, update the sensitivity, publish, repeat. It idles
/// while there is no hook. A new hook starts from one solve and the fixed-muscle derivative
/// (cheap, too compliant with recruitment), then the full sensitivity, then secant updates.
/// predict() uses the latest model when it was made for the same vertebra and hook point (blended
/// in from the previous one over MultirateOptions::handover_ticks); before the first one arrives
/// for a new hook it predicts no motion (the hook's force ramps up from zero over ~0.3 s).
class MultirateSpine final : public SpineResponse {
 public:
  /// Solves the gravity-only baseline here (throws spine::SolveError if it fails).
  MultirateSpine(const spine::SpineModel& model, const MultirateOptions& options);
  ~MultirateSpine() override;
  const char* name() const override { return "multirate"; }
  void predict(const HookLoad& load, SpineDisplacement& relative) override;
  void publish(const HookLoad& load) override;
  const SpineDisplacement& baseline() const override { return baseline_; }
  double max_force_n() const override { return options_.max_force_n; }
  double max_moment_nmm() const override { return options_.max_moment_nmm; }
  void start() override;
  void stop() override;

  struct Stats {
    std::int64_t solves = 0, failures = 0;
    double busy_s = 0;         ///< time spent solving and differentiating
    double mean_update_s = 0;  ///< per published model (solve + sensitivity)
    std::string last_error;
  };
  /// After stop().
  const Stats& stats() const { return stats_; }
  /// Servo side (the thread calling predict): sequence number of the local model in use.
  std::int64_t model_in_use() const { return current_.solve; }
  /// One update for `load` on the calling thread (the worker's body; tests call it directly):
  /// the solve, and the sensitivity — `previous` (same hook) updated by the secant, or new
  /// (`full`: through whole solves; otherwise at fixed muscle forces, with no moment columns —
  /// a rigid twist until the full one arrives). A twisting hook's moment columns come from
  /// forward differences of whole solves.
  LocalSpineModel solve(const HookLoad& load, const LocalSpineModel* previous = nullptr,
                        bool full = true) const;

 private:
  void run();

  const spine::SpineModel& model_;
  MultirateOptions options_;
  SpineDisplacement baseline_;
  TripleBuffer<HookLoad> request_;
  TripleBuffer<LocalSpineModel> model_out_;
  std::atomic<bool> stop_{false};
  std::thread worker_;
  Stats stats_;
  // The servo thread's side: the model in use, the one it is taking over from, ticks left.
  LocalSpineModel current_, previous_;
  int handover_left_ = 0;
};

struct CouplingParameters {
  double stiffness_n_per_mm = 0.2;  ///< felt spring, within the device's usable stiffness
  double damping_n_s_per_mm = 0;    ///< felt, on the probe's velocity relative to the hook
  double force_scale = 100;         ///< spine force per felt force (N/N), and moment per torque
  /// The torsional spring of a 6-DOF hook (felt, N·mm/rad; 0: the hook holds no orientation)
  /// and its damping on the stylus's angular velocity relative to the vertebra's.
  double rotational_stiffness_nmm_per_rad = 0;
  double rotational_damping_nmm_s_per_rad = 0;
  double ramp_s = 0.3;       ///< attach and release blend over this long
  unsigned button_mask = 1;  ///< the stylus button that hooks
};

/// The stage's state after a tick (for the status line and the recording).
struct HookState {
  bool attached = false;                                      ///< button held on a hooked vertebra
  double gain = 0;                                            ///< the attach/release blend, 0…1
  HookLoad load;                                              ///< on the spine
  Eigen::Vector3d hook_mm = Eigen::Vector3d::Zero();          ///< the hook point, world
  Eigen::Vector3d felt_force_n = Eigen::Vector3d::Zero();     ///< the spring's force on the hand
  Eigen::Vector3d felt_torque_nmm = Eigen::Vector3d::Zero();  ///< the torsional spring's
  /// The stylus's turn since the press minus the vertebra's (rotation vector, deg).
  Eigen::Vector3d twist_deg = Eigen::Vector3d::Zero();
  bool clamped = false;  ///< the spine force (or moment) was limited to the response's
};

/// Drives a SpineResponse from the device and the renderer, inside the servo tick.
class CompliantStage {
 public:
  /// `body_of[i]`: the scene body of vertebra i (T1…L5). Throws std::invalid_argument for
  /// a stiffness or scale ≤ 0, a negative damping or ramp.
  CompliantStage(SpineResponse& response, const std::vector<Eigen::Vector3d>& centres_mm,
                 const std::array<int, kSpineVertebrae>& body_of, const CouplingParameters& p);

  /// Before the render: hooks on a button press while the last render touched a vertebra (at
  /// the proxy's centre); finds the hook force F in equilibrium with the spring,
  /// F = s·k·(probe − hook(F)) with hook(F) from the response (Newton, finite-difference 3×3
  /// Jacobian: taking the hook from the previous tick instead is a fixed-point iteration with a
  /// gain of s·k times the spine's compliance, ~30 at T1, and diverges); predicts the poses for
  /// it into `poses` (bodies of T1…L5 and an attached rib cage's; others untouched). No
  /// allocation.
  void update(const DeviceState& device, const RenderOutput& last, double dt_s, ScenePoses& poses);
  /// From now on update() also poses the rib cage's bodies from the thoracic vertebrae's:
  /// `bodies[b]` is the scene body of cage rib b, the last one the sternum's. `cage` and
  /// `vertebrae` must outlive the stage. Throws std::invalid_argument for a wrong count or a
  /// body outside the scene's range.
  void attach_rib_cage(const spine::RibCage& cage, const std::vector<spine::Vertebra>& vertebrae,
                       const std::vector<int>& bodies);
  /// After the render: the force for the hand — the rendered contact force blended with the
  /// hook spring's by the attach gain.
  Eigen::Vector3d blend(const Eigen::Vector3d& contact_force_n) const;
  /// The torque for the hand (zero unless a 6-DOF hook holds a vertebra).
  const Eigen::Vector3d& torque() const { return state_.felt_torque_nmm; }
  /// Whether a hook holds the orientation (the coupling's rotational stiffness is > 0 and the
  /// response takes moments).
  bool twists() const { return twists_; }

  const HookState& state() const { return state_; }
  const SpineDisplacement& displacement() const { return relative_; }  ///< last prediction
  SpineResponse& response() { return response_; }
  const std::array<int, kSpineVertebrae>& bodies() const { return body_of_; }

 private:
  SpineResponse& response_;
  std::vector<Eigen::Vector3d> centres_;
  std::array<int, kSpineVertebrae> body_of_;
  CouplingParameters p_;
  HookState state_;
  SpineDisplacement relative_ = SpineDisplacement::Zero(), absolute_;
  using Vector6d = Eigen::Matrix<double, 6, 1>;
  /// The hook point in the world and the hooked vertebra's rotation from the baseline under the
  /// load (F, M) (predicts into relative_).
  Eigen::Vector3d hook_at(const Vector6d& load, Eigen::Matrix3d* rotation = nullptr);
  /// The load (F, M) in equilibrium with the springs: F = c (probe − hook), M = c_r φ.
  Vector6d equilibrium_load(const Eigen::Vector3d& probe_mm, const Eigen::Matrix3d& turn,
                            double spring_n_per_mm, double torsion_nmm_per_rad);
  /// The twist φ (rad): the stylus's turn since the press against the vertebra's.
  Eigen::Vector3d twist(const Eigen::Matrix3d& turn, const Eigen::Matrix3d& vertebra) const;
  unsigned last_buttons_ = 0;
  Eigen::Vector3d last_hook_mm_ = Eigen::Vector3d::Zero();
  bool twists_ = false;
  Eigen::Matrix3d grip_at_press_ = Eigen::Matrix3d::Identity();      ///< stylus, at the press
  Eigen::Matrix3d vertebra_at_press_ = Eigen::Matrix3d::Identity();  ///< from the baseline
  Eigen::Matrix3d last_vertebra_ = Eigen::Matrix3d::Identity();
  /// The rib cage, when attached: its poser, the scene bodies it poses and its buffers.
  std::unique_ptr<spine::RibCagePoser> ribs_;
  std::vector<int> rib_bodies_, thoracic_bodies_;
  std::vector<spine::Pose> thoracic_, rib_poses_;
};

}  // namespace spinesim::haptics

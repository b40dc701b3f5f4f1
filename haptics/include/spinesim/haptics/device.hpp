// The device layer: one interface for PHANToM-class devices — 3-DOF (position in, force out,
// stylus buttons) and 6-DOF (also the stylus's orientation in and a torque out) — with a
// capability record per model, and the devices that need no hardware:
// `sim` (a simulated hand holding a simulated device), `replay` (a recorded run) and `null`.
// Units: mm, mm/s, N, N·mm, rad, s; the device frame is the scene frame (x lateral, y up, z anterior).
#pragma once

#include "spinesim/haptics/triple_buffer.hpp"

#include <Eigen/Core>

#include <memory>
#include <string>
#include <vector>

namespace spinesim::haptics {

/// What a device model can do, with the source of each number.
struct DeviceCapabilities {
  std::string model;  ///< e.g. "touch"
  std::string description;
  Eigen::Vector3d workspace_mm = Eigen::Vector3d::Zero();  ///< width × height × depth
  double peak_force_n = 0;                                 ///< nominal maximum exertable force
  double continuous_force_n = 0;                           ///< sustainable (24 h) force
  double usable_stiffness_n_per_mm = 0;  ///< the stiffness the device renders stably
  /// The device's own viscous damping (what makes a sampled wall passive, Colgate & Brown
  /// 1995: b > K T / 2 + |B|). Not published: an assumption for each model.
  double physical_damping_n_s_per_mm = 0;
  std::string source;
  // Rotations (6-DOF devices). A device that senses the stylus's orientation but has no motors
  // on its wrist (omega.6) has torque_axes 0: it is held and turned, but no torque is felt.
  bool senses_orientation = false;
  int torque_axes = 0;               ///< 3: torque about every axis; 0: none
  double peak_torque_nmm = 0;        ///< the smallest axis's, so no axis is asked for more
  double continuous_torque_nmm = 0;  ///< likewise
  double usable_rotational_stiffness_nmm_per_rad = 0;  ///< an assumption, as the damping
  double rotational_damping_nmm_s_per_rad = 0;         ///< an assumption (not published)
  bool renders_torque() const { return torque_axes == 3 && peak_torque_nmm > 0; }
};

/// The models this program knows: "touch" (Geomagic Touch / PHANToM Omni), "premium-1.5"
/// (PHANToM Premium 1.5), "omega.3" (Force Dimension), and the 6-DOF "premium-1.5-6dof",
/// "sigma.7" (torque on three axes) and "omega.6" (orientation sensed, no torque). Throws std::invalid_argument for an
/// unknown name, listing the known ones.
const std::vector<DeviceCapabilities>& device_models();
const DeviceCapabilities& device_model(const std::string& name);

/// The largest wall stiffness that keeps a device passive at servo period T with virtual
/// damping B (Colgate & Brown 1995): K < 2 (b − |B|) / T, b the device's physical damping.
double passive_stiffness_limit(const DeviceCapabilities& c, double period_s,
                               double virtual_damping_n_s_per_mm = 0);
/// The same bound for a torsional spring on a device with torque motors: 2 b_r / T (N·mm/rad).
double passive_rotational_stiffness_limit(const DeviceCapabilities& c, double period_s);

struct DeviceState {
  Eigen::Vector3d position_mm = Eigen::Vector3d::Zero();
  Eigen::Vector3d velocity_mm_s = Eigen::Vector3d::Zero();
  /// The stylus's orientation (stylus frame → scene frame; identity on a 3-DOF device) and its
  /// angular velocity (rad/s, scene axes).
  Eigen::Matrix3d orientation = Eigen::Matrix3d::Identity();
  Eigen::Vector3d angular_velocity_rad_s = Eigen::Vector3d::Zero();
  unsigned buttons = 0;  ///< bit 0: the stylus's first button
};

class Device {
 public:
  virtual ~Device() = default;
  virtual std::string name() const = 0;
  virtual const DeviceCapabilities& capabilities() const = 0;
  /// Opens the device; throws std::runtime_error with one line (the vendor's error text where
  /// there is one) when it cannot.
  virtual void open() = 0;
  /// Zeroes the force and releases the device. Safe to call twice.
  virtual void close() = 0;
  /// Reads the state at the start of a servo tick; false on a device error (then the loop
  /// zeroes the force and stops). Called from the servo thread only; must not allocate.
  virtual bool read(DeviceState& state) = 0;
  /// Commands a force for the rest of the tick; false on a device error. Must not allocate.
  virtual bool write_force(const Eigen::Vector3d& force_n) = 0;
  /// Commands a force and a torque (N·mm, scene axes). A device without torque motors drops the
  /// torque (the servo loop's safety chain has already zeroed it for such a device).
  virtual bool write_wrench(const Eigen::Vector3d& force_n, const Eigen::Vector3d& torque_nmm) {
    (void)torque_nmm;
    return write_force(force_n);
  }
  /// True once a scripted or replayed device has nothing more to play.
  virtual bool finished() const { return false; }
  /// The last error's text (empty if none).
  virtual std::string last_error() const { return {}; }
};

/// A set-point trajectory: times (s, strictly increasing from 0 or later), positions (mm),
/// buttons, and for a 6-DOF hand the stylus's orientation. Read from CSV
/// `t_s,x_mm,y_mm,z_mm[,button[,…]]` with '#' comment lines and an optional header row; when the
/// header names columns `rx_deg,ry_deg,rz_deg` (the stylus's rotation vector, degrees, scene
/// axes) they are read too; other columns after the fifth are ignored (a `--record` file
/// replays, orientation included).
struct Trajectory {
  std::vector<double> t_s;
  std::vector<Eigen::Vector3d> position_mm;
  std::vector<unsigned> buttons;
  std::vector<Eigen::Vector3d> rotation_deg;  ///< empty: no orientation (identity)
  double duration_s() const { return t_s.empty() ? 0 : t_s.back(); }
  /// Linear interpolation (held constant past the ends); no allocation.
  Eigen::Vector3d position_at(double t) const;
  Eigen::Vector3d velocity_at(double t) const;
  unsigned buttons_at(double t) const;
  /// The orientation at t: spherical linear interpolation between the rows (identity without
  /// orientation columns), and the angular velocity of that interpolation (rad/s).
  Eigen::Matrix3d orientation_at(double t) const;
  Eigen::Vector3d angular_velocity_at(double t) const;
  bool has_orientation() const { return !rotation_deg.empty(); }
};
/// Throws std::invalid_argument with one line "PATH:LINE: problem" for a missing file, a bad
/// number, NaN/inf, times not strictly increasing, a rotation of more than half a turn, or an
/// empty trajectory.
Trajectory read_trajectory(const std::string& path);

/// A human hand (an assumption, see haptics/README.md): mass, grip stiffness and damping pulling
/// the stylus towards the scripted set-point.
struct HandModel {
  double mass_kg = 0.15;
  double stiffness_n_per_mm = 0.4;
  double damping_n_s_per_mm = 0.004;
  /// The most the hand pushes or pulls with (N; 0: no limit). A person holding a desktop device
  /// pushes with a few newtons, not with whatever a far set-point would ask of the grip spring.
  double max_force_n = 0;
  // The wrist, for 6-DOF devices (assumptions, see haptics/README.md): the hand and stylus's
  // moment of inertia about the grip, and the grip's rotational stiffness and damping towards
  // the scripted orientation.
  double inertia_kg_mm2 = 300;
  double rotational_stiffness_nmm_per_rad = 2000;
  double rotational_damping_nmm_s_per_rad = 20;
};

/// `sim`: the device is a point mass held by the hand model and driven by the commanded force
/// (held for the whole servo period, as a real device's DAC holds it), integrated with
/// semi-implicit Euler at 10 sub-steps per period, with the device's physical damping. Each
/// read() advances the simulation by one servo period, so the closed loop is deterministic. Past
/// the script's end the hand holds its last set-point (the loop's duration ends the run). When
/// the device senses orientation, the stylus is also a rigid body turned by the wrist towards the
/// script's orientation and, if the device has torque motors, by the commanded torque.
std::unique_ptr<Device> make_sim_device(const Trajectory& script, const DeviceCapabilities& caps,
                                        double period_s, const HandModel& hand = HandModel());
/// What a pointing device (the viewer's mouse and keyboard) gives the `mouse` device, written by
/// the GUI thread: where the cursor and the wheel put the hand's set-point in the scene (mm), the
/// buttons (bit 0: the stylus button), and whether the window has been closed.
struct PointerInput {
  Eigen::Vector3d set_point_mm = Eigen::Vector3d::Zero();
  unsigned buttons = 0;
  bool active = false;  ///< false: no set-point given yet (the device holds its own)
  bool quit = false;
};

/// `mouse`: the mouse as a 3-DOF device. A simulated hand holds a simulated stylus (as `sim`)
/// and pulls it towards a set-point that follows the pointer's at no more than `max_speed_mm_s`
/// (a jump of the cursor becomes a glide, never a blow), starting at `start_mm`, with at most the
/// device's continuous force when the hand model sets no limit of its own (so a cursor behind a
/// wall does not push the probe through it: a person would not either); the rendered
/// force acts on the stylus, so the probe stops at surfaces and the hook drags the spine as with
/// a real device, and the viewer shows the force that would be felt. Reads `input` every tick
/// (no allocation, no wait); finished once `input` says quit.
std::unique_ptr<Device> make_mouse_device(TripleBuffer<PointerInput>& input,
                                          const Eigen::Vector3d& start_mm,
                                          const DeviceCapabilities& caps, double period_s,
                                          double max_speed_mm_s = 250,
                                          const HandModel& hand = HandModel());

/// `replay`: plays the recorded positions and buttons tick by tick; forces are discarded.
std::unique_ptr<Device> make_replay_device(const Trajectory& recording,
                                           const DeviceCapabilities& caps, double period_s);
/// `null`: stays at `position_mm`, discards forces; finished after `duration_s` (0: never).
std::unique_ptr<Device> make_null_device(const Eigen::Vector3d& position_mm,
                                         const DeviceCapabilities& caps, double period_s,
                                         double duration_s);

}  // namespace spinesim::haptics

namespace spinesim::haptics {

// --- Vendor backends, loaded at run time (dlopen), so they build and are tested everywhere ----
//
// Device frame of both backends: x to the user's right, y up, z towards the user (OpenHaptics's
// convention; DHD's x towards the user, y right, z up is turned into it), mm, mm/s, N.

/// What a backend found on this machine (for `spinesim haptics devices`).
struct BackendProbe {
  std::string name;     ///< "openhaptics" or "dhd"
  std::string library;  ///< the shared library asked for
  bool loaded = false;  ///< the library and every function we use were found
  int devices = -1;     ///< devices found (−1: the SDK cannot count without opening one)
  std::string detail;   ///< why not, or the vendor's system name
};

/// OpenHaptics HD (3D Systems Touch, PHANToM Premium …): `library` (default "libHD.so") is
/// loaded with dlopen; the device is opened with hdInitDevice(HD_DEFAULT_DEVICE) and served by
/// the HD scheduler, whose callback exchanges the state and the force with the servo loop
/// through triple buffers. Function signatures and constants are those of OpenHaptics's
/// published headers hd.h and hdDefines.h (HD_CURRENT_POSITION 0x2050, HD_CURRENT_VELOCITY
/// 0x2051, HD_CURRENT_BUTTONS 0x2000, HD_CURRENT_FORCE 0x2700, HD_FORCE_OUTPUT 0x4000,
/// HD_INVALID_HANDLE 0xFFFFFFFF). open() throws std::runtime_error with one line — the library
/// or a function missing, or the vendor's error text from hdGetErrorString.
std::unique_ptr<Device> make_openhaptics_device(const DeviceCapabilities& caps,
                                                const std::string& library = "");
/// Force Dimension DHD (omega.3 …): `library` (default "libdhd.so") loaded with dlopen; the
/// SDK's calls (dhdOpen, dhdGetPosition [m], dhdGetLinearVelocity [m/s], dhdGetButtonMask,
/// dhdSetForce [N], dhdEnableForce, dhdClose, dhdErrorGetLastStr, dhdGetDeviceCount, as
/// declared in dhdc.h) are made from the servo thread. Errors as above.
std::unique_ptr<Device> make_dhd_device(const DeviceCapabilities& caps,
                                        const std::string& library = "");
BackendProbe probe_openhaptics(const std::string& library = "");
BackendProbe probe_dhd(const std::string& library = "");

/// A device seen through a rigid map into the scene: position_scene = center + R position,
/// force_device = Rᵀ force_scene (R a rotation, e.g. a view from behind the patient).
std::unique_ptr<Device> map_device(std::unique_ptr<Device> device, const Eigen::Matrix3d& R,
                                   const Eigen::Vector3d& center_mm);

}  // namespace spinesim::haptics

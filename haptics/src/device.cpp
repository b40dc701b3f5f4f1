#include "spinesim/haptics/device.hpp"

#include "spinesim/common/constants.hpp"
#include "spinesim/common/input_file.hpp"
#include "spinesim/common/rotation.hpp"

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <stdexcept>

namespace spinesim::haptics {

namespace {

DeviceCapabilities six_dof(DeviceCapabilities c, int torque_axes, double peak_torque_nmm,
                           double continuous_torque_nmm, double usable_nmm_per_rad,
                           double damping_nmm_s_per_rad) {
  c.senses_orientation = true;
  c.torque_axes = torque_axes;
  c.peak_torque_nmm = peak_torque_nmm;
  c.continuous_torque_nmm = continuous_torque_nmm;
  c.usable_rotational_stiffness_nmm_per_rad = usable_nmm_per_rad;
  c.rotational_damping_nmm_s_per_rad = damping_nmm_s_per_rad;
  return c;
}

}  // namespace

const std::vector<DeviceCapabilities>& device_models() {
  // Sources: the vendors' specification sheets as quoted (not re-measured here). The physical
  // damping of every model is an assumption (no vendor publishes it); it only enters the
  // simulated device and the default-stiffness rule.
  static const std::vector<DeviceCapabilities> models = {
      {"touch", "Geomagic/3D Systems Touch (formerly Sensable PHANToM Omni)",
       Eigen::Vector3d(160, 120, 70), 3.3, 0.88, 0.5, 0.002,
       "3D Systems Touch specification sheet: workspace 160 W x 120 H x 70 D mm, maximum force "
       "3.3 N, continuous 0.88 N, stiffness 1.02-2.31 N/mm per axis; 0.5 N/mm is the usable "
       "stiffness the project specification takes; damping 0.002 N s/mm is an assumption"},
      {"premium-1.5", "3D Systems PHANToM Premium 1.5", Eigen::Vector3d(381, 267, 191), 8.5, 1.4,
       3.5, 0.004,
       "3D Systems PHANToM Premium 1.5 specification sheet: workspace 381 x 267 x 191 mm, "
       "maximum force 8.5 N, continuous 1.4 N, stiffness 3.5 N/mm; damping 0.004 N s/mm is an "
       "assumption"},
      {"omega.3", "Force Dimension omega.3", Eigen::Vector3d(160, 110, 160), 12.0, 12.0, 14.5, 0.02,
       "Force Dimension omega.3 specification sheet: workspace 160 mm diameter x 110 mm, "
       "continuous force 12.0 N, closed-loop stiffness 14.5 N/mm; damping 0.02 N s/mm is an "
       "assumption"},
      six_dof({"premium-1.5-6dof", "3D Systems PHANToM Premium 1.5 6DOF",
               Eigen::Vector3d(381, 267, 191), 8.5, 1.4, 3.5, 0.004,
               "3D Systems PHANToM Premium 1.5/6DOF specification sheet: workspace 381 x 267 x "
               "191 mm, maximum force 8.5 N, continuous 1.4 N; torque peak 515 mNm (Rx, Ry) and "
               "170 mNm (Rz), continuous 188 mNm (Rx, Ry) and 48 mNm (Rz); the smaller axis is "
               "taken for all three; rotational damping 0.2 N mm s/rad and usable rotational "
               "stiffness 200 N mm/rad are assumptions"},
              3, 170, 48, 200, 0.2),
      six_dof({"sigma.7", "Force Dimension sigma.7", Eigen::Vector3d(190, 130, 190), 20.0, 20.0,
               14.5, 0.02,
               "Force Dimension sigma.7 specification sheet: workspace 190 mm diameter x 130 mm, "
               "continuous force 20 N, continuous torque 400 mNm (also taken as the peak), "
               "translational stiffness taken as the omega's 14.5 N/mm; damping 0.02 N s/mm, "
               "rotational damping 0.5 N mm s/rad and usable rotational stiffness 300 N mm/rad "
               "are assumptions"},
              3, 400, 400, 300, 0.5),
      six_dof({"omega.6", "Force Dimension omega.6", Eigen::Vector3d(160, 110, 160), 12.0, 12.0,
               14.5, 0.02,
               "Force Dimension omega.6 specification sheet: the omega.3's translation and forces, "
               "with a wrist whose three rotations are sensed but not actuated (no torque); "
               "damping 0.02 N s/mm is an assumption"},
              0, 0, 0, 0, 0)};
  return models;
}

const DeviceCapabilities& device_model(const std::string& name) {
  std::string known;
  for (const auto& m : device_models()) {
    if (m.model == name) return m;
    known += (known.empty() ? "" : ", ") + m.model;
  }
  throw std::invalid_argument("unknown device model '" + name + "' (known: " + known + ")");
}

double passive_stiffness_limit(const DeviceCapabilities& c, double period_s,
                               double virtual_damping) {
  return std::max(0.0,
                  2.0 * (c.physical_damping_n_s_per_mm - std::abs(virtual_damping)) / period_s);
}

double passive_rotational_stiffness_limit(const DeviceCapabilities& c, double period_s) {
  return c.renders_torque() ? 2.0 * c.rotational_damping_nmm_s_per_rad / period_s : 0.0;
}

// ---------------------------------------------------------------------------------------------
// Trajectories

namespace {

std::size_t segment(const std::vector<double>& t, double at) {
  // Index i with t[i] <= at < t[i+1] (clamped); binary search, no allocation.
  const auto it = std::upper_bound(t.begin(), t.end(), at);
  if (it == t.begin()) return 0;
  return std::min(std::size_t(it - t.begin()) - 1, t.size() - 1);
}

}  // namespace

Eigen::Vector3d Trajectory::position_at(double t) const {
  if (t_s.empty()) return Eigen::Vector3d::Zero();
  if (t <= t_s.front()) return position_mm.front();
  if (t >= t_s.back()) return position_mm.back();
  const std::size_t i = segment(t_s, t);
  const double f = (t - t_s[i]) / (t_s[i + 1] - t_s[i]);
  return position_mm[i] + f * (position_mm[i + 1] - position_mm[i]);
}

Eigen::Vector3d Trajectory::velocity_at(double t) const {
  if (t_s.size() < 2 || t < t_s.front() || t >= t_s.back()) return Eigen::Vector3d::Zero();
  const std::size_t i = segment(t_s, t);
  return (position_mm[i + 1] - position_mm[i]) / (t_s[i + 1] - t_s[i]);
}

namespace {

Eigen::Quaterniond quaternion_of(const Eigen::Vector3d& rotation_deg) {
  return Eigen::Quaterniond(rotation_exp(rotation_deg * kRadPerDeg));
}

}  // namespace

Eigen::Matrix3d Trajectory::orientation_at(double t) const {
  if (rotation_deg.empty()) return Eigen::Matrix3d::Identity();
  if (t <= t_s.front()) return quaternion_of(rotation_deg.front()).toRotationMatrix();
  if (t >= t_s.back()) return quaternion_of(rotation_deg.back()).toRotationMatrix();
  const std::size_t i = segment(t_s, t);
  const double f = (t - t_s[i]) / (t_s[i + 1] - t_s[i]);
  return quaternion_of(rotation_deg[i])
      .slerp(f, quaternion_of(rotation_deg[i + 1]))
      .toRotationMatrix();
}

Eigen::Vector3d Trajectory::angular_velocity_at(double t) const {
  if (rotation_deg.empty() || t_s.size() < 2 || t < t_s.front() || t >= t_s.back())
    return Eigen::Vector3d::Zero();
  const std::size_t i = segment(t_s, t);
  const Eigen::Matrix3d R0 = quaternion_of(rotation_deg[i]).toRotationMatrix();
  const Eigen::Matrix3d R1 = quaternion_of(rotation_deg[i + 1]).toRotationMatrix();
  return rotation_log_total(R1 * R0.transpose()) / (t_s[i + 1] - t_s[i]);
}

unsigned Trajectory::buttons_at(double t) const {
  if (t_s.empty()) return 0;
  return buttons[segment(t_s, t)];
}

namespace {

double finite_cell(const std::string& cell, const std::string& where) {
  char* end = nullptr;
  const double v = std::strtod(cell.c_str(), &end);
  while (end && (*end == ' ' || *end == '\r' || *end == '\t')) ++end;
  if (end == cell.c_str() || (end && *end != '\0') || !std::isfinite(v))
    throw std::invalid_argument(where + ": '" + cell + "' is not a finite number");
  return v;
}

}  // namespace

Trajectory read_trajectory(const std::string& path) {
  // Only a regular file is read (a FIFO or device is refused by name), at most 1 GiB.
  std::istringstream in(read_regular_file(path, "the trajectory"));
  Trajectory tr;
  std::string line;
  int line_no = 0;
  int rotation_column = -1;  // the column of rx_deg (ry_deg, rz_deg follow), from the header
  while (std::getline(in, line)) {
    ++line_no;
    const auto first = line.find_first_not_of(" \t\r");
    if (first == std::string::npos || line[first] == '#') continue;
    if (line.size() > 4096)
      throw std::invalid_argument(path + ":" + std::to_string(line_no) + ": line too long");
    std::vector<std::string> cells;
    std::stringstream ss(line);
    std::string cell;
    while (std::getline(ss, cell, ',')) cells.push_back(cell);
    const std::string where = path + ":" + std::to_string(line_no);
    if (tr.t_s.empty() && !cells.empty() && cells[0].find("t_s") != std::string::npos) {
      for (std::size_t k = 0; k + 2 < cells.size(); ++k)
        if (cells[k] == "rx_deg" && cells[k + 1] == "ry_deg" && cells[k + 2] == "rz_deg")
          rotation_column = int(k);
      continue;
    }
    if (cells.size() < 4)
      throw std::invalid_argument(where + ": expected t_s,x_mm,y_mm,z_mm[,button,...], got " +
                                  std::to_string(cells.size()) + " cells");
    double v[5] = {0, 0, 0, 0, 0};
    for (std::size_t k = 0; k < std::min<std::size_t>(cells.size(), 5); ++k)
      v[k] = finite_cell(cells[k], where);
    if (v[0] < 0) throw std::invalid_argument(where + ": negative time");
    if (!tr.t_s.empty() && !(v[0] > tr.t_s.back()))
      throw std::invalid_argument(where + ": time " + cells[0] +
                                  " s is not after the previous row's");
    if (std::abs(v[1]) > 1e5 || std::abs(v[2]) > 1e5 || std::abs(v[3]) > 1e5)
      throw std::invalid_argument(where + ": a position beyond 100 m");
    if (v[4] != 0 && v[4] != 1) throw std::invalid_argument(where + ": button must be 0 or 1");
    tr.t_s.push_back(v[0]);
    tr.position_mm.emplace_back(v[1], v[2], v[3]);
    tr.buttons.push_back(unsigned(v[4]));
    if (rotation_column >= 0) {
      if (int(cells.size()) < rotation_column + 3)
        throw std::invalid_argument(where +
                                    ": the header names rx_deg,ry_deg,rz_deg but the row "
                                    "has only " +
                                    std::to_string(cells.size()) + " cells");
      Eigen::Vector3d r;
      for (int k = 0; k < 3; ++k)
        r[k] = finite_cell(cells[std::size_t(rotation_column + k)], where);
      if (r.norm() > 180)
        throw std::invalid_argument(where + ": a rotation of more than 180 degrees");
      tr.rotation_deg.push_back(r);
    }
    if (tr.t_s.size() > 50000000) throw std::invalid_argument(path + ": more than 50 million rows");
  }
  if (tr.t_s.empty()) throw std::invalid_argument(path + ": no trajectory rows");
  return tr;
}

// ---------------------------------------------------------------------------------------------
// Devices without hardware

namespace {

/// The hand and the device over one servo period with the force held (zero-order hold): a
/// point mass pulled by the hand's spring and damper towards `set_point(t)` (t from the period's
/// start) with the device's physical damping, semi-implicit Euler in 10 sub-steps.
template <class SetPoint, class SetVelocity>
void hold_for_one_period(const HandModel& hand, const DeviceCapabilities& caps, double period,
                         const Eigen::Vector3d& force, Eigen::Vector3d& x, Eigen::Vector3d& v,
                         const SetPoint& set_point, const SetVelocity& set_velocity) {
  const int substeps = 10;
  const double h = period / substeps, m = hand.mass_kg * 1e-3;  // tonnes (mm-N-t-s)
  for (int k = 0; k < substeps; ++k) {
    const double t = k * h;
    Eigen::Vector3d grip = hand.stiffness_n_per_mm * (set_point(t) - x) +
                           hand.damping_n_s_per_mm * (set_velocity(t) - v);
    if (hand.max_force_n > 0 && grip.norm() > hand.max_force_n)
      grip *= hand.max_force_n / grip.norm();
    const Eigen::Vector3d a = (grip - caps.physical_damping_n_s_per_mm * v + force) / m;
    v += h * a;
    x += h * v;
  }
}

/// The stylus's orientation over one servo period with the torque held: a rigid body of the
/// hand's inertia (isotropic) turned by the wrist's rotational spring and damper towards
/// `set_orientation(t)`, the device's rotational damping and `torque` (N·mm, scene axes);
/// semi-implicit Euler in 10 sub-steps, the orientation advanced by the exponential map.
template <class SetOrientation, class SetAngularVelocity>
void turn_for_one_period(const HandModel& hand, const DeviceCapabilities& caps, double period,
                         const Eigen::Vector3d& torque, Eigen::Matrix3d& R, Eigen::Vector3d& w,
                         const SetOrientation& set_orientation,
                         const SetAngularVelocity& set_angular_velocity) {
  const int substeps = 10;
  const double h = period / substeps, inertia = hand.inertia_kg_mm2 * 1e-3;  // t·mm²
  for (int k = 0; k < substeps; ++k) {
    const double t = k * h;
    const Eigen::Vector3d grip =
        hand.rotational_stiffness_nmm_per_rad *
            rotation_log_total(set_orientation(t) * R.transpose()) +
        hand.rotational_damping_nmm_s_per_rad * (set_angular_velocity(t) - w);
    w += h * (grip - caps.rotational_damping_nmm_s_per_rad * w + torque) / inertia;
    R = rotation_exp(h * w) * R;
  }
  // Keep R a rotation to round-off (the products drift over millions of ticks).
  const Eigen::Quaterniond q(R);
  R = q.normalized().toRotationMatrix();
}

void check_hand(const char* who, double period_s, const HandModel& hand) {
  if (!(period_s > 0)) throw std::invalid_argument(std::string(who) + ": period must be > 0");
  if (!(hand.mass_kg > 0) || !(hand.stiffness_n_per_mm > 0) || !(hand.damping_n_s_per_mm >= 0) ||
      !(hand.max_force_n >= 0) || !(hand.inertia_kg_mm2 > 0) ||
      !(hand.rotational_stiffness_nmm_per_rad > 0) || !(hand.rotational_damping_nmm_s_per_rad >= 0))
    throw std::invalid_argument(std::string(who) +
                                ": hand mass, inertia and stiffnesses must be > 0");
}

class SimDevice final : public Device {
 public:
  SimDevice(const Trajectory& script, const DeviceCapabilities& caps, double period_s,
            const HandModel& hand)
      : script_(script), caps_(caps), period_(period_s), hand_(hand) {
    check_hand("sim device", period_s, hand);
  }
  std::string name() const override { return "sim"; }
  const DeviceCapabilities& capabilities() const override { return caps_; }
  void open() override {
    time_ = script_.t_s.empty() ? 0 : script_.t_s.front();
    x_ = script_.position_at(time_);
    v_.setZero();
    force_.setZero();
    R_ = script_.orientation_at(time_);
    w_.setZero();
    torque_.setZero();
  }
  void close() override {
    force_.setZero();
    torque_.setZero();
  }
  bool read(DeviceState& s) override {
    hold_for_one_period(
        hand_, caps_, period_, force_, x_, v_,
        [&](double since) { return script_.position_at(time_ + since); },
        [&](double since) { return script_.velocity_at(time_ + since); });
    if (caps_.senses_orientation)
      turn_for_one_period(
          hand_, caps_, period_, torque_, R_, w_,
          [&](double since) { return script_.orientation_at(time_ + since); },
          [&](double since) { return script_.angular_velocity_at(time_ + since); });
    time_ += period_;
    s.position_mm = x_;
    s.velocity_mm_s = v_;
    s.orientation = R_;
    s.angular_velocity_rad_s = w_;
    s.buttons = script_.buttons_at(time_);
    return true;
  }
  bool write_force(const Eigen::Vector3d& f) override {
    force_ = f;
    torque_.setZero();  // a force-only command holds no torque
    return true;
  }
  bool write_wrench(const Eigen::Vector3d& f, const Eigen::Vector3d& torque) override {
    force_ = f;
    torque_ = caps_.renders_torque() ? torque : Eigen::Vector3d::Zero();
    return true;
  }
  // The hand holds the script's last set-point for as long as the loop runs.
  bool finished() const override { return false; }

 private:
  Trajectory script_;
  DeviceCapabilities caps_;
  double period_;
  HandModel hand_;
  double time_ = 0;
  Eigen::Vector3d x_ = Eigen::Vector3d::Zero(), v_ = Eigen::Vector3d::Zero(),
                  force_ = Eigen::Vector3d::Zero();
  Eigen::Matrix3d R_ = Eigen::Matrix3d::Identity();
  Eigen::Vector3d w_ = Eigen::Vector3d::Zero(), torque_ = Eigen::Vector3d::Zero();
};

class MouseDevice final : public Device {
 public:
  MouseDevice(TripleBuffer<PointerInput>& input, const Eigen::Vector3d& start,
              const DeviceCapabilities& caps, double period_s, double max_speed,
              const HandModel& hand)
      : input_(input),
        start_(start),
        caps_(caps),
        period_(period_s),
        speed_(max_speed),
        hand_(hand) {
    check_hand("mouse device", period_s, hand);
    if (hand_.max_force_n == 0) hand_.max_force_n = caps.continuous_force_n;
    if (!(max_speed > 0) || !std::isfinite(max_speed) || !start.allFinite())
      throw std::invalid_argument("mouse device: the speed must be > 0 and the start finite");
  }
  std::string name() const override { return "mouse"; }
  const DeviceCapabilities& capabilities() const override { return caps_; }
  void open() override {
    x_ = set_ = start_;
    v_.setZero();
    force_.setZero();
    quit_ = false;
  }
  void close() override { force_.setZero(); }
  bool read(DeviceState& s) override {
    const PointerInput& in = input_.read();
    quit_ = in.quit;
    // The set-point glides towards the pointer's at the speed limit (a non-finite one is held).
    Eigen::Vector3d step = Eigen::Vector3d::Zero();
    if (in.active && in.set_point_mm.allFinite()) {
      step = in.set_point_mm - set_;
      const double most = speed_ * period_;
      if (step.norm() > most) step *= most / step.norm();
    }
    const Eigen::Vector3d from = set_, velocity = step / period_;
    hold_for_one_period(
        hand_, caps_, period_, force_, x_, v_,
        [&](double since) -> Eigen::Vector3d { return from + since * velocity; },
        [&](double) { return velocity; });
    set_ = from + step;
    s.position_mm = x_;
    s.velocity_mm_s = v_;
    s.buttons = in.buttons;
    return true;
  }
  bool write_force(const Eigen::Vector3d& f) override {
    force_ = f;
    return true;
  }
  bool finished() const override { return quit_; }

 private:
  TripleBuffer<PointerInput>& input_;
  Eigen::Vector3d start_;
  DeviceCapabilities caps_;
  double period_, speed_;
  HandModel hand_;
  bool quit_ = false;
  Eigen::Vector3d x_ = Eigen::Vector3d::Zero(), v_ = Eigen::Vector3d::Zero(),
                  set_ = Eigen::Vector3d::Zero(), force_ = Eigen::Vector3d::Zero();
};

class ReplayDevice final : public Device {
 public:
  ReplayDevice(const Trajectory& rec, const DeviceCapabilities& caps, double period_s)
      : rec_(rec), caps_(caps), period_(period_s) {}
  std::string name() const override { return "replay"; }
  const DeviceCapabilities& capabilities() const override { return caps_; }
  void open() override { time_ = rec_.t_s.empty() ? 0 : rec_.t_s.front(); }
  void close() override {}
  bool read(DeviceState& s) override {
    s.position_mm = rec_.position_at(time_);
    s.velocity_mm_s = rec_.velocity_at(time_);
    s.orientation = rec_.orientation_at(time_);
    s.angular_velocity_rad_s = rec_.angular_velocity_at(time_);
    s.buttons = rec_.buttons_at(time_);
    time_ += period_;
    return true;
  }
  bool write_force(const Eigen::Vector3d&) override { return true; }
  bool finished() const override { return time_ > rec_.duration_s(); }

 private:
  Trajectory rec_;
  DeviceCapabilities caps_;
  double period_, time_ = 0;
};

class NullDevice final : public Device {
 public:
  NullDevice(const Eigen::Vector3d& p, const DeviceCapabilities& caps, double period_s,
             double duration_s)
      : p_(p), caps_(caps), period_(period_s), duration_(duration_s) {}
  std::string name() const override { return "null"; }
  const DeviceCapabilities& capabilities() const override { return caps_; }
  void open() override { time_ = 0; }
  void close() override {}
  bool read(DeviceState& s) override {
    s.position_mm = p_;
    s.velocity_mm_s.setZero();
    s.buttons = 0;
    time_ += period_;
    return true;
  }
  bool write_force(const Eigen::Vector3d&) override { return true; }
  bool finished() const override { return duration_ > 0 && time_ >= duration_; }

 private:
  Eigen::Vector3d p_;
  DeviceCapabilities caps_;
  double period_, duration_, time_ = 0;
};

}  // namespace

std::unique_ptr<Device> make_sim_device(const Trajectory& script, const DeviceCapabilities& caps,
                                        double period_s, const HandModel& hand) {
  return std::make_unique<SimDevice>(script, caps, period_s, hand);
}

std::unique_ptr<Device> make_mouse_device(TripleBuffer<PointerInput>& input,
                                          const Eigen::Vector3d& start_mm,
                                          const DeviceCapabilities& caps, double period_s,
                                          double max_speed_mm_s, const HandModel& hand) {
  return std::make_unique<MouseDevice>(input, start_mm, caps, period_s, max_speed_mm_s, hand);
}

std::unique_ptr<Device> make_replay_device(const Trajectory& recording,
                                           const DeviceCapabilities& caps, double period_s) {
  return std::make_unique<ReplayDevice>(recording, caps, period_s);
}

std::unique_ptr<Device> make_null_device(const Eigen::Vector3d& position_mm,
                                         const DeviceCapabilities& caps, double period_s,
                                         double duration_s) {
  return std::make_unique<NullDevice>(position_mm, caps, period_s, duration_s);
}

}  // namespace spinesim::haptics

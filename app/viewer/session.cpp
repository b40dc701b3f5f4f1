#include "session.hpp"

#include "field_surface.hpp"

#include "spinesim/haptics/triple_buffer.hpp"
#include "spinesim/mss/model.hpp"
#include "spinesim/mss/quantities.hpp"
#include "spinesim/spine/model.hpp"

#include <imgui.h>

#include <atomic>
#include <cmath>
#include <exception>
#include <limits>
#include <mutex>
#include <optional>
#include <thread>

namespace spinesim::viewer {
namespace {

// Marker colours and scales.
const Eigen::Vector3f kProbe(0.35f, 0.65f, 1.0f), kProxy(1.0f, 1.0f, 1.0f),
    kForce(1.0f, 0.0f, 1.0f), kHook(1.0f, 0.85f, 0.1f), kSpineForce(1.0f, 0.5f, 0.0f),
    kSetPoint(0.6f, 0.6f, 0.6f);
constexpr double kForceArrowMmPerN = 15;   ///< the force on the hand
constexpr double kSpineArrowMmPerN = 0.1;  ///< the hook's force on the spine
constexpr double kWheelStepMm = 5;         ///< a wheel notch moves the mouse's probe this far

/// What the window keeps of the session's set-up (the session's own objects die with it).
struct Setup {
  std::vector<Body> bodies;  ///< the rigid stage, reference coordinates
  std::optional<mss::MssModel> disc;
  FieldSurface disc_surface;
  std::string disc_level, disc_model, device, spine, description;
  double probe_radius_mm = 4;
  Eigen::Vector3d start_mm = Eigen::Vector3d::Zero();
};

class SessionController final : public Controller {
 public:
  SessionController(const studies::HapticsRunRequest& request, const std::string& data_dir,
                    DiscField field)
      : request_(request), data_dir_(data_dir), field_(field) {
    hooks_.pointer = &pointer_;
    hooks_.ready = [this](const studies::HapticsLiveSetup& s) { on_ready(s); };
    hooks_.frame = [this](const studies::HapticsLiveFrame& f) {
      frames_.write(f);
      session_frames_.fetch_add(1);
    };
    request_.live = &hooks_;
    request_.stop = &stop_;
  }
  ~SessionController() override { closing(); }

  /// The session starts with the window's first frame (a window that cannot open costs nothing).
  void start() {
    thread_ = std::thread([this] {
      try {
        result_ = studies::run_haptics(request_, data_dir_);
      } catch (...) {
        std::lock_guard<std::mutex> lock(mutex_);
        error_ = std::current_exception();
      }
      ended_.store(true);
    });
  }

  void update(SceneFrame& scene, const Pointer& pointer) override {
    if (!thread_.joinable() && !stop_.load()) start();
    if (!ready_.load()) return;
    if (scene.bodies.empty()) {
      scene.bodies = setup_.bodies;
      if (setup_.disc) scene.bodies.emplace_back().name = "disc " + setup_.disc_level;
      set_point_ = setup_.start_mm;
    }
    if (setup_.device == "mouse") drive_pointer(pointer);
    const bool fresh = frames_.fresh();
    const studies::HapticsLiveFrame& f = frames_.read();
    if (fresh) ++frames_shown_;
    latest_ = &f;
    const haptics::ServoStatus& s = f.status;
    for (std::size_t i = 0; i < setup_.bodies.size(); ++i) {
      scene.bodies[i].R = s.poses.pose[i].R;
      scene.bodies[i].t = s.poses.pose[i].t;
    }
    if (setup_.disc && f.disc_x_mm.size() == 3 * setup_.disc->num_nodes() &&
        (fresh || field_changed_))
      color_disc(scene.bodies.back(), f.disc_x_mm);
    field_changed_ = false;
    markers(scene, s);
    rates(s, f.loop_time_s);
  }

  void panel() override;
  // The disc is pressed at its anterior wall: look from the front right.
  // The plane (normal +z) would be edge-on from the side: look at it obliquely from the front.
  float initial_yaw() const override {
    if (request_.scene.scene == "plane") return -1.0f;
    return ready_.load() && setup_.disc ? -0.785f : 0.0f;
  }
  // setup_ is the session thread's until ready_ (read ready_ first).
  bool takes_pointer() const override { return ready_.load() && setup_.device == "mouse"; }
  double clock_s(double) const override {
    if (ended_.load()) return std::numeric_limits<double>::infinity();
    return latest_ && session_frames_.load() > 0 ? latest_->loop_time_s : -1;
  }
  bool done() const override {
    std::lock_guard<std::mutex> lock(mutex_);
    return error_ != nullptr;
  }
  void closing() override {
    if (!thread_.joinable()) return;
    haptics::PointerInput quit;
    quit.set_point_mm = set_point_;
    quit.quit = true;
    pointer_.write(quit);
    stop_.store(true);
    thread_.join();
  }

  SessionViewResult result() const {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      if (error_) std::rethrow_exception(error_);  // the session's own one-line error
    }
    SessionViewResult r;
    r.run = result_;
    r.session_frames = session_frames_.load();
    r.frames_shown = frames_shown_;
    r.session_rate_hz =
        result_.stats.seconds > 0 ? double(r.session_frames) / result_.stats.seconds : 0;
    return r;
  }

 private:
  studies::HapticsRunRequest request_;
  std::string data_dir_;
  DiscField field_;
  bool field_changed_ = false;
  studies::HapticsLiveHooks hooks_;
  haptics::TripleBuffer<haptics::PointerInput> pointer_;
  haptics::TripleBuffer<studies::HapticsLiveFrame> frames_;
  std::atomic<bool> stop_{false}, ready_{false}, ended_{false};
  std::atomic<std::int64_t> session_frames_{0};
  std::int64_t frames_shown_ = 0;
  std::thread thread_;
  mutable std::mutex mutex_;
  std::exception_ptr error_;
  studies::HapticsRunResult result_;
  Setup setup_;
  const studies::HapticsLiveFrame* latest_ = nullptr;
  Eigen::Vector3d set_point_ = Eigen::Vector3d::Zero();
  double lo_ = 0, hi_ = 0;
  // The servo rate over the last half second or more, from the ticks the status counts.
  std::int64_t rate_ticks_ = 0;
  double rate_time_ = 0, servo_hz_ = 0;

  void on_ready(const studies::HapticsLiveSetup& s) {
    Setup c;
    c.bodies = bodies_of(s.scene.scene);
    if (s.disc) {
      c.disc.emplace(*s.disc);
      c.disc_surface = FieldSurface(s.disc->mesh().T);
    }
    c.disc_level = s.disc_level;
    c.disc_model = s.disc_model;
    c.device = s.device;
    c.spine = s.spine;
    c.description = s.scene.description;
    c.probe_radius_mm = s.probe_radius_mm;
    c.start_mm = s.device_start_mm;
    setup_ = std::move(c);  // the window's thread takes the start from here once ready_
    ready_.store(true);
  }

  /// The cursor moves the set-point in the plane through it facing the eye; the wheel in depth.
  void drive_pointer(const Pointer& p) {
    if (p.inside && !p.camera_moving) {
      const double denom = p.ray_direction.dot(p.view_direction);
      if (std::abs(denom) > 1e-6) {
        const double t = (set_point_ - p.ray_origin).dot(p.view_direction) / denom;
        if (t > 0) set_point_ = p.ray_origin + t * p.ray_direction;
      }
    }
    set_point_ += p.wheel * kWheelStepMm * p.view_direction;
    haptics::PointerInput in;
    in.set_point_mm = set_point_;
    in.buttons = p.buttons;
    in.active = true;
    pointer_.write(in);
  }

  void color_disc(Body& body, const Eigen::VectorXd& x) {
    const mss::MssModel& m = *setup_.disc;
    Eigen::VectorXd values;
    if (field_ == DiscField::displacement) {
      const Eigen::VectorXd u = mss::displacement(m, x).rowwise().norm();
      values = setup_.disc_surface.from_points(u);
      // 0.1 µm: a disc at rest shows its lowest colour, a pressed one its pattern; the legend
      // reaches the pressed node's displacement (the panel's indentation), not the corner mean.
      setup_.disc_surface.point_range(u, 1e-4, lo_, hi_);
    } else {
      values = setup_.disc_surface.from_cells(field_ == DiscField::spring_strain
                                                  ? mss::tet_edge_strain(m, x)
                                                  : mss::tet_volume_change(m, x));
      FieldSurface::range(values, 1e-5, lo_, hi_);
    }
    const Eigen::Map<const Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor>> V(
        x.data(), x.size() / 3, 3);
    setup_.disc_surface.fill(body, V, values, lo_, hi_);
  }

  void markers(SceneFrame& scene, const haptics::ServoStatus& s) {
    scene.markers.clear();
    const double r = setup_.probe_radius_mm;
    const auto sphere = [&](const Eigen::Vector3d& c, double radius, const Eigen::Vector3f& col) {
      scene.markers.push_back({Marker::Kind::sphere, c, c, radius, col});
    };
    const auto arrow = [&](const Eigen::Vector3d& a, const Eigen::Vector3d& b, double radius,
                           const Eigen::Vector3f& col) {
      scene.markers.push_back({Marker::Kind::arrow, a, b, radius, col});
    };
    sphere(s.probe_mm, r, kProbe);
    // Where the hand is held back: the rigid proxy, or the disc's own probe when pressing it.
    const Eigen::Vector3d held = s.disc_contact ? s.disc_probe_mm : s.proxy_mm;
    if (s.contact || s.disc_contact) sphere(held, r * 1.02, kProxy);
    if (s.force_n.norm() > 0.02) {  // from the sphere's surface, so that all of it shows
      const Eigen::Vector3d from = held + r * s.force_n.normalized();
      arrow(from, from + kForceArrowMmPerN * s.force_n, std::max(0.6, 0.3 * r), kForce);
    }
    if (setup_.device == "mouse") sphere(set_point_, 0.35 * r, kSetPoint);
    if (s.hook.attached || s.hook.gain > 0) {
      sphere(s.hook.hook_mm, 0.5 * r, kHook);
      arrow(s.hook.hook_mm, s.probe_mm, 0.2 * r, kHook);  // the coupling spring
      if (s.hook.load.force_n.norm() > 1)
        arrow(s.hook.hook_mm, s.hook.hook_mm + kSpineArrowMmPerN * s.hook.load.force_n, 0.3 * r,
              kSpineForce);
    }
  }

  void rates(const haptics::ServoStatus& s, double t) {
    if (t - rate_time_ >= 0.5) {
      if (rate_time_ > 0) servo_hz_ = double(s.ticks - rate_ticks_) / (t - rate_time_);
      rate_ticks_ = s.ticks, rate_time_ = t;
    }
  }
};

void SessionController::panel() {
  if (!ready_.load()) {
    ImGui::Text("setting up the session (scene, device, disc) ...");
    return;
  }
  ImGui::Text("%s | device %s%s%s", setup_.description.c_str(), setup_.device.c_str(),
              setup_.spine.empty() ? "" : " | spine ", setup_.spine.c_str());
  if (ended_.load()) ImGui::TextColored(ImVec4(1, 0.8f, 0.3f, 1), "the session has ended");
  if (!latest_) return;
  const haptics::ServoStatus& s = latest_->status;
  ImGui::Text("t %.1f s | servo %.1f Hz | jitter %.0f us | compute %.0f us", latest_->loop_time_s,
              servo_hz_, s.recent_jitter_us, s.recent_compute_us);
  ImGui::Text("graphics %.1f Hz | session frames %lld", double(ImGui::GetIO().Framerate),
              static_cast<long long>(session_frames_.load()));
  const std::string body =
      s.body >= 0 && std::size_t(s.body) < setup_.bodies.size() ? setup_.bodies[s.body].name : "";
  ImGui::Text("force %.2f N %s%s", s.force_n.norm(),
              s.contact ? "touching " : (s.hook.attached ? "hooked" : "free"), body.c_str());
  ImGui::Text("probe %.1f %.1f %.1f mm | absorbed %+.1f mJ (passive: >= 0)", s.probe_mm.x(),
              s.probe_mm.y(), s.probe_mm.z(), s.passivity_mj);
  if (s.hook.attached || s.hook.gain > 0) {
    const int v = s.hook.load.vertebra;
    ImGui::Text("hook %s: spine force %.0f N (felt %.2f N, gain %.2f)",
                v >= 0 && std::size_t(v) < spine::vertebra_names().size()
                    ? spine::vertebra_names()[std::size_t(v)].c_str()
                    : "-",
                s.hook.load.force_n.norm(), s.hook.felt_force_n.norm(), s.hook.gain);
    if (s.hook.load.twist)
      ImGui::Text("twist %.1f deg: spine moment %.2f N m (felt %.0f N mm)", s.hook.twist_deg.norm(),
                  s.hook.load.moment_nmm.norm() / 1000, s.hook.felt_torque_nmm.norm());
  }
  if (setup_.disc) {
    ImGui::Text("disc %s (%s): %s | load %.1f N | indented %.2f mm | volume %+.3f %%",
                setup_.disc_level.c_str(), setup_.disc_model.c_str(),
                s.disc_contact ? "pressed" : "free",
                s.disc_force_n.norm(), s.disc_indentation_mm, 100 * s.disc_volume_change);
    int f = int(field_);
    if (ImGui::Combo("field", &f, kDiscFieldNames, 3)) field_ = DiscField(f), field_changed_ = true;
    color_legend(kDiscFieldLabels[int(field_)], lo_, hi_);
  }
}

}  // namespace

std::vector<Body> bodies_of(const haptics::Scene& scene) {
  std::vector<Body> out;
  for (int i = 0; i < scene.size(); ++i) {
    const haptics::RigidBody& b = scene.body(i);
    Body v;
    v.name = b.name;
    v.V = b.tree.vertices();
    v.F = b.tree.triangles();
    if (b.name == "S1" || b.name == "sacrum") v.color = {0.72f, 0.66f, 0.56f};
    out.push_back(std::move(v));
  }
  return out;
}

SessionViewResult view_session(const studies::HapticsRunRequest& request,
                               const std::string& data_dir, const ViewOptions& options,
                               const std::string& field) {
  check(options);
  const DiscField f = disc_field(field);
  {
    studies::HapticsRunRequest r = request;
    haptics::TripleBuffer<haptics::PointerInput> pointer;
    studies::HapticsLiveHooks hooks;  // the mouse device needs hooks to pass the check
    hooks.pointer = &pointer;
    r.live = &hooks;
    studies::check_haptics_request(r);
  }
  SessionController controller(request, data_dir, f);
  ViewResult view;
  try {
    view = viewer::view(controller, options);
  } catch (...) {
    controller.closing();
    throw;
  }
  controller.closing();
  SessionViewResult r = controller.result();
  r.view = view;
  return r;
}

}  // namespace spinesim::viewer

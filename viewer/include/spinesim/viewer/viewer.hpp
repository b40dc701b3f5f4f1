// The 3-D window: bodies (triangle surfaces at their poses, one colour or a colour per
// triangle), markers (spheres and arrows) and an ImGui panel, with an orbit camera. What is shown
// comes from a Controller, asked once a frame on the window's thread, so a live session or a
// playback can move and recolour everything while the window runs at its own rate. OpenGL 3.3
// core through GLFW; the panel is Dear ImGui. `screenshot` renders a number of frames (or until
// a time) and writes the last as a PNG (for scripts and the tests under Xvfb).
//
// Camera: left drag orbits, right drag pans, the wheel zooms. When the controller takes the
// pointer (the mouse as a 3-DOF device): the cursor is the probe's set-point, the left button or
// the space bar is the stylus button, the wheel moves the probe in depth; right drag orbits,
// middle drag pans and shift + wheel zooms.
//
// Frame: the spine's (x lateral, body's right -x; y superior; z anterior), mm. The default camera
// looks at the scene's centre from the body's right (a sagittal view: superior up, anterior to
// the screen's right), far enough for the whole scene to fit.
#pragma once

#include <Eigen/Core>

#include <cstdint>
#include <limits>
#include <string>
#include <vector>

namespace spinesim::viewer {

struct Body {
  std::string name;
  Eigen::MatrixX3d V;  ///< reference coordinates, mm
  Eigen::MatrixX3i F;
  Eigen::Matrix3d R = Eigen::Matrix3d::Identity();  ///< pose: x_world = R x + t
  Eigen::Vector3d t = Eigen::Vector3d::Zero();
  Eigen::Vector3f color{0.85f, 0.80f, 0.70f};  ///< RGB in [0, 1]
  Eigen::MatrixX3f face_colors;                ///< per triangle (#F×3); empty: `color`
  bool visible = true;
  /// Changed by whoever changes V, F or face_colors: the viewer uploads the body again.
  std::uint64_t revision = 0;
};

/// A sphere (centre `a`, `radius_mm`), an arrow from `a` to `b` (shaft radius `radius_mm`), or
/// a rod from `a` to `b` (an undirected glyph: a fibre, a principal axis).
struct Marker {
  enum class Kind { sphere, arrow, rod };
  Kind kind = Kind::sphere;
  Eigen::Vector3d a = Eigen::Vector3d::Zero(), b = Eigen::Vector3d::Zero();
  double radius_mm = 1;
  Eigen::Vector3f color{1, 1, 1};
};

struct SceneFrame {
  std::vector<Body> bodies;
  std::vector<Marker> markers;
};

/// The pointer as the viewer sees it this frame (world frame, mm).
struct Pointer {
  bool inside = false;  ///< the cursor is in the window and not over the panel
  Eigen::Vector3d ray_origin = Eigen::Vector3d::Zero(), ray_direction = Eigen::Vector3d::UnitZ();
  Eigen::Vector3d view_direction = Eigen::Vector3d::UnitX();  ///< from the eye into the scene
  unsigned buttons = 0;        ///< bit 0: the stylus button (left button or space)
  double wheel = 0;            ///< notches since the last frame (+: away from the eye)
  bool camera_moving = false;  ///< right or middle button held: the camera moves
};

/// Supplies the scene, frame by frame, on the window's thread.
class Controller {
 public:
  virtual ~Controller() = default;
  /// Before each frame is drawn: bring `scene` up to date (poses, colours, markers).
  virtual void update(SceneFrame& scene, const Pointer& pointer) = 0;
  /// The panel's contents: Dear ImGui calls, inside the viewer's panel window.
  virtual void panel() {}
  /// The first view's yaw about the superior axis (rad): 0 is the sagittal view from the body's
  /// right, -pi/4 looks from the front right.
  virtual float initial_yaw() const { return 0; }
  /// True: the pointer drives a device (see the header comment).
  virtual bool takes_pointer() const { return false; }
  /// The clock (s) the cursor script and the screenshot time count on, given the window's
  /// (seconds since it opened); negative: not started (no screenshot yet, the script waits).
  virtual double clock_s(double window_s) const { return window_s; }
  /// True: close the window (e.g. the session failed).
  virtual bool done() const { return false; }
  /// Called once when the window closes (or after the screenshot).
  virtual void closing() {}
};

struct ViewOptions {
  std::string title = "spinesim";
  int width = 1280, height = 800;  ///< window size, pixels
  std::string screenshot;          ///< PNG path: render, write, close
  int frames = 3;                  ///< frames before the screenshot (>= 1)
  double screenshot_after_s = 0;   ///< ... and not before this time (Controller::clock_s)
  bool panel = true;               ///< the ImGui panel
  /// The first view's direction, degrees: yaw about the superior axis (0: from the body's right,
  /// -45: from the front right) and the eye's elevation above the horizontal. NaN: the
  /// controller's choice, level.
  double camera_yaw_deg = std::numeric_limits<double>::quiet_NaN();
  double camera_pitch_deg = std::numeric_limits<double>::quiet_NaN();
  /// Scripted pointer (tests and demos): at `t_s` (Controller::clock_s), the cursor is where
  /// the world point `point_mm` appears on the screen (linear in between), with `buttons` held
  /// and `wheel` notches turned at that step. Replaces the real cursor when not empty.
  struct CursorStep {
    double t_s = 0;
    Eigen::Vector3d point_mm = Eigen::Vector3d::Zero();
    unsigned buttons = 0;
    double wheel = 0;
  };
  std::vector<CursorStep> cursor_script;
};

struct ViewResult {
  int frames = 0;
  /// Wall time to make a frame (input, the controller's update, drawing, the panel, reading the
  /// screenshot), over the frames that showed a scene; the swap and the 60 Hz cap excluded.
  double mean_frame_ms = 0, p50_frame_ms = 0, p99_frame_ms = 0;
  double rate_hz = 0;      ///< frames shown per second (at most 60)
  std::string renderer;    ///< GL_RENDERER, e.g. "llvmpipe (LLVM 15.0.6, 256 bits)"
  std::string gl_version;  ///< GL_VERSION
};

/// Throws std::invalid_argument (one line) for a window size outside 64-8192 pixels, a
/// screenshot after fewer than one frame or a negative time, or a cursor script whose times
/// do not increase; view() checks the same before it opens anything.
void check(const ViewOptions& options);

/// Opens the window and runs until it is closed (or, with a screenshot, until it is taken).
/// Throws std::runtime_error with one line when there is no display, no OpenGL 3.3 core context
/// or the PNG cannot be written; std::invalid_argument for bad options.
ViewResult view(Controller& controller, const ViewOptions& options);

/// A still scene (the bodies as given).
ViewResult view(const std::vector<Body>& bodies, const ViewOptions& options);

/// A colour for `value` on [lo, hi]: a diverging blue–white–red map centred on 0 when lo < 0 <
/// hi, else a sequential one (dark blue → yellow). Values outside are clamped; NaN is grey.
Eigen::Vector3f colormap(double value, double lo, double hi);

/// In a panel: a colour bar of `colormap` over [lo, hi] labelled with `label` and the ends.
void color_legend(const char* label, double lo, double hi);

}  // namespace spinesim::viewer

// The 3-D window: the scene's bodies (triangle surfaces at their poses), shaded, with an orbit
// camera (left drag orbits, right drag pans, the wheel zooms) and a panel of what is shown.
// OpenGL 3.3 core through GLFW; the panel is Dear ImGui. `screenshot` renders a fixed number of
// frames and writes the last as a PNG (for scripts and the tests under Xvfb).
//
// Frame: the spine's (x lateral, body's right -x; y superior; z anterior), mm. The default camera
// looks at the scene's centre from the body's right (a sagittal view: superior up, anterior to
// the screen's right), far enough for the whole scene to fit.
#pragma once

#include <Eigen/Core>

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
};

struct ViewOptions {
  std::string title = "spinesim";
  int width = 1280, height = 800;  ///< window size, pixels
  std::string screenshot;          ///< PNG path: render `frames` frames, write, close
  int frames = 3;                  ///< frames before the screenshot (>= 1)
  bool panel = true;               ///< the ImGui panel
};

struct ViewResult {
  int frames = 0;
  double mean_frame_ms = 0;  ///< wall time per frame, rendering and swapping
  std::string renderer;      ///< GL_RENDERER, e.g. "llvmpipe (LLVM 15.0.6, 256 bits)"
  std::string gl_version;    ///< GL_VERSION
};

/// Throws std::invalid_argument (one line) for a window size outside 64-8192 pixels or a
/// screenshot after fewer than one frame; view() checks the same before it opens anything.
void check(const ViewOptions& options);

/// Opens the window and runs until it is closed (or, with a screenshot, for `frames` frames).
/// Throws std::runtime_error with one line when there is no display, no OpenGL 3.3 core context
/// or the PNG cannot be written; std::invalid_argument for an empty scene or bad options.
ViewResult view(const std::vector<Body>& bodies, const ViewOptions& options);

}  // namespace spinesim::viewer

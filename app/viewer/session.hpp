// The viewer on a haptic session: studies::run_haptics runs on its own thread (its servo thread,
// disc thread and spine worker under it) while the window shows its scene at the graphics' own
// rate — the vertebrae at the poses the servo rendered, the palpated disc coloured by a field,
// the probe, the proxy, the force on the hand, the hook — and a panel with the loop's own
// figures (servo rate, period jitter, compute time, force, passivity energy, hook force). The
// window reads the session's latest frame through a triple buffer: it never blocks the servo.
// With the `mouse` device the pointer is the probe's hand (viewer.hpp, "the mouse as a 3-DOF
// device").
#pragma once

#include "spinesim/studies/haptics_run.hpp"
#include "spinesim/viewer/viewer.hpp"

#include <cstdint>
#include <string>
#include <vector>

namespace spinesim::viewer {

/// A haptic scene's rigid bodies at the reference posture, bone-coloured (the sacrum darker).
std::vector<Body> bodies_of(const haptics::Scene& scene);

struct SessionViewResult {
  studies::HapticsRunResult run;
  ViewResult view;
  std::int64_t session_frames = 0;  ///< frames the session published (about every 10 ms)
  std::int64_t frames_shown = 0;    ///< window frames that drew a new session frame
  double session_rate_hz = 0;       ///< session frames per second of the loop
};

/// Runs the session and the window until the window closes (the session is then stopped), or
/// the screenshot is taken; a session that ends on its own leaves the window showing its last
/// state. `field`: displacement, spring_strain or volume_change. Throws what run_haptics throws
/// (one line) when the session cannot start, std::runtime_error for a window that cannot open.
SessionViewResult view_session(const studies::HapticsRunRequest& request,
                               const std::string& data_dir, const ViewOptions& options,
                               const std::string& field = "displacement");

}  // namespace spinesim::viewer

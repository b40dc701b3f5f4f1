// spinesim view — the 3-D window (viewer/).
//
//   spinesim view [--scene spine|vertebra|disc|plane] [--device mouse|sim|replay|null|openhaptics|dhd|none]
//                 [every `haptics run` flag: --spine multirate, --level, --script …]
//                 [--field displacement|spring_strain|volume_change]
//                 [--width W --height H] [--screenshot FILE [--frames N] [--screenshot-at S]]
//                 [--cursor-script CSV] [--no-panel] [--json]
//   spinesim view --play SERIES.pvd [--recording REC.csv] [--field F] [--speed X] [--at S] [--paused]
//   spinesim view --play RESULT.vtu [--field F] [--vectors fibre_direction_1,fibre_direction_2]
//
// By default the servo loop runs with the mouse as the device. A missing display, an OpenGL
// below 3.3 core or a device that cannot be opened is one line and a non-zero exit.
#include "cli_common.hpp"

#include "playback.hpp"
#include "session.hpp"
#include "spinesim/haptics/device.hpp"
#include "spinesim/haptics/scene_builder.hpp"
#include "spinesim/viewer/viewer.hpp"

#include <cmath>
#include <iostream>
#include <memory>

namespace spinesim::cli {
namespace {

struct ViewArgs {
  HapticsRunFlags session;
  viewer::ViewOptions view;
  viewer::PlaybackRequest play;
  std::string cursor_script;
  std::vector<double> camera;
  bool no_panel = false, json = false, quiet = false;
};

nlohmann::json view_json(const viewer::ViewResult& r) {
  return {
      {"frames", r.frames},
      {"frame_ms", {{"mean", r.mean_frame_ms}, {"p50", r.p50_frame_ms}, {"p99", r.p99_frame_ms}}},
      {"rate_hz", r.rate_hz},
      {"renderer", r.renderer},
      {"gl_version", r.gl_version}};
}

void report_view(const ViewArgs& a, const viewer::ViewResult& r) {
  if (a.json || a.quiet) return;
  std::cout << (a.view.screenshot.empty() ? "window" : "screenshot " + a.view.screenshot) << ": "
            << r.frames << " frames at " << fixed(r.rate_hz, 1) << " Hz, "
            << fixed(r.mean_frame_ms, 1) << " ms to draw one (p50 " << fixed(r.p50_frame_ms, 1)
            << ", p99 " << fixed(r.p99_frame_ms, 1) << "; " << r.renderer << ", OpenGL "
            << r.gl_version << ")\n";
}

void run_still(const ViewArgs& a, viewer::ViewOptions o) {
  haptics::HapticSceneRequest request = a.session.request.scene;
  const haptics::HapticScene scene = haptics::build_haptic_scene(request, data_dir());
  if (scene.scene.size() == 0)
    throw std::invalid_argument("view: the " + request.scene + " scene has no surfaces to show");
  o.title = "spinesim — " + scene.description;
  const viewer::ViewResult r = viewer::view(viewer::bodies_of(scene.scene), o);
  if (a.json) print_json({{"view", view_json(r)}});
  report_view(a, r);
}

void run_session(const ViewArgs& a, viewer::ViewOptions o) {
  o.title = "spinesim — " + a.session.request.scene.scene + ", device " + a.session.request.device;
  const viewer::SessionViewResult r =
      viewer::view_session(a.session.request, data_dir(), o, a.play.field);
  if (a.json) {
    nlohmann::json j = haptics_run_json(r.run);
    j["view"] = view_json(r.view);
    j["view"]["session_frames"] = r.session_frames;
    j["view"]["frames_with_new_session_frame"] = r.frames_shown;
    j["view"]["session_rate_hz"] = r.session_rate_hz;
    print_json(j);
    return;
  }
  if (!a.quiet) std::cout << haptics_run_table(r.run);
  report_view(a, r.view);
  if (!a.quiet)
    std::cout << "graphics read the session's latest frame " << fixed(r.session_rate_hz, 1)
              << " times a second of the loop (" << r.session_frames << " frames)\n";
}

void run_playback(const ViewArgs& a, viewer::ViewOptions o) {
  o.title = "spinesim — " + a.play.pvd;
  const viewer::PlaybackResult r = viewer::view_playback(a.play, data_dir(), o);
  if (a.json) {
    print_json({{"view", view_json(r.view)},
                {"series",
                 {{"times", r.times},
                  {"first_s", r.first_s},
                  {"last_s", r.last_s},
                  {"fields", r.fields},
                  {"frames_read", r.loads},
                  {"glyphs", r.glyphs}}}});
    return;
  }
  report_view(a, r.view);
}

void run(ViewArgs& a) {
  viewer::ViewOptions o = a.view;
  o.panel = !a.no_panel;
  if (!a.camera.empty()) {
    if (a.camera.size() != 2 || !std::isfinite(a.camera[0]) || !std::isfinite(a.camera[1]) ||
        std::abs(a.camera[1]) > 85 || std::abs(a.camera[0]) > 360)
      throw std::invalid_argument(
          "--camera YAW,PITCH: two finite angles in degrees, |yaw| <= 360, |pitch| <= 85");
    o.camera_yaw_deg = a.camera[0];
    o.camera_pitch_deg = a.camera[1];
  }
  if (!a.cursor_script.empty()) {
    const haptics::Trajectory t = haptics::read_trajectory(a.cursor_script);
    for (std::size_t i = 0; i < t.t_s.size(); ++i)
      o.cursor_script.push_back({t.t_s[i], t.position_mm[i], t.buttons[i], 0});
  }
  viewer::check(o);  // before anything slow
  if (!o.screenshot.empty()) require_output_folder(o.screenshot, "--screenshot");
  if (!a.play.pvd.empty()) return run_playback(a, o);
  resolve_haptics_run_flags(a.session);
  if (a.session.request.device == "none") return run_still(a, o);
  run_session(a, o);
}

}  // namespace

void register_view(CLI::App& app) {
  auto a = std::make_shared<ViewArgs>();
  a->session.request.device = "mouse";
  auto* cmd = app.add_subcommand(
      "view",
      "The scene in a 3-D window with the servo loop running (the mouse is the device unless "
      "another is named), or a time series played back (--play)");
  add_haptics_run_flags(cmd, a->session, true);
  cmd->add_option("--field", a->play.field,
                  "Colour the discs by displacement, spring_strain or volume_change (--play: any "
                  "field the series has)")
      ->capture_default_str();
  cmd->add_option("--play", a->play.pvd,
                  "Play back this ParaView series (.pvd), or show one VTU file, instead");
  cmd->add_option("--vectors", a->play.vectors,
                  "--play: draw these cell vector fields as rods on the surface (e.g. "
                  "fibre_direction_1,fibre_direction_2 of a `spinesim fem` VTU)")
      ->delimiter(',');
  cmd->add_option(
      "--recording", a->play.recording,
      "--play: the compliant-stage recording that drove the series (probe, hook, force)");
  cmd->add_option("--speed", a->play.speed, "--play: series seconds per second")
      ->capture_default_str();
  cmd->add_option("--at", a->play.at_s, "--play: start at this time of the series, s");
  cmd->add_flag("--paused", a->play.paused, "--play: start paused");
  cmd->add_option("--width", a->view.width, "Window width, pixels")->capture_default_str();
  cmd->add_option("--height", a->view.height, "Window height, pixels")->capture_default_str();
  cmd->add_option("--screenshot", a->view.screenshot,
                  "Render --frames frames (and until --screenshot-at), write the last as this PNG "
                  "and close");
  cmd->add_option("--frames", a->view.frames, "Frames before the screenshot")
      ->capture_default_str();
  cmd->add_option("--screenshot-at", a->view.screenshot_after_s,
                  "Not before this time of the session's loop (s; the window's time for a still "
                  "scene or a playback)");
  cmd->add_option("--cursor-script", a->cursor_script,
                  "Move the cursor to where these scene points (CSV t_s,x_mm,y_mm,z_mm[,button]) "
                  "appear on the screen, on the session's clock (tests, demos)");
  cmd->add_flag("--no-panel", a->no_panel, "Leave out the ImGui panel");
  cmd->add_option("--camera", a->camera,
                  "First view as YAW,PITCH in degrees (yaw 0: from the body's right, -90: from "
                  "the front; pitch: the eye's elevation above the horizontal)")
      ->delimiter(',');
  add_output_flags(cmd, a->json, a->quiet);
  cmd->callback([a] { run(*a); });
}

}  // namespace spinesim::cli

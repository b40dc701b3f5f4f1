// spinesim view — the scene in a 3-D window (viewer/viewer.hpp).
//
//   spinesim view [--scene spine|vertebra|disc] [--level L4-L5] [--vertebrae generated|real|FILE]
//                 [--triangles N] [--width W --height H] [--screenshot FILE --frames N] [--no-panel]
//
// A missing display or an OpenGL below 3.3 core is one line and a non-zero exit.
#include "cli_common.hpp"

#include "spinesim/studies/haptic_scene.hpp"
#include "spinesim/viewer/viewer.hpp"

#include <iostream>
#include <memory>

namespace spinesim::cli {
namespace {

struct ViewArgs {
  studies::HapticSceneRequest scene;
  viewer::ViewOptions view;
  bool no_panel = false;
};

/// The scene's bodies at the reference posture, bone-coloured (the sacrum a little darker).
std::vector<viewer::Body> bodies_of(const studies::HapticScene& s) {
  std::vector<viewer::Body> out;
  for (int i = 0; i < s.scene.size(); ++i) {
    const haptics::RigidBody& b = s.scene.body(i);
    viewer::Body v;
    v.name = b.name;
    v.V = b.tree.vertices();
    v.F = b.tree.triangles();
    if (b.name == "S1" || b.name == "sacrum") v.color = {0.72f, 0.66f, 0.56f};
    out.push_back(std::move(v));
  }
  return out;
}

void run(const ViewArgs& a) {
  viewer::ViewOptions o = a.view;
  o.panel = !a.no_panel;
  viewer::check(o);  // before the scene is built
  studies::HapticSceneRequest request = a.scene;
  if (request.testdata_dir.empty()) request.testdata_dir = testdata_dir();
  const studies::HapticScene scene = studies::build_haptic_scene(request, data_dir());
  if (scene.scene.size() == 0)
    throw std::invalid_argument("view: the " + request.scene + " scene has no surfaces to show");
  o.title = "spinesim — " + scene.description;
  const viewer::ViewResult r = viewer::view(bodies_of(scene), o);
  if (!o.screenshot.empty())
    std::cout << "screenshot " << o.screenshot << ": " << r.frames << " frames, " << r.mean_frame_ms
              << " ms a frame (" << r.renderer << ", OpenGL " << r.gl_version << ")\n";
}

}  // namespace

void register_view(CLI::App& app) {
  auto a = std::make_shared<ViewArgs>();
  auto* cmd = app.add_subcommand("view", "Show the scene in a 3-D window (orbit, pan, zoom)");
  add_scene_flags(cmd, a->scene);
  cmd->add_option("--level", a->scene.level, "disc scene: the level whose vertebrae are shown")
      ->capture_default_str();
  cmd->add_option("--width", a->view.width, "Window width, pixels")->capture_default_str();
  cmd->add_option("--height", a->view.height, "Window height, pixels")->capture_default_str();
  cmd->add_option("--screenshot", a->view.screenshot,
                  "Render --frames frames, write the last as this PNG and close");
  cmd->add_option("--frames", a->view.frames, "Frames before the screenshot")
      ->capture_default_str();
  cmd->add_flag("--no-panel", a->no_panel, "Leave out the ImGui panel");
  cmd->callback([a] { run(*a); });
}

}  // namespace spinesim::cli

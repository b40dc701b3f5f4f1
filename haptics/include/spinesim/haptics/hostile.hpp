// Hostile hands: scripted set-point trajectories made to break a haptic tick's bounds, built from
// any scene's own geometry so that every scene gets them. Each is what a real hand can do to a
// desktop device (the sim device's hand model still has to pull the stylus there):
//   teleport      the set-point jumps from outside the scene to a point deep inside a body and
//                 back, body after body;
//   start-inside  the run starts with the set-point inside a body, which then leaves slowly;
//   sweep         back and forth along the scene's longest axis through its middle at 2.5 m/s;
//   skim          the same, offset towards one face of the scene (grazing the surfaces);
//   shake         a 30 Hz, ±8 mm shake into and out of a body's surface;
//   hammer        pressed on a body while dragged along the long axis, the button pressed and
//                 released every 20 ms (hook, release, hook again in the compliant stage).
#pragma once

#include "spinesim/haptics/device.hpp"
#include "spinesim/haptics/scene.hpp"

#include <string>
#include <vector>

namespace spinesim::haptics {

/// The names above, in that order.
const std::vector<std::string>& hostile_names();
/// Throws std::invalid_argument (one line, naming the trajectories) unless `name` is one of them.
void check_hostile_name(const std::string& name);

/// The trajectory `name` for `scene` at `poses` (world frame, mm). Throws std::invalid_argument
/// (one line, naming the trajectories) for an unknown name or an empty scene.
Trajectory hostile_trajectory(const std::string& name, const Scene& scene,
                              const ScenePoses& poses = ScenePoses{});

}  // namespace spinesim::haptics

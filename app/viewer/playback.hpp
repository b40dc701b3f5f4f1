// The viewer on a time series the program wrote (a ParaView .pvd: `spine discs`, `study
// haptic-drag`): at the time shown, each part's VTU — tetrahedral parts (the discs) coloured by
// a field, triangle parts (the vertebrae) bone-coloured — with play, pause, speed and a time
// slider. With the compliant-stage recording that drove the series, the probe, the hook and the
// force on the spine at that time are drawn too. A single .vtu plays as a one-frame series, and
// cell vector fields (the annulus fibres) can be drawn as rods on the surface.
#pragma once

#include "spinesim/viewer/viewer.hpp"

#include <string>
#include <vector>

namespace spinesim::viewer {

struct PlaybackRequest {
  std::string pvd;                     ///< a .pvd series, or one .vtu
  std::string recording;               ///< optional: the haptic recording (haptic_recording.hpp)
  std::string field = "displacement";  ///< a point field's magnitude or a one-component cell field
  double speed = 1;                    ///< simulated seconds per wall-clock second
  double at_s = 0;                     ///< start at this time of the series
  bool paused = false;
  /// Three-component cell fields drawn as rods through the surface cells (each field its own
  /// colour; zero or non-finite vectors are skipped).
  std::vector<std::string> vectors;
};

struct PlaybackResult {
  ViewResult view;
  int times = 0;  ///< distinct times in the series
  double first_s = 0, last_s = 0;
  std::vector<std::string> fields;  ///< what the tetrahedral parts can be coloured by
  int loads = 0;                    ///< frames read from disk
  double mean_load_ms = 0;          ///< per frame read (all parts)
  int glyphs = 0;                   ///< vector rods drawn in the last frame
};

/// Reads the series' index and its first frame before the window opens: throws
/// std::invalid_argument (one line) for a bad .pvd or VTU, a field or vector field the series
/// does not have (listing those it has), a bad speed or time, or a recording of another spine
/// model.
PlaybackResult view_playback(const PlaybackRequest& request, const std::string& data_dir,
                             const ViewOptions& options);

}  // namespace spinesim::viewer

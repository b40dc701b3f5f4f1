// The demo's pictures of the viewer (cli_demo.cpp).
#pragma once

#include <string>

namespace spinesim::cli {

/// Writes DIR/plots/view_*.png and DIR/viewer.json (file, title, thesis, ours per picture) by
/// running `spinesim view --screenshot` on three scenes, under xvfb-run when there is no
/// display; returns one line saying how many were made (or why none).
std::string take_demo_screenshots(const std::string& out);

}  // namespace spinesim::cli

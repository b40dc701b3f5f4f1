// The demo's pictures of the viewer: `spinesim view` run as a child process (under xvfb-run when
// there is no display) on three scenes, each a PNG in DIR/plots/ with its caption and numbers in
// DIR/viewer.json for the report script.
#include "demo_screenshots.hpp"

#include "cli_common.hpp"

#include <array>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>

namespace spinesim::cli {
namespace {

namespace fs = std::filesystem;

std::string quote(const std::string& s) {
  std::string q = "'";
  for (const char c : s) q += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return q + "'";
}

/// Runs `command`; its stdout, or empty when it failed.
std::string run(const std::string& command) {
  std::string out;
  FILE* pipe = ::popen((command + " 2>/dev/null").c_str(), "r");
  if (!pipe) return {};
  std::array<char, 4096> buffer{};
  while (std::fgets(buffer.data(), int(buffer.size()), pipe)) out += buffer.data();
  return ::pclose(pipe) == 0 ? out : std::string();
}

struct Shot {
  std::string file, args, title, thesis;
};

}  // namespace

std::string take_demo_screenshots(const std::string& out) {
  std::string prefix;
  const char* display = std::getenv("DISPLAY");
  if (!display || !*display) {
    if (std::system("command -v xvfb-run >/dev/null 2>&1") != 0)
      return "viewer screenshots skipped: no display and no xvfb-run (apt-get install xvfb)";
    prefix = "xvfb-run -a -s '-screen 0 1280x960x24' ";
  }
  std::error_code ec;
  const fs::path self = fs::read_symlink("/proc/self/exe", ec);
  if (ec) return "viewer screenshots skipped: cannot find the spinesim program";
  const fs::path haptics = fs::path(data_dir()) / "haptics";
  const std::vector<Shot> shots = {
      {"view_spine_drag.png",
       "--scene spine --spine multirate --device sim --script " +
           quote((haptics / "drag_t1_sagittal.csv").string()) + " --screenshot-at 4.2",
       "The viewer on the compliant stage: the hand hooks T1 and drags it 40 mm posteriorly",
       "Ch. 4.5, 6.3: the thesis's users watched the spine in HOOPS while they dragged it."},
      {"view_disc_displacement.png",
       "--scene disc --device sim --disc-cell-size 3 --screenshot-at 2.5",
       "The viewer on disc palpation: the hand 2 mm past the L4-L5 disc's anterior wall, the disc "
       "coloured by displacement (its indentation and load below)",
       "Ch. 5.3, 6.4: the MSS disc under the probe (fig 5.8 plots its force)."},
      {"view_disc_volume.png",
       "--scene disc --device sim --disc-cell-size 3 --field volume_change --screenshot-at 5.0",
       "The same disc, the hand 4 mm past the wall, coloured by each tet's volume change",
       "Ch. 5.2: the MSS's volume springs keep the disc's volume; the thesis shows no picture."}};
  nlohmann::json list = nlohmann::json::array();
  for (const Shot& s : shots) {
    const std::string png = (fs::path(out) / "plots" / s.file).string();
    fs::create_directories(fs::path(png).parent_path(), ec);
    const std::string text = run(prefix + quote(self.string()) + " view " + s.args +
                                 " --width 1100 --height 800 --json --screenshot " + quote(png));
    nlohmann::json j = nlohmann::json::parse(text, nullptr, false);
    if (text.empty() || j.is_discarded() || !fs::exists(png)) continue;
    std::string ours = "servo " + fixed(j.value("rate_hz", 0.0), 1) + " Hz while the viewer drew " +
                       fixed(j["view"].value("rate_hz", 0.0), 1) + " frames a second (" +
                       fixed(j["view"]["frame_ms"].value("p50", 0.0), 1) + " ms each, " +
                       j["view"].value("renderer", std::string()) + ")";
    if (j["compliant_stage"].is_object())
      ours += "; largest force on the spine " +
              fixed(j["compliant_stage"].value("max_spine_force_n", 0.0), 0) + " N";
    if (j["disc_palpation"].is_object()) {
      const auto& d = j["disc_palpation"];
      ours += "; disc " + std::to_string(d.value("tets", 0)) + " tets (" +
              d.value("solver", std::string()) + "), indented up to " +
              fixed(d.value("max_indentation_mm", 0.0), 2) + " mm under a load of up to " +
              fixed(d.value("max_load_n", 0.0), 1) + " N (force scale " +
              fixed(d.value("force_scale", 0.0), 1) + " disc N per felt N)";
    }
    list.push_back({{"file", s.file}, {"title", s.title}, {"thesis", s.thesis}, {"ours", ours}});
  }
  output::write_json_file((fs::path(out) / "viewer.json").string(), list);
  return std::to_string(list.size()) + " of " + std::to_string(shots.size()) +
         " viewer screenshots" + (prefix.empty() ? "" : " (under xvfb-run)");
}

}  // namespace spinesim::cli

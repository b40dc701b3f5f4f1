// `spinesim view`: a screenshot of the spine under Xvfb (Mesa's software renderer) shows the spine
// where the camera puts it; pressing the disc colours it and draws the force arrow; the mouse
// (a scripted cursor) hooks T1 and drags the spine; a series plays back; a missing display, a
// bad option or a mouse without the viewer is one line and a non-zero exit.
#include "cli_runner.hpp"

#include <gtest/gtest.h>
#include <stb_image.h>

#include <nlohmann/json.hpp>

#include "spinesim/mesh/io.hpp"

#include <filesystem>
#include <fstream>
#include <memory>
#include <sstream>

namespace spinesim::test_cli {
namespace {

bool have_xvfb() { return std::system("command -v xvfb-run >/dev/null 2>&1") == 0; }

/// The program's command line run under xvfb-run on a screen of `screen` pixels (WxH), after
/// `env` (variables to set).
std::string xvfb(const std::string& screen, const std::string& env = "") {
  return env + "xvfb-run -a -s '-screen 0 " + screen + "x24' ";
}

struct Image {
  int width = 0, height = 0;
  std::unique_ptr<unsigned char, void (*)(void*)> rgb{nullptr, stbi_image_free};
  const unsigned char* at(int x, int y) const { return rgb.get() + 3 * (y * width + x); }
};

Image load_png(const std::string& path) {
  Image im;
  int channels = 0;
  im.rgb.reset(stbi_load(path.c_str(), &im.width, &im.height, &channels, 3));
  return im;
}

TEST(CliView, ScreenshotShowsTheSpineUprightInTheMiddle) {
  if (!have_xvfb()) GTEST_SKIP() << "xvfb-run missing (apt-get install xvfb)";
  const std::string png = tmp("view.png");
  std::filesystem::remove(png);
  const CliRun r = run_spinesim(
      "view --triangles 600 --width 400 --height 500 --no-panel --frames 2 --screenshot '" + png +
          "'",
      xvfb("640x600"));
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("screenshot"), std::string::npos) << r.out;
  const Image im = load_png(png);
  ASSERT_TRUE(im.rgb) << "not a PNG: " << png;
  ASSERT_EQ(im.width, 400);
  ASSERT_EQ(im.height, 500);
  // The background is the clear colour (dark grey-blue); bone is light. Bounding box of bone.
  int lit = 0, x0 = im.width, x1 = -1, y0 = im.height, y1 = -1;
  for (int y = 0; y < im.height; ++y)
    for (int x = 0; x < im.width; ++x) {
      const unsigned char* p = im.at(x, y);
      if (p[0] > 90 && p[1] > 80 && p[2] > 60) {
        ++lit;
        x0 = std::min(x0, x), x1 = std::max(x1, x), y0 = std::min(y0, y), y1 = std::max(y1, y);
      }
    }
  ASSERT_GT(lit, im.width * im.height / 50) << "blank screenshot";
  // Framed: the spine spans most of the height, is taller than wide, centred left-right.
  EXPECT_GT(y1 - y0, im.height * 6 / 10);
  EXPECT_GT(y1 - y0, 2 * (x1 - x0));
  EXPECT_NEAR(0.5 * (x0 + x1), 0.5 * im.width, 0.15 * im.width);
  EXPECT_GT(y0, 0);  // nothing cut off at the top or bottom
  EXPECT_LT(y1, im.height - 1);
}

/// Pixels of the sequential colour map's upper half (teal, green, yellow: G dominant), which
/// neither bone (R > G), the probe (B > G), the proxy (white) nor the arrow (magenta) has.
int colormap_high_pixels(const Image& im) {
  int n = 0;
  for (int y = 0; y < im.height; ++y)
    for (int x = 0; x < im.width; ++x) {
      const unsigned char* p = im.at(x, y);
      n += p[1] > 90 && p[1] > p[0] + 15 && p[1] >= p[2];
    }
  return n;
}

/// Pixels of the force arrow (magenta).
int magenta_pixels(const Image& im) {
  int n = 0;
  for (int y = 0; y < im.height; ++y)
    for (int x = 0; x < im.width; ++x) {
      const unsigned char* p = im.at(x, y);
      n += p[0] > 120 && p[2] > 120 && p[1] < 60;
    }
  return n;
}

// The shipped press of the L4-L5 disc (sim hand): free at 0.3 s, pressed 4 mm at 5 s. Free: the
// disc is one colour (the map's lowest: nothing displaced) and there is no force arrow; pressed:
// the faces under the probe take the map's upper colours and the arrow is there.
TEST(CliView, PressedDiscIsColouredAndTheForceArrowShows) {
  if (!have_xvfb()) GTEST_SKIP() << "xvfb-run missing (apt-get install xvfb)";
  int high[2] = {0, 0}, arrow[2] = {0, 0};
  const char* at[2] = {"0.3", "5.0"};
  for (int k = 0; k < 2; ++k) {
    const std::string png = tmp(std::string("disc_") + at[k] + ".png");
    std::filesystem::remove(png);
    const CliRun r = run_spinesim(
        std::string("view --scene disc --device sim --disc-cell-size 4 --no-realtime --no-panel "
                    "--width 640 --height 480 --json --screenshot-at ") +
            at[k] + " --screenshot '" + png + "'",
        xvfb("800x600"));
    ASSERT_EQ(r.status, 0) << r.err;
    const auto j = nlohmann::json::parse(r.out);
    EXPECT_GT(j["view"]["session_frames"].get<int>(), 0);
    const Image im = load_png(png);
    ASSERT_TRUE(im.rgb) << png;
    high[k] = colormap_high_pixels(im);
    arrow[k] = magenta_pixels(im);
  }
  EXPECT_EQ(high[0], 0);
  EXPECT_GT(high[1], 20);
  EXPECT_EQ(arrow[0], 0);
  EXPECT_GT(arrow[1], 20);
}

// The mouse as the device: a scripted cursor touches T1's spinous process from behind, holds the
// button and moves 63 mm posteriorly; the hook takes T1 and the recorded T1 moves posteriorly.
TEST(CliView, TheMouseHooksT1AndTheSpineFollows) {
  if (!have_xvfb()) GTEST_SKIP() << "xvfb-run missing (apt-get install xvfb)";
  const std::string script = tmp("drag_t1.csv"), rec = tmp("drag_t1_rec.csv");
  // T1's spinous process tip of the generated spine is at (0, 531.5, -90.1) mm.
  std::ofstream(script) << "t_s,x_mm,y_mm,z_mm,button\n0,0,531.5,-130,0\n2.0,0,531.5,-130,0\n"
                           "3.0,0,531.5,-87,0\n3.5,0,531.5,-87,1\n4.0,0,531.5,-87,1\n"
                           "6.0,0,531.5,-150,1\n";
  const CliRun r = run_spinesim(
      "view --spine multirate --no-realtime --no-panel --width 400 "
      "--height 500 --json --screenshot-at 6.5 --screenshot '" +
          tmp("drag_t1.png") + "' --cursor-script '" + script + "' --record '" + rec + "'",
      xvfb("640x600"));
  ASSERT_EQ(r.status, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["device"], "mouse") << j["device"];
  EXPECT_GT(j["compliant_stage"]["hooked_ticks"].get<int>(), 1000);
  EXPECT_GT(j["compliant_stage"]["max_spine_force_n"].get<double>(), 50);
  // The recording's last row: T1's centre displacement.
  std::ifstream in(rec);
  std::string line, header, last;
  while (std::getline(in, line)) {
    if (line.empty() || line[0] == '#') continue;
    if (header.empty())
      header = line;
    else
      last = line;
  }
  const auto column = [](const std::string& row, int i) {
    std::stringstream ss(row);
    std::string cell;
    for (int k = 0; k <= i; ++k) std::getline(ss, cell, ',');
    return std::stod(cell);
  };
  std::stringstream hs(header);
  std::string name;
  int tz = -1;
  for (int i = 0; std::getline(hs, name, ','); ++i)
    if (name == "T1_tz_mm") tz = i;
  ASSERT_GE(tz, 0) << header;
  ASSERT_FALSE(last.empty());
  EXPECT_LT(column(last, tz), -5) << "T1 did not move posteriorly";
}

// A series the program could have written: a tet "disc" whose top moves over three frames and a
// triangle "vertebra"; played back paused at the last frame it shows both; a field the series
// lacks is refused naming those it has; a time outside it is refused.
TEST(CliView, ASeriesPlaysBack) {
  namespace sm = spinesim::mesh;
  const std::string dir = tmp("series");
  std::filesystem::create_directories(dir);
  sm::TetMesh m;
  m.V.resize(4, 3);
  m.V << -20, 0, -20, 20, 0, -20, 0, 0, 20, 0, 30, 0;
  m.T.resize(1, 4);
  m.T << 0, 1, 2, 3;
  if (sm::tet_volume(m, 0) < 0) std::swap(m.T(0, 1), m.T(0, 2));
  m.surface = Eigen::VectorXi::Zero(4);
  m.region = Eigen::VectorXi::Ones(1);
  sm::TriSurface v{m.V.array() - 40, Eigen::MatrixX3i(3, 3)};
  v.F << 0, 1, 2, 0, 1, 3, 1, 2, 3;
  std::vector<sm::PvdEntry> entries;
  for (int f = 0; f < 3; ++f) {
    Eigen::MatrixXd u = Eigen::MatrixXd::Zero(4, 3);
    u(3, 1) = -2.0 * f;
    sm::TetMesh moved = m;
    moved.V += u;
    const std::string name = "d" + std::to_string(f) + ".vtu";
    sm::write_vtu(dir + "/" + name, moved, {{"displacement", u}},
                  {{"volume_change", Eigen::MatrixXd::Constant(1, 1, -0.01 * f)}});
    sm::write_surface_vtu(dir + "/v" + std::to_string(f) + ".vtu", v);
    entries.push_back({0.5 * f, name, 0});
    entries.push_back({0.5 * f, "v" + std::to_string(f) + ".vtu", 1});
  }
  sm::write_pvd(dir + "/s.pvd", entries);
  if (have_xvfb()) {
    const std::string png = tmp("series.png");
    const CliRun r = run_spinesim("view --play '" + dir + "/s.pvd' --at 1 --paused --json " +
                                      "--field volume_change --width 320 --height 240 --no-panel "
                                      "--screenshot '" +
                                      png + "'",
                                  xvfb("640x480"));
    ASSERT_EQ(r.status, 0) << r.err;
    const auto j = nlohmann::json::parse(r.out);
    EXPECT_EQ(j["series"]["times"], 3);
    EXPECT_EQ(j["series"]["last_s"], 1.0);
    EXPECT_EQ(j["series"]["fields"], nlohmann::json({"displacement", "volume_change"}));
    const Image im = load_png(png);
    ASSERT_TRUE(im.rgb);
    int bone = 0, blue = 0;  // the vertebra; the tet at the diverging map's cold end (-0.02)
    for (int y = 0; y < im.height; ++y)
      for (int x = 0; x < im.width; ++x) {
        const unsigned char* p = im.at(x, y);
        bone += p[0] > 90 && p[0] > p[2] + 20;
        blue += p[2] > 70 && p[2] > p[0] + 40;
      }
    EXPECT_GT(bone, 50);
    EXPECT_GT(blue, 50);
  }
  expect_refused(run_spinesim("view --play '" + dir + "/s.pvd' --field stress"),
                 "displacement, volume_change");
  expect_refused(run_spinesim("view --play '" + dir + "/s.pvd' --at 5"), "outside");
  expect_refused(run_spinesim("view --play '" + dir + "/absent.pvd'"), "no such file");
}

TEST(CliView, TheMouseIsTheViewersDevice) {
  expect_refused(run_spinesim("haptics run --device mouse"), "spinesim view --device mouse");
  expect_refused(run_spinesim("view --field pressure"), "displacement, spring_strain");
}

// A device that cannot be opened: the missing library before the window opens, the vendor's
// own error (the fake HD library finds no device) once the session has started; one line each.
TEST(CliView, ADeviceThatCannotOpenIsOneLine) {
  expect_refused(
      run_spinesim("view --scene plane --device openhaptics --sdk-lib /nonexistent/libHD.so"),
      "cannot load /nonexistent/libHD.so");
  if (!have_xvfb()) GTEST_SKIP() << "xvfb-run missing (apt-get install xvfb)";
  const CliRun r =
      run_spinesim("view --scene plane --no-realtime --device openhaptics --sdk-lib '" +
                       std::string(SPINESIM_FAKE_HD) + "' --screenshot '" + tmp("never.png") + "'",
                   xvfb("640x480", "FAKE_HAPTIC_FAIL_INIT=1 "));
  EXPECT_EQ(r.status, 1) << r.err;
  EXPECT_EQ(count_lines(r.err), 1) << r.err;
  EXPECT_NE(r.err.find("fake HD: no device found"), std::string::npos) << r.err;
  EXPECT_FALSE(std::filesystem::exists(tmp("never.png")));
}

// A vendor device (the fake OpenHaptics library's scripted stylus presses the plane): the viewer
// shows what the servo loop does — contact, the force arrow. The fake's stylus reaches the plane
// about 2.3 s after the device opens (z = 50 - 20 t mm, probe 4 mm), so the run lasts 4 s: at
// 2 s it sometimes ended before contact, when the session's set-up was quick. `--view front`:
// the stylus comes from the plane's front (+z), the side the camera looks from.
TEST(CliView, AVendorDeviceShowsWhatTheLoopDoes) {
  if (!have_xvfb()) GTEST_SKIP() << "xvfb-run missing (apt-get install xvfb)";
  const std::string png = tmp("hd.png");
  const CliRun r = run_spinesim(
      "view --scene plane --no-realtime --no-panel --device openhaptics "
      "--sdk-lib '" +
          std::string(SPINESIM_FAKE_HD) +
          "' --view front --duration 4 --json --screenshot-at 3.5 --width 480 "
          "--height 360 --screenshot '" +
          png + "'",
      xvfb("640x480"));
  ASSERT_EQ(r.status, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["device"], "openhaptics");
  EXPECT_GT(j["contact_ticks"].get<int>(), 500);
  const Image im = load_png(png);
  ASSERT_TRUE(im.rgb);
  EXPECT_GT(magenta_pixels(im), 20);
}

// Mesa made to offer OpenGL 3.0 only: no 3.3 core context, one line.
TEST(CliView, AnOpenGLBelow33IsOneLine) {
  if (!have_xvfb()) GTEST_SKIP() << "xvfb-run missing (apt-get install xvfb)";
  const CliRun r =
      run_spinesim("view --device none --triangles 300 --screenshot '" + tmp("old_gl.png") + "'",
                   xvfb("640x480", "MESA_GL_VERSION_OVERRIDE=3.0 "));
  EXPECT_EQ(r.status, 1) << r.err;
  EXPECT_EQ(count_lines(r.err), 1) << r.err;
  EXPECT_NE(r.err.find("no OpenGL 3.3 core context"), std::string::npos) << r.err;
}

TEST(CliView, NoDisplayIsOneLineAndNonZero) {
  const CliRun r = run_spinesim("view --triangles 300", "env -u DISPLAY -u WAYLAND_DISPLAY ");
  EXPECT_NE(r.status, 0);
  EXPECT_EQ(count_lines(r.err), 1) << r.err;
  EXPECT_NE(r.err.find("no display"), std::string::npos) << r.err;
}

TEST(CliView, BadOptionsAreRefused) {
  expect_refused(run_spinesim("view --width 10 --screenshot x.png"), "64 to 8192");
  expect_refused(run_spinesim("view --scene nowhere"), "scene");
}

}  // namespace
}  // namespace spinesim::test_cli

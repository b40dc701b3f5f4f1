// `spinesim view`: a screenshot of the spine under Xvfb (Mesa's software renderer) shows the spine
// where the camera puts it, and a missing display is one line and a non-zero exit.
#include "cli_runner.hpp"

#include <gtest/gtest.h>
#include <stb_image.h>

#include <filesystem>
#include <memory>

namespace spinesim::test_cli {
namespace {

bool have_xvfb() { return std::system("command -v xvfb-run >/dev/null 2>&1") == 0; }

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
      "xvfb-run -a -s '-screen 0 640x600x24' ");
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

// The OpenHaptics HD and Force Dimension DHD backends against fake vendor libraries built by
// the tests (the same C functions, scripted motion, recorded forces): units and axes, the
// vendor's error text on a failed open, a device error mid-run (the force goes to zero), and
// a missing or wrong library refused in one line.
#include "spinesim/haptics/device.hpp"
#include "spinesim/haptics/servo.hpp"

#include <gtest/gtest.h>

#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <thread>

namespace sh = spinesim::haptics;

namespace {

std::string log_path(const std::string& name) {
  const auto dir =
      std::filesystem::path(SPINESIM_TEST_TMP) / ("vendor-" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  return (dir / name).string();
}

// The fake's force log: one (frame, fx, fy, fz) per line.
std::vector<std::array<double, 4>> read_log(const std::string& path) {
  std::vector<std::array<double, 4>> rows;
  std::ifstream in(path);
  std::array<double, 4> r;
  while (in >> r[0] >> r[1] >> r[2] >> r[3]) rows.push_back(r);
  return rows;
}

struct Env {
  explicit Env(const std::string& log, const char* fail_init = "0", const char* fail_at = "-1") {
    ::setenv("FAKE_HAPTIC_LOG", log.c_str(), 1);
    ::setenv("FAKE_HAPTIC_FAIL_INIT", fail_init, 1);
    ::setenv("FAKE_HAPTIC_FAIL_AT", fail_at, 1);
  }
  ~Env() {
    ::unsetenv("FAKE_HAPTIC_LOG");
    ::unsetenv("FAKE_HAPTIC_FAIL_INIT");
    ::unsetenv("FAKE_HAPTIC_FAIL_AT");
  }
};

const sh::DeviceCapabilities& touch() { return sh::device_model("touch"); }

}  // namespace

TEST(OpenHaptics, ReadsTheSchedulersStateAndSendsTheForce) {
  const std::string log = log_path("hd.log");
  const Env env(log);
  auto d = sh::make_openhaptics_device(touch(), SPINESIM_FAKE_HD);
  d->open();
  sh::DeviceState s;
  for (int i = 0; i < 200; ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
    ASSERT_TRUE(d->read(s));
    ASSERT_TRUE(d->write_force(Eigen::Vector3d(0.25, -0.5, 1.0)));
  }
  // The fake moves x = 30 sin(2 pi t), y = 0, z = 50 - 20 t (mm): the HD frame is ours.
  EXPECT_EQ(s.position_mm.y(), 0.0);
  EXPECT_GT(s.position_mm.z(), 40.0);
  EXPECT_LT(s.position_mm.z(), 50.0);
  const double t = (50.0 - s.position_mm.z()) / 20.0;
  EXPECT_NEAR(s.position_mm.x(), 30 * std::sin(2 * M_PI * t), 1e-6);
  EXPECT_NEAR(s.velocity_mm_s.z(), -20.0, 1e-12);
  d->close();
  const auto rows = read_log(log);
  ASSERT_GT(rows.size(), 50u);
  bool saw_force = false;
  for (const auto& r : rows) saw_force |= r[1] == 0.25 && r[2] == -0.5 && r[3] == 1.0;
  EXPECT_TRUE(saw_force);
  EXPECT_EQ(rows.back()[1], 0.0);  // closing zeroes the force first
  EXPECT_EQ(rows.back()[3], 0.0);
}

TEST(OpenHaptics, InitFailureGivesTheVendorsText) {
  const Env env(log_path("hd_init.log"), "1");
  auto d = sh::make_openhaptics_device(touch(), SPINESIM_FAKE_HD);
  try {
    d->open();
    FAIL() << "opened";
  } catch (const std::runtime_error& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("fake HD: no device found"), std::string::npos) << what;
    EXPECT_NE(what.find("0x0302"), std::string::npos) << what;
    EXPECT_EQ(what.find('\n'), std::string::npos);
  }
}

TEST(OpenHaptics, DeviceErrorMidRunStopsTheLoopWithZeroForce) {
  const std::string log = log_path("hd_fault.log");
  const Env env(log, "0", "100");
  auto d = sh::make_openhaptics_device(touch(), SPINESIM_FAKE_HD);
  d->open();
  sh::Scene scene;
  scene.add_body("wall", sh::square_plane(200, 10));
  sh::TripleBuffer<sh::ScenePoses> poses{sh::ScenePoses{}};
  sh::ProxyParameters pp;
  pp.radius_mm = 4;
  sh::SphereProxyRenderer proxy(pp);
  sh::ServoOptions so;
  so.duration_s = 2;
  so.realtime_priority = false;
  sh::ServoLoop loop(*d, proxy, scene, poses, sh::SafetyOptions::for_device(touch()), so);
  const auto stats = loop.run([&](const sh::ServoStatus&, double now) {
    sh::ScenePoses p;
    p.time_s = now;
    poses.write(p);
  });
  EXPECT_TRUE(stats.error);
  EXPECT_EQ(stats.stop_reason, "device error");
  EXPECT_LT(stats.seconds, 1.0);
  EXPECT_NE(d->last_error().find("fake HD: device fault"), std::string::npos) << d->last_error();
  d->close();
  const auto rows = read_log(log);
  ASSERT_FALSE(rows.empty());
  EXPECT_EQ(rows.back()[1], 0.0);
  EXPECT_EQ(rows.back()[2], 0.0);
  EXPECT_EQ(rows.back()[3], 0.0);
}

TEST(Dhd, ConvertsUnitsAndAxes) {
  const std::string log = log_path("dhd.log");
  const Env env(log);
  auto d = sh::make_dhd_device(sh::device_model("omega.3"), SPINESIM_FAKE_DHD);
  d->open();
  sh::DeviceState s;
  ASSERT_TRUE(d->read(s));
  // DHD (x towards the user, y right, z up) in m: (0.05, 0, 0.01) → ours (0, 10, 50) mm.
  EXPECT_NEAR((s.position_mm - Eigen::Vector3d(0, 10, 50)).norm(), 0, 1e-9);
  EXPECT_NEAR(s.velocity_mm_s.z(), -20.0, 1e-9);  // DHD vx = -0.02 m/s
  ASSERT_TRUE(d->write_force(Eigen::Vector3d(1, 2, 3)));
  d->close();
  const auto rows = read_log(log);
  ASSERT_GE(rows.size(), 2u);
  EXPECT_EQ(rows[0][1], 3.0);  // DHD x = our z
  EXPECT_EQ(rows[0][2], 1.0);  // DHD y = our x
  EXPECT_EQ(rows[0][3], 2.0);  // DHD z = our y
  EXPECT_EQ(rows.back()[1], 0.0);
}

TEST(Dhd, InitFailureAndMidRunErrorAndNaN) {
  {
    const Env env(log_path("dhd_init.log"), "1");
    auto d = sh::make_dhd_device(sh::device_model("omega.3"), SPINESIM_FAKE_DHD);
    EXPECT_THROW(
        {
          try {
            d->open();
          } catch (const std::runtime_error& e) {
            EXPECT_NE(std::string(e.what()).find("fake DHD: no device found"), std::string::npos);
            throw;
          }
        },
        std::runtime_error);
  }
  const std::string log = log_path("dhd_fault.log");
  const Env env(log, "0", "10");
  auto d = sh::make_dhd_device(sh::device_model("omega.3"), SPINESIM_FAKE_DHD);
  d->open();
  sh::DeviceState s;
  int good = 0;
  while (d->read(s)) {
    ++good;
    d->write_force(Eigen::Vector3d(0.5, 0.5, std::nan("")));  // a NaN never reaches the device
  }
  EXPECT_EQ(good, 10);
  EXPECT_NE(d->last_error().find("communication error"), std::string::npos);
  d->close();
  const auto rows = read_log(log);
  for (const auto& r : rows)
    EXPECT_TRUE(std::isfinite(r[1]) && std::isfinite(r[2]) && std::isfinite(r[3]));
  EXPECT_EQ(rows.back()[1], 0.0);
}

TEST(VendorBackends, MissingOrWrongLibraryIsOneLine) {
  for (auto make : {&sh::make_openhaptics_device, &sh::make_dhd_device}) {
    auto d = make(touch(), "/nonexistent/libvendor.so");
    try {
      d->open();
      FAIL() << "opened";
    } catch (const std::runtime_error& e) {
      const std::string what = e.what();
      EXPECT_NE(what.find("cannot load /nonexistent/libvendor.so"), std::string::npos) << what;
      EXPECT_EQ(what.find('\n'), std::string::npos);
    }
  }
  auto wrong = sh::make_openhaptics_device(touch(), SPINESIM_FAKE_DHD);
  try {
    wrong->open();
    FAIL() << "opened";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("lacks hdInitDevice"), std::string::npos) << e.what();
  }
  EXPECT_TRUE(sh::probe_openhaptics(SPINESIM_FAKE_HD).loaded);
  const auto dhd = sh::probe_dhd(SPINESIM_FAKE_DHD);
  EXPECT_TRUE(dhd.loaded);
  EXPECT_EQ(dhd.devices, 1);
  EXPECT_FALSE(sh::probe_dhd("/nonexistent/libdhd.so").loaded);
}

TEST(VendorBackends, MappedDeviceTurnsPositionsAndForces) {
  const Env env(log_path("dhd_map.log"));
  // Seen from behind the patient: 180° about the vertical, centred at (0, 100, -50).
  const Eigen::Matrix3d R = Eigen::Vector3d(-1, 1, -1).asDiagonal();
  auto d = sh::map_device(sh::make_dhd_device(sh::device_model("omega.3"), SPINESIM_FAKE_DHD), R,
                          Eigen::Vector3d(0, 100, -50));
  d->open();
  sh::DeviceState s;
  ASSERT_TRUE(d->read(s));
  EXPECT_NEAR((s.position_mm - Eigen::Vector3d(0, 110, -100)).norm(), 0, 1e-9);
  d->close();
}

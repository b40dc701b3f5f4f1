// spinesim haptics run | devices, study haptic-plane, mesh vertebrae: the contract (JSON keys,
// a recording that replays), and bad input refused in one line with nothing written.
#include "cli_runner.hpp"

#include <nlohmann/json.hpp>

#include <cmath>
#include <csignal>
#include <fstream>
#include <sstream>
#include <vector>

using namespace spinesim::test_cli;

namespace {

std::string write_file(const std::string& name, const std::string& text) {
  const std::string path = tmp(name);
  std::ofstream(path) << text;
  return path;
}

// The rows of a haptic recording as numbers (comment and header lines skipped).
std::vector<std::vector<double>> recording_rows(const std::string& path) {
  std::ifstream in(path);
  std::vector<std::vector<double>> rows;
  for (std::string line; std::getline(in, line);) {
    if (line.empty() || line[0] == '#' || line[0] == 't') continue;
    std::vector<double> row;
    std::stringstream cells(line);
    for (std::string cell; std::getline(cells, cell, ',');) row.push_back(std::stod(cell));
    rows.push_back(row);
  }
  return rows;
}

}  // namespace

TEST(CliHaptics, PlaneRunReportsTheLoopsStatisticsAndRecordsAReplayableRun) {
  const std::string rec = tmp("plane_rec.csv");
  const auto r = run_spinesim("haptics run --scene plane --device sim --duration 2 --record '" +
                              rec + "' --json");
  ASSERT_EQ(r.status, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  for (const char* key :
       {"ticks", "rate_hz", "period_us", "compute_us", "missed_deadlines", "max_force_n",
        "clamped_ticks", "contact_ticks", "passivity_energy_mj", "realtime_priority"})
    EXPECT_TRUE(j.contains(key)) << key;
  for (const char* key : {"p50", "p99", "p999", "max"}) {
    EXPECT_TRUE(j["period_us"].contains(key));
    EXPECT_TRUE(j["compute_us"].contains(key));
  }
  EXPECT_TRUE(j["realtime_priority"].contains("reason"));
  EXPECT_LE(j["max_force_n"].get<double>(), j["peak_force_n"].get<double>());
  EXPECT_GE(j["passivity_energy_mj"]["min"].get<double>(), -1e-6);
  const int ticks = j["ticks"].get<int>();
  EXPECT_EQ(j["recorded_rows"].get<int>(), ticks);
  const auto rows = recording_rows(rec);
  ASSERT_EQ(int(rows.size()), ticks);
  // The run stops after its 2 s of wall time. A stalled host costs ticks (the loop catches up at
  // most 10 periods), so the count is bounded, not exact.
  EXPECT_LE(ticks, 2001);
  EXPECT_GT(ticks, 1000);
  EXPECT_GE(rows.back()[0], 2.0);
  EXPECT_LT(rows.back()[0], 2.1);
  // The sim hand's script advances one period a tick: press_plane.csv lowers the probe (radius
  // 4 mm) from z = 20 to 1 mm over its first second, so it touches the plane at 16/19 s of ticks
  // (plus the hand's lag), whatever the host did, and stays on it.
  std::size_t first = 0;
  while (first < rows.size() && rows[first][11] == 0) ++first;
  ASSERT_LT(first, rows.size());
  EXPECT_NEAR(rows[first][12] * 1e-3, 16.0 / 19.0, 0.01);
  EXPECT_EQ(j["contact_ticks"].get<int>(), ticks - int(first));

  // The replay plays the recorded hand in the recording's own (wall) time, one period a tick.
  const auto replay =
      run_spinesim("haptics run --scene plane --device replay --replay '" + rec + "' --json");
  ASSERT_EQ(replay.status, 0) << replay.err;
  const auto k = nlohmann::json::parse(replay.out);
  const double contact_s = rows.back()[0] - rows[first][0];
  // A tick that misses its deadline skips that period of the recording (a loaded machine).
  EXPECT_NEAR(k["contact_ticks"].get<double>(), contact_s / 1e-3,
              20 + 2 * k["missed_deadlines"].get<double>());
}

// A hostile trajectory runs on any scene: the plane pressed by a 30 Hz shake and swept at 2.5 m/s.
TEST(CliHaptics, HostileTrajectoriesRunAndReportTheTicksWork) {
  for (const std::string name : {"shake", "sweep"}) {
    const auto r = run_spinesim("haptics run --scene plane --device sim --script hostile:" + name +
                                " --no-realtime --spin-us 0 --json --quiet");
    ASSERT_EQ(r.status, 0) << r.err;
    const auto j = nlohmann::json::parse(r.out);
    EXPECT_EQ(j["script"], "hostile:" + name);
    EXPECT_GT(j["contact_ticks"].get<int>(), 20) << name;
    EXPECT_GT(j["max_render_work"].get<int>(), 0) << name;
    EXPECT_LE(j["max_render_work"].get<int>(), 4096) << name;
    EXPECT_LE(j["max_force_n"].get<double>(), j["peak_force_n"].get<double>() * (1 + 1e-12));
    // The machine's floor was measured beside the loop, over the same run.
    ASSERT_TRUE(j["floor"].is_object()) << name;
    EXPECT_GE(j["floor"]["wakeups"].get<int>(), j["ticks"].get<int>() / 2) << name;
    EXPECT_LE(j["floor"]["late"].get<int>(), j["floor"]["wakeups"].get<int>()) << name;
  }
  const auto off = run_spinesim(
      "haptics run --scene plane --device sim --duration 0.2 --no-floor --no-realtime --json");
  ASSERT_EQ(off.status, 0) << off.err;
  EXPECT_TRUE(nlohmann::json::parse(off.out)["floor"].is_null());
}

TEST(CliHaptics, VendorBackendRunsAgainstTheFakeLibraryAndReportsAFault) {
  const std::string hd = SPINESIM_FAKE_HD;
  const auto r = run_spinesim("haptics run --scene plane --device openhaptics --sdk-lib '" + hd +
                              "' --duration 0.5 --no-realtime --json");
  ASSERT_EQ(r.status, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  // The loop ran for its duration at no more than 1 kHz; how many of the 500 ticks a loaded,
  // shared machine lets it keep is the machine's, measured by the floor, not asserted here.
  EXPECT_GT(j["ticks"].get<int>(), 0);
  EXPECT_LE(j["ticks"].get<int>(), 550);
  EXPECT_EQ(j["stop_reason"], "duration");
  const auto fault = run_spinesim("haptics run --scene plane --device openhaptics --sdk-lib '" +
                                      hd + "' --duration 2 --no-realtime --json",
                                  "FAKE_HAPTIC_FAIL_AT=200 ");
  EXPECT_EQ(fault.status, 1);
  EXPECT_EQ(count_lines(fault.err), 1) << fault.err;
  EXPECT_NE(fault.err.find("fake HD: device fault"), std::string::npos) << fault.err;
  EXPECT_EQ(
      nlohmann::json::parse(fault.out)["stop_reason"].get<std::string>().rfind("device error", 0),
      0u);
  const auto devices =
      run_spinesim("haptics devices --json --dhd-lib '" + std::string(SPINESIM_FAKE_DHD) + "'");
  ASSERT_EQ(devices.status, 0) << devices.err;
  const auto d = nlohmann::json::parse(devices.out);
  EXPECT_EQ(d["backends"][4]["name"], "dhd");
  EXPECT_TRUE(d["backends"][4]["available"].get<bool>());
  EXPECT_EQ(d["backends"][4]["devices"], 1);
  EXPECT_FALSE(d["backends"][3]["available"].get<bool>());  // no libHD.so on this machine
}

// Ctrl-C during a run with a device in hand: the loop ends with the force at zero (the fake
// vendor library records what it was sent), the summary is printed, the recording is kept
// whole, and the program exits by the signal.
TEST(CliHaptics, CtrlCZeroesTheForceAndKeepsTheRecording) {
  const std::string log = tmp("ctrl_c_forces.log"), rec = tmp("ctrl_c_rec.csv");
  const pid_t pid = start_spinesim(
      "haptics run --scene plane --device openhaptics --sdk-lib '" + std::string(SPINESIM_FAKE_HD) +
          "' --view front --duration 30 --no-realtime --record '" + rec + "'",
      "FAKE_HAPTIC_LOG='" + log + "' ");
  // The fake device reaches the plane after 2.3 s and presses on: wait for 3.5 s of frames.
  for (int k = 0; k < 200 && count_lines(slurp(log)) < 3500; ++k) ::usleep(50000);
  ASSERT_GE(count_lines(slurp(log)), 3500);
  ::kill(pid, SIGINT);
  int status = 0;
  ::waitpid(pid, &status, 0);
  ASSERT_TRUE(WIFSIGNALED(status)) << status;
  EXPECT_EQ(WTERMSIG(status), SIGINT);
  EXPECT_NE(slurp((tmp_dir() / "bg.stdout").string()).find("stopped: interrupted"),
            std::string::npos);
  std::istringstream forces(slurp(log));
  double frame, fx, fy, fz, largest = 0, last = -1;
  while (forces >> frame >> fx >> fy >> fz) {
    last = std::sqrt(fx * fx + fy * fy + fz * fz);
    largest = std::max(largest, last);
  }
  EXPECT_GT(largest, 0.1);  // it was pressing
  EXPECT_EQ(last, 0.0);     // and let go
  const std::string recording = slurp(rec);
  EXPECT_GT(count_lines(recording), 3000);
  for (const auto& e : fs::directory_iterator(tmp_dir()))
    EXPECT_EQ(e.path().string().find(".partial-"), std::string::npos) << e.path();
}

TEST(CliHaptics, DevicesListsBackendsAndModels) {
  const auto r = run_spinesim("haptics devices --json");
  ASSERT_EQ(r.status, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["models"].size(), 6u);
  EXPECT_EQ(j["backends"][0]["name"], "sim");
  int with_torque = 0;
  for (const auto& m : j["models"]) {
    EXPECT_FALSE(m["source"].get<std::string>().empty());
    if (m["torque_axes"].get<int>() == 3) {
      ++with_torque;
      EXPECT_TRUE(m["senses_orientation"].get<bool>());
      EXPECT_GE(m["peak_torque_nmm"].get<double>(), m["continuous_torque_nmm"].get<double>());
      EXPECT_GT(m["continuous_torque_nmm"].get<double>(), 0);
    }
  }
  EXPECT_EQ(with_torque, 2);  // sigma.7, premium-1.5-6dof (the omega.6's wrist is not driven)
}

TEST(CliHaptics, PlaneStudyReproducesTheThesisFindings) {
  const std::string csv = tmp("plane.csv");
  const auto r = run_spinesim("study haptic-plane --out '" + csv + "' --json");
  ASSERT_EQ(r.status, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_NEAR(j["small_peak_depth_eq49_mm"].get<double>(), j["small_radius_mm"].get<double>(), 0.1);
  EXPECT_NEAR(j["large_peak_depth_eq49_mm"].get<double>(), j["large_radius_mm"].get<double>(), 0.1);
  EXPECT_TRUE(j["large_higher_everywhere_eq49"].get<bool>());
  EXPECT_NEAR(j["ratio_at_small_peak_eq410"].get<double>(), 1.0, 0.01);
  EXPECT_TRUE(j["small_higher_before_peak_eq410"].get<bool>());
  EXPECT_NE(slurp(csv).find("depth_mm,small_eq49_n"), std::string::npos);
}

TEST(CliHaptics, BadInputIsRefusedInOneLineWithNothingWritten) {
  const std::string nan_script = write_file("nan.csv", "t_s,x_mm,y_mm,z_mm\n0,0,0,10\n1,nan,0,0\n");
  const std::string backwards = write_file("back.csv", "0,0,0,10\n1,0,0,5\n0.5,0,0,0\n");
  const auto before = files_in(tmp_dir());
  const std::string rec = tmp_dir().string() + "/never.csv";
  const std::string base = "haptics run --scene plane --duration 1 --record '" + rec + "' ";
  expect_refused(run_spinesim(base + "--device joystick"), "unknown");
  expect_refused(run_spinesim(base + "--device openhaptics --sdk-lib /nonexistent/libHD.so"),
                 "cannot load /nonexistent/libHD.so");
  expect_refused(run_spinesim(base + "--device dhd --sdk-lib /nonexistent/libdhd.so"),
                 "cannot load /nonexistent/libdhd.so");
  expect_refused(run_spinesim(base + "--device openhaptics --sdk-lib '" + SPINESIM_FAKE_HD + "'",
                              "FAKE_HAPTIC_FAIL_INIT=1 "),
                 "fake HD: no device found");
  expect_refused(run_spinesim(base + "--device sim --sdk-lib x.so"), "--sdk-lib");
  expect_refused(run_spinesim(base + "--probe-radius 0"), "--probe-radius");
  expect_refused(run_spinesim(base + "--probe-radius -3"), "--probe-radius");
  expect_refused(run_spinesim(base + "--script '" + nan_script + "'"), "not a finite number");
  expect_refused(run_spinesim(base + "--script '" + backwards + "'"), "not after the previous");
  expect_refused(run_spinesim(base + "--script /nonexistent.csv"), "cannot read");
  expect_refused(run_spinesim(base + "--script /dev/zero"), "not a regular file");
  expect_refused(run_spinesim(base + "--script '" + tmp_dir().string() + "'"), "a directory");
  expect_refused(run_spinesim(base + "--script hostile:wobble"), "no such hostile trajectory");
  expect_refused(run_spinesim(base + "--renderer magic"), "--renderer");
  expect_refused(run_spinesim(base + "--scene moon"), "--scene");
  expect_refused(run_spinesim(base + "--vertebrae /nonexistent.json"), "--vertebrae");
  expect_refused(run_spinesim(base + "--model falcon"), "unknown device model");
  expect_refused(run_spinesim(base + "--device replay"), "--replay");
  expect_refused(run_spinesim("haptics run --scene plane --record /nonexistent/dir/r.csv"),
                 "does not exist");
  expect_refused(run_spinesim("mesh vertebrae --level C3 --out '" + tmp("vv") + "'"),
                 "unknown vertebra");
  expect_refused(run_spinesim("mesh vertebrae --triangles 5 --out '" + tmp("vw") + "'"),
                 "--triangles");
  expect_refused(run_spinesim("study haptic-plane --radius 0"), "radius");
  EXPECT_TRUE(new_files(before).empty());
}

TEST(CliHaptics, MeshVertebraeWritesClosedSurfaces) {
  const std::string dir = tmp("vertebrae");
  const auto r =
      run_spinesim("mesh vertebrae --level L4,S1 --triangles 2000 --out '" + dir + "' --json");
  ASSERT_EQ(r.status, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  ASSERT_EQ(j["bodies"].size(), 2u);
  for (const auto& b : j["bodies"]) {
    EXPECT_TRUE(b["closed"].get<bool>());
    EXPECT_TRUE(b["oriented"].get<bool>());
    EXPECT_TRUE(fs::exists(b["file"].get<std::string>()));
  }
}

// The compliant stage from the command line: a scripted drag of T1 hooks, loads the spine and
// records every vertebra; a run killed mid-drag (SIGKILL: nothing can clean up) leaves a
// recording whose every complete row is whole; bad compliant-stage input is refused.
TEST(CliHaptics, DragOfT1RecordsTheSpineAndAKilledRunLeavesReadableRows) {
  const std::string rec = tmp("drag_rec.csv");
  const std::string script = std::string(SPINESIM_DATA_DIR) + "/haptics/drag_t1_lateral.csv";
  const auto r = run_spinesim(
      "haptics run --scene spine --triangles 1500 --spine multirate "
      "--script '" +
      script + "' --duration 3 --no-realtime --record '" + rec + "' --json");
  ASSERT_EQ(r.status, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  const auto& c = j["compliant_stage"];
  EXPECT_EQ(c["spine"], "multirate");
  EXPECT_GT(c["hooked_ticks"].get<int>(), 1500);  // the button is held from 1.0 s
  EXPECT_GT(c["max_spine_force_n"].get<double>(), 20.0);
  EXPECT_GT(c["worker_solves"].get<int>(), 5);
  EXPECT_EQ(c["worker_failures"].get<int>(), 0);
  const std::string text = slurp(rec);
  EXPECT_NE(text.find("# spine model "), std::string::npos);
  EXPECT_NE(text.find("L5_rz_deg"), std::string::npos);
  EXPECT_NE(text.find("# end: "), std::string::npos);

  // The offline discs of that drag: a ParaView series python3-meshio reads, frame by frame.
  const std::string out = tmp("drag_discs");
  const auto d = run_spinesim("spine discs --record '" + rec + "' --out '" + out +
                              "' --vertebra-triangles 150 --frame-period 0.1 --json");
  ASSERT_EQ(d.status, 0) << d.err;
  const auto dj = nlohmann::json::parse(d.out);
  // One step per recorded tick after the first (a loaded machine runs fewer than 3000 ticks).
  EXPECT_EQ(dj["steps"].get<long>(), j["recorded_rows"].get<long>() - 1);
  EXPECT_EQ(dj["discs"].get<int>(), 17);
  EXPECT_GT(dj["speedup_over_real_time"].get<double>(), 0);
  ASSERT_EQ(dj["per_disc"].size(), 17u);
  EXPECT_GT(dj["per_disc"][0]["peak_rotation_deg"].get<double>(), 0.1);  // T1-T2 bends
  for (const auto& disc : dj["per_disc"]) {
    EXPECT_EQ(disc["inverted_tets_max"].get<int>(), 0) << disc["level"];
    EXPECT_EQ(disc["rejected_steps"].get<int>(), 0) << disc["level"];
  }
  if (std::system("/usr/bin/python3 -c 'import meshio' >/dev/null 2>&1") == 0) {
    const std::string script = tmp("read_pvd.py");
    std::ofstream(script)
        << "import sys, os, meshio, xml.etree.ElementTree as ET\n"
           "p = sys.argv[1]\n"
           "sets = ET.parse(p).getroot().find('Collection').findall('DataSet')\n"
           "kinds = set()\n"
           "for s in sets:\n"
           "    m = meshio.read(os.path.join(os.path.dirname(p), s.get('file')))\n"
           "    kinds.add((s.get('part'), tuple(sorted(m.cells_dict))))\n"
           "print(len(sets), sorted(kinds))\n";
    const std::string read_out = tmp("read_pvd.out");
    const std::string py =
        "/usr/bin/python3 '" + script + "' '" + out + "/spine.pvd' > '" + read_out + "' 2>&1";
    ASSERT_EQ(std::system(py.c_str()), 0) << slurp(read_out);
    const int frames = dj["frames"].get<int>();
    EXPECT_EQ(slurp(read_out),
              std::to_string(2 * frames) + " [('0', ('tetra',)), ('1', ('triangle',))]\n");
  }

  const std::string killed = tmp("drag_killed.csv");
  const pid_t pid = start_spinesim(
      "haptics run --scene spine --triangles 1500 --spine multirate "
      "--script '" +
      script + "' --no-realtime --record '" + killed + "'");
  for (int k = 0; k < 600 && count_lines(slurp(killed)) < 1500; ++k) ::usleep(50000);
  ::kill(pid, SIGKILL);
  int status = 0;
  ::waitpid(pid, &status, 0);
  const std::string part = slurp(killed);
  ASSERT_GT(count_lines(part), 1000);
  EXPECT_EQ(part.find("# end: "), std::string::npos);
  // Every complete data row has all 132 columns (13 + 11 hook + 6 × 17 vertebrae).
  std::istringstream rows(part);
  std::string line;
  int complete = 0;
  while (std::getline(rows, line)) {
    if (rows.eof()) break;  // a last row without its newline may be cut
    if (line.empty() || line[0] == '#' || line[0] == 't') continue;
    EXPECT_EQ(std::count(line.begin(), line.end(), ','), 125) << line.substr(0, 60);
    ++complete;
  }
  EXPECT_GT(complete, 1000);
}

// 6-DOF from the command line: the shipped twist script on a simulated sigma.7 turns the hooked
// T1 about the long axis, the hand feels the spine's moment as a torque within the device's
// peak, the recording carries the stylus's turn and the moments, and replaying it twists the
// spine the same way; a device without torque motors, or the database, says why nothing twists.
TEST(CliHaptics, SixDofTwistOfT1IsFeltAsATorqueAndItsRecordingReplays) {
  const std::string rec = tmp("twist_rec.csv");
  const std::string script = std::string(SPINESIM_DATA_DIR) + "/haptics/twist_t1_axial.csv";
  const std::string common =
      "haptics run --scene spine --triangles 1500 --spine multirate "
      "--model sigma.7 --no-realtime --json ";
  const auto r = run_spinesim(common + "--script '" + script + "' --record '" + rec + "'");
  ASSERT_EQ(r.status, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  const auto& six = j["six_dof"];
  ASSERT_TRUE(six.is_object());
  EXPECT_EQ(six["torque_axes"].get<int>(), 3);
  const double peak = six["peak_torque_nmm"].get<double>();
  EXPECT_GT(six["max_torque_nmm"].get<double>(), 30.0);
  EXPECT_LE(six["max_torque_nmm"].get<double>(), peak);
  const auto& c = j["compliant_stage"];
  EXPECT_GT(c["rotational_stiffness_nmm_per_rad"].get<double>(), 0);
  EXPECT_LE(c["rotational_stiffness_nmm_per_rad"].get<double>(),
            c["rotational_passive_limit_nmm_per_rad"].get<double>());
  const double moment = c["max_spine_moment_nmm"].get<double>();
  EXPECT_GT(moment, 1000.0);  // N·mm on T1
  EXPECT_GE(j["passivity_energy_mj"]["min"].get<double>(), -1.0);
  // The recording: T1 turned about y the way the stylus did; the stylus's turn and the moments
  // are columns.
  std::ifstream in(rec);
  std::string header;
  while (std::getline(in, header) && header[0] == '#') {}
  EXPECT_NE(header.find(",rx_deg,ry_deg,rz_deg,tx_nmm,ty_nmm,tz_nmm,spine_mx_nmm"),
            std::string::npos);
  const auto rows = recording_rows(rec);
  ASSERT_GT(rows.size(), 3000u);
  const std::size_t columns = rows[0].size();
  ASSERT_EQ(columns, 135u);  // 13 + 11 hook + 6 x 17 vertebrae + turn, torque and moment
  double t1_turn = 0, stylus_turn = 0;
  for (const auto& row : rows) {
    t1_turn = std::max(t1_turn, row[24 + 4]);  // T1_ry_deg
    stylus_turn = std::max(stylus_turn, row[columns - 8]);
  }
  EXPECT_GT(stylus_turn, 20.0);
  EXPECT_GT(t1_turn, 1.0);
  EXPECT_LT(t1_turn, stylus_turn);
  // Replayed: the device follows the recorded turn and the hook twists the spine again.
  const auto again = run_spinesim(common + "--device replay --replay '" + rec + "'");
  ASSERT_EQ(again.status, 0) << again.err;
  const auto ja = nlohmann::json::parse(again.out);
  EXPECT_NEAR(ja["compliant_stage"]["max_spine_moment_nmm"].get<double>(), moment, 0.25 * moment);
  // No torque motors, or a response without moments: nothing twists, and the run says why.
  const auto omega = run_spinesim(
      "haptics run --scene spine --triangles 1500 --spine multirate --model omega.6 "
      "--no-realtime --duration 0.5 --script '" +
      script + "'");
  ASSERT_EQ(omega.status, 0) << omega.err;
  EXPECT_NE(omega.out.find("no torque motors"), std::string::npos) << omega.out;
  const auto bad = run_spinesim(
      "haptics run --scene spine --triangles 1500 --spine multirate --model sigma.7 "
      "--no-realtime --duration 0.5 --rotational-stiffness 5000 --script '" +
      script + "'");
  EXPECT_NE(bad.status, 0);
  EXPECT_NE(bad.err.find("passive limit"), std::string::npos) << bad.err;
}

TEST(CliHaptics, OfflineDiscsRefuseBadInputInOneLineWithNothingWritten) {
  const std::string out = tmp("never_discs");
  const std::string plane = tmp("plane_only.csv");
  ASSERT_EQ(run_spinesim("haptics run --scene plane --device sim --duration 0.2 --no-realtime "
                         "--record '" +
                         plane + "'")
                .status,
            0);
  expect_refused(run_spinesim("spine discs --record '" + plane + "' --out '" + out + "'"),
                 "not a compliant-stage recording");
  expect_refused(run_spinesim("spine discs --record /nonexistent.csv --out '" + out + "'"),
                 "nonexistent");
  EXPECT_FALSE(fs::exists(out));
}

// Disc palpation: the scripted press of the L4-L5 disc runs; the budget check's choice and the
// disc thread's statistics are reported; the recording carries the disc's contact, force and
// volume change; the loop stays passive; bad disc input is refused in one line.
TEST(CliHaptics, DiscPalpationPressesTheTunedDiscAndRecordsItsResponse) {
  const std::string rec = tmp("disc_rec.csv");
  const auto r = run_spinesim(
      "haptics run --scene disc --level L4-L5 --triangles 1500 --no-realtime --disc-cell-size 4 "
      "--record '" +
      rec + "' --json");
  ASSERT_EQ(r.status, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  const auto& d = j["disc_palpation"];
  ASSERT_TRUE(d.is_object()) << r.out.substr(0, 400);
  EXPECT_EQ(d["level"], "L4-L5");
  EXPECT_GT(d["tets"].get<long>(), 1000);
  EXPECT_FALSE(d["cpu"].get<std::string>().empty());
  ASSERT_EQ(d["budget_check"].size(), 1u);  // the asked resolution, measured
  EXPECT_EQ(d["tets"].get<long>(), d["budget_check"][0]["tets"].get<long>());
  EXPECT_GT(d["steps"].get<long>(), 100);  // the disc thread ran (its rate is the machine's)
  EXPECT_EQ(d["failed_steps"].get<long>(), 0);
  EXPECT_EQ(d["solver"], "multirate");
  EXPECT_EQ(d["period_ms"].get<double>(), 10.0);
  EXPECT_GT(d["rate_hz"].get<double>(), 50.0);
  // The disc meets the hand's force times the scale (100 N at the Touch's 3.3 N peak).
  EXPECT_NEAR(d["force_scale"].get<double>(), 100 / 3.3, 0.1);
  EXPECT_GT(d["max_load_n"].get<double>(), 5.0);
  EXPECT_GT(d["max_indentation_mm"].get<double>(), 0.3);  // visibly indented
  EXPECT_TRUE(d["sync_check"].is_null());
  EXPECT_LT(d["volume_change"]["min"].get<double>(), 0.0);
  EXPECT_GE(j["passivity_energy_mj"]["min"].get<double>(), 0.0);
  const std::string text = slurp(rec);
  const auto header = text.find("t_s,");
  ASSERT_NE(header, std::string::npos);
  EXPECT_NE(text.find("disc_volume_change,disc_indentation_mm", header), std::string::npos);
  // Some row has the disc in contact with a non-zero force.
  std::istringstream rows(text.substr(header));
  std::string line;
  std::getline(rows, line);
  int pressed = 0;
  while (std::getline(rows, line)) {
    if (line.empty() || line[0] == '#') continue;
    std::vector<double> v;
    std::stringstream ss(line);
    for (std::string c; std::getline(ss, c, ',');) v.push_back(std::stod(c));
    ASSERT_EQ(v.size(), 22u);  // 13 common + 9 disc columns
    if (v[13] == 1 && std::hypot(v[17], v[18], v[19]) > 0.1 && v[21] > 0) ++pressed;
  }
  EXPECT_GT(pressed, 100);
}

TEST(CliHaptics, MultirateDiscFollowsTheSynchronousSolve) {
  // The shipped press (4 mm past the anterior wall) on a coarse disc; after the run the hand's
  // path goes through the disc stepped every 1 ms off the clock.
  const auto r = run_spinesim(
      "haptics run --scene disc --level L4-L5 --triangles 1500 --no-realtime --disc-cell-size 4 "
      "--disc-sync-check --json --quiet");
  ASSERT_EQ(r.status, 0) << r.err;
  const auto d = nlohmann::json::parse(r.out)["disc_palpation"];
  const auto& s = d["sync_check"];
  ASSERT_TRUE(s.is_object()) << d.dump();
  EXPECT_EQ(s["ticks"].get<long>(), nlohmann::json::parse(r.out)["ticks"].get<long>());
  EXPECT_GT(s["peak_force_n"].get<double>(), 5.0);
  // A shared machine: a late worker step makes the felt force lag; a few % of the peak at most.
  EXPECT_LT(s["relative_rms_error"].get<double>(), 0.05) << s.dump();
}

TEST(CliHaptics, TheFemDiscIsPalpatedOnTheWorkerAndFollowsTheSynchronousSolve) {
  // The linear FEM disc itself on the coarse mesh: the same press, the same check; its coupling
  // damped by k_c T / 2 unless told otherwise, and the run passive.
  const auto r = run_spinesim(
      "haptics run --scene disc --level L4-L5 --disc-model fem --triangles 1500 --no-realtime "
      "--disc-cell-size 4 --disc-sync-check --json --quiet");
  ASSERT_EQ(r.status, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  const auto d = j["disc_palpation"];
  EXPECT_EQ(d["model"].get<std::string>(), "linear FEM");
  EXPECT_EQ(d["failed_steps"].get<long>(), 0);
  EXPECT_GT(d["max_indentation_mm"].get<double>(), 0.1);
  EXPECT_NEAR(d["coupling_damping_n_s_per_mm"].get<double>(),
              0.5e-3 * d["coupling_stiffness_n_per_mm"].get<double>(), 1e-12);
  const auto& s = d["sync_check"];
  ASSERT_TRUE(s.is_object()) << d.dump();
  EXPECT_GT(s["peak_force_n"].get<double>(), 5.0);
  EXPECT_LT(s["relative_rms_error"].get<double>(), 0.05) << s.dump();
  EXPECT_GE(j["passivity_energy_mj"]["min"].get<double>(), -1e-6);
}

TEST(CliHaptics, BadDiscInputIsRefused) {
  const std::string rec = tmp("never_disc.csv");
  const std::string base = "haptics run --duration 1 --record '" + rec + "' ";
  expect_refused(run_spinesim(base + "--scene disc --level L9-L10"), "L9-L10");
  expect_refused(run_spinesim(base + "--scene spine --disc-budget-us 300"), "--scene disc");
  // Nothing steps within 1 us: the run still starts, on the coarsest disc, and says so.
  const auto slow = run_spinesim(
      "haptics run --duration 0.3 --scene disc --disc-solver direct --disc-budget-us 1 "
      "--triangles 300 --json --quiet");
  ASSERT_EQ(slow.status, 0) << slow.err;
  const auto disc = nlohmann::json::parse(slow.out)["disc_palpation"];
  EXPECT_NE(disc["note"].get<std::string>().find("no resolution fits"), std::string::npos);
  EXPECT_EQ(disc["cell_size_mm"].get<double>(),
            disc["budget_check"].back()["cell_size_mm"].get<double>());
  for (const auto& c : disc["budget_check"]) EXPECT_FALSE(c["fits"].get<bool>());
  expect_refused(run_spinesim(base + "--scene disc --disc-cell-size 0.1"), "--disc-cell-size");
  expect_refused(run_spinesim(base + "--scene disc --disc-solver sometimes"), "--disc-solver");
  expect_refused(run_spinesim(base + "--scene disc --disc-model hex"), "--disc-model");
  expect_refused(run_spinesim(base + "--scene spine --disc-model fem"), "--scene disc");
  expect_refused(run_spinesim(base + "--scene disc --disc-period-ms 20"), "--disc-period-ms");
  expect_refused(run_spinesim(base + "--scene disc --disc-solver direct --disc-sync-check"),
                 "multirate");
  expect_refused(run_spinesim(base + "--scene disc --force-scale 0.5"), "--force-scale");
  expect_refused(run_spinesim(base + "--scene disc --force-scale 1000"), "1000 N");
  expect_refused(run_spinesim(base + "--scene plane --disc-sync-check"), "--scene disc");
  // A tuned set without the level.
  const std::string set = tmp("one_level.json");
  {
    auto j = nlohmann::json::parse(slurp(std::string(SPINESIM_DATA_DIR) + "/tuned_discs.json"));
    for (auto it = j["levels"].begin(); it != j["levels"].end();)
      it = it.key() == "T7-T8" ? std::next(it) : j["levels"].erase(it);
    std::ofstream(set) << j.dump();
  }
  expect_refused(run_spinesim(base + "--scene disc --level L4-L5 --params '" + set + "'"), "L4-L5");
  EXPECT_FALSE(fs::exists(rec));
}

TEST(CliHaptics, BadCompliantStageInputIsRefused) {
  const std::string rec = tmp("never_drag.csv");
  const std::string base = "haptics run --duration 1 --record '" + rec + "' ";
  expect_refused(run_spinesim(base + "--scene plane --spine multirate"), "--scene spine");
  expect_refused(run_spinesim(base + "--scene spine --spine magic"), "--spine");
  expect_refused(run_spinesim(base + "--scene spine --spine database --force-scale 1000"),
                 "beyond the 600 N");
  expect_refused(run_spinesim(base + "--scene plane --force-scale 10"), "--spine");
  // A body is the spine scene's: elsewhere, out of range or unknown it is refused.
  expect_refused(run_spinesim(base + "--scene disc --subject p5-female"), "--scene spine");
  expect_refused(run_spinesim(base + "--scene plane --body-height 1.6"), "--scene spine");
  expect_refused(run_spinesim(base + "--scene spine --body-height 2.6"), "height");
  expect_refused(run_spinesim(base + "--scene spine --subject giant"), "p95-male");
  EXPECT_FALSE(fs::exists(rec));
}

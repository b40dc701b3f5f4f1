// The hybrid spine offline: the shipped structured tuned set fits every level's structured disc
// (and a set fitted on other meshes is refused); a still spine leaves every disc at rest; pressing
// T1 down moves only the T1-T2 disc, by the recorded amount, and its reaction matches a static
// solve of that disc; the ParaView series has a disc and a vertebra part per frame.
#include "spinesim/calibration/tuned_set.hpp"
#include "spinesim/haptics/recording.hpp"
#include "spinesim/mss/boundary.hpp"
#include "spinesim/mss/solver.hpp"
#include "spinesim/spine/kinematics.hpp"
#include "spinesim/spine/scoliosis.hpp"
#include "spinesim/studies/spine_discs.hpp"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>

namespace st = spinesim::studies;
namespace sp = spinesim::spine;
namespace sh = spinesim::haptics;
namespace cal = spinesim::calibration;
namespace fs = std::filesystem;
namespace mss = spinesim::mss;

namespace {

const sp::SpineModel& model() {
  static const sp::SpineModel m = sp::load_spine_model(SPINESIM_DATA_DIR);
  return m;
}

const cal::TunedSet& structured_set() {
  static const cal::TunedSet s =
      cal::read_tuned_set(std::string(SPINESIM_DATA_DIR) + "/tuned_structured_discs.json");
  return s;
}

fs::path scratch(const std::string& name) {
  const fs::path dir =
      fs::path(SPINESIM_TEST_TMP) / ("spine-discs-" + std::to_string(::getpid())) / name;
  fs::create_directories(dir.parent_path());
  return dir;
}

/// n ticks in which vertebra `moved` (-1: none) is translated by `shift(k)` (mm, reference
/// frame); the others stay at the reference posture.
template <class Shift>
std::string recording(const std::string& name, int n, int moved, Shift shift) {
  std::vector<sh::TickRecord> rows(static_cast<std::size_t>(n));
  for (int k = 0; k < n; ++k) {
    sh::TickRecord& r = rows[std::size_t(k)];
    r.t_s = 1e-3 * k;
    r.tick = k + 1;
    r.probe_mm = r.force_n = r.proxy_mm = Eigen::Vector3d::Zero();
    r.compliant = true;
    for (int i = 0; i < 17; ++i) {
      const Eigen::Vector3d t = i == moved ? Eigen::Vector3d(shift(k)) : Eigen::Vector3d::Zero();
      const sp::Pose p = sp::pose_from_displacement(model().vertebrae[std::size_t(i)].centre_mm, t,
                                                    Eigen::Vector3d::Zero());
      r.R[std::size_t(i)] = p.R.cast<float>();
      r.t[std::size_t(i)] = p.t.cast<float>();
    }
  }
  const std::string path = scratch(name).string();
  spinesim::haptics::HapticRecordingWriter w(path, "test", &model(), "multirate");
  w.append(rows.data(), rows.size());
  w.finish();
  return path;
}

/// Rows of disc_motion.csv for one level: {t, dx, dy, dz, rx, ry, rz, dV, inverted, F, M}.
std::vector<std::vector<double>> motion_rows(const std::string& csv, const std::string& level) {
  std::ifstream in(csv);
  std::string line;
  std::vector<std::vector<double>> out;
  while (std::getline(in, line)) {
    if (line.empty() || line[0] == '#' || line[0] == 't') continue;
    std::stringstream ss(line);
    std::string cell, lv;
    std::getline(ss, cell, ',');
    std::vector<double> row = {std::stod(cell)};
    std::getline(ss, lv, ',');
    while (std::getline(ss, cell, ',')) row.push_back(std::stod(cell));
    if (lv == level) out.push_back(row);
  }
  return out;
}

}  // namespace

TEST(SpineDiscs, ShippedStructuredSetFitsEveryLevelsStructuredDisc) {
  const st::SpineDiscs d = st::build_spine_discs(model(), structured_set());
  ASSERT_EQ(d.models.size(), 17u);
  EXPECT_EQ(d.levels.front(), "T1-T2");
  EXPECT_EQ(d.upper.front(), 0);
  EXPECT_EQ(d.lower.front(), 1);
  EXPECT_EQ(d.levels.back(), "L5-S1");
  EXPECT_EQ(d.upper.back(), 16);
  EXPECT_EQ(d.lower.back(), -1);  // the sacrum
  for (const auto& m : d.models) EXPECT_EQ(m.mesh().num_tets(), 360);
}

TEST(SpineDiscs, ASetFittedOnOtherMeshesOrMissingALevelIsRefused) {
  const cal::TunedSet fine =
      cal::read_tuned_set(std::string(SPINESIM_DATA_DIR) + "/tuned_discs.json");
  try {
    st::build_spine_discs(model(), fine);
    ADD_FAILURE() << "a CGAL-mesh set was accepted for the structured discs";
  } catch (const std::invalid_argument& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("fitted on another mesh"), std::string::npos) << what;
    EXPECT_NE(what.find("--structured"), std::string::npos) << what;
  }
  cal::TunedSet partial = structured_set();
  partial.levels.erase("T9-T10");
  try {
    st::build_spine_discs(model(), partial);
    ADD_FAILURE() << "a set without T9-T10 was accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("T9-T10"), std::string::npos) << e.what();
  }
}

// The discs are meshed at the resolution the set records: the shipped linear set's 12 x 3 x 2
// entries do not fit a 16-sector disc, and the refusal names the resolution simulated.
TEST(SpineDiscs, TheSetsRecordedResolutionIsTheMeshSimulated) {
  EXPECT_EQ(st::build_spine_discs(model(), structured_set()).resolution,
            "12 sectors x 3 rings x 2 layers");
  cal::TunedSet other = structured_set();
  other.settings["structured"] = {{"sectors", 16}, {"rings", 3}, {"layers", 2}};
  try {
    st::build_spine_discs(model(), other);
    ADD_FAILURE() << "12-sector entries were accepted for 16-sector discs";
  } catch (const std::invalid_argument& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("fitted on another mesh"), std::string::npos) << what;
    EXPECT_NE(what.find("16 sectors x 3 rings x 2 layers"), std::string::npos) << what;
  }
}

TEST(SpineDiscs, ParamsNameAShippedSetOrAFile) {
  const std::string data = SPINESIM_DATA_DIR;
  EXPECT_EQ(st::spine_discs_params_path("", data), data + "/tuned_structured_discs.json");
  EXPECT_EQ(st::spine_discs_params_path("real-disc", data), data + "/tuned_structured_discs.json");
  EXPECT_EQ(st::spine_discs_params_path("fibre-reinforced", data),
            data + "/tuned_structured_fibre_discs.json");
  const std::string file = data + "/tuned_discs.json";
  EXPECT_EQ(st::spine_discs_params_path(file, data), file);
  try {
    st::spine_discs_params_path("fibre", data);
    ADD_FAILURE() << "an unknown name was taken for a file";
  } catch (const std::invalid_argument& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("real-disc, fibre-reinforced"), std::string::npos) << what;
  }
}

TEST(SpineDiscs, StillSpineLeavesEveryDiscAtRest) {
  st::SpineDiscsRequest rq;
  rq.recording = recording("still.csv", 40, -1, [](int) { return Eigen::Vector3d::Zero(); });
  rq.out = scratch("still-out").string();
  rq.frame_period_s = 0.01;
  rq.vertebra_triangles = 150;
  const st::SpineDiscsResult r = st::run_spine_discs(rq, SPINESIM_DATA_DIR);
  EXPECT_EQ(r.steps, 39);
  EXPECT_EQ(r.discs, 17);
  for (const auto& p : r.peaks) {
    EXPECT_LT(p.compression_mm, 1e-9) << p.level;
    EXPECT_LT(p.force_n, 1e-6) << p.level;
    EXPECT_LT(std::abs(p.volume_change_min), 1e-12) << p.level;
    EXPECT_EQ(p.inverted_tets, 0) << p.level;
    EXPECT_EQ(p.rejected_steps, 0) << p.level;
  }
  // Two parts per frame, every frame file there.
  std::ifstream pvd(r.pvd);
  std::stringstream text;
  text << pvd.rdbuf();
  const std::string s = text.str();
  int part0 = 0, part1 = 0;
  for (std::size_t at = s.find("part=\""); at != std::string::npos; at = s.find("part=\"", at + 1))
    (s[at + 6] == '0' ? part0 : part1)++;
  EXPECT_EQ(part0, r.frames);
  EXPECT_EQ(part1, r.frames);
  EXPECT_GE(r.frames, 4);
  EXPECT_TRUE(fs::exists(r.table_csv));
  EXPECT_TRUE(fs::exists(fs::path(rq.out) / "spine" / "spine_000001.vtu"));
}

// Both shipped sets: the linear calibration, and the fibre networks of the nonlinear disc (whose
// frozen steps are line-searched, mss/README.md).
class SpineDiscsPress : public ::testing::TestWithParam<const char*> {};

TEST_P(SpineDiscsPress, PressingT1DownCompressesOnlyT1T2AsAStaticSolveDoes) {
  const std::string params = GetParam();
  const st::SpineDiscs d = st::build_spine_discs(
      model(), cal::read_tuned_set(st::spine_discs_params_path(params, SPINESIM_DATA_DIR)));
  const Eigen::Vector3d axis = d.models[0].mesh().frame.axes.col(1);  // T1-T2's axial direction
  const double depth = 0.1;                                           // mm
  st::SpineDiscsRequest rq;
  rq.recording = recording("press.csv", 300, 0, [&](int k) {
    return Eigen::Vector3d(-depth * std::min(1.0, k / 50.0) * axis);
  });
  rq.tuned = params;
  rq.out = scratch("press-out-" + params).string();
  rq.frame_period_s = 0.01;
  rq.vertebra_triangles = 0;
  const st::SpineDiscsResult r = st::run_spine_discs(rq, SPINESIM_DATA_DIR);
  EXPECT_NEAR(r.peaks[0].compression_mm, depth, 1e-4);  // float poses in the recording
  EXPECT_LT(r.peaks[0].shear_mm, 1e-4);
  EXPECT_GT(r.peaks[0].force_n, 10.0);
  for (std::size_t i = 1; i < r.peaks.size(); ++i) {
    EXPECT_LT(r.peaks[i].compression_mm, 1e-9) << r.peaks[i].level;
    EXPECT_LT(r.peaks[i].force_n, 1e-6) << r.peaks[i].level;
  }
  // 250 ms after the press the disc has settled: its reaction is the static solve's.
  mss::Boundary bc;
  bc.superior.translation_mm = -depth * axis;
  bc.plate_center_mm = mss::default_plate_center(d.models[0].mesh());
  const mss::StaticResult s = mss::solve_static(d.models[0], bc);
  ASSERT_TRUE(s.converged);
  const auto rows = motion_rows(r.motion_csv, "T1-T2");
  ASSERT_FALSE(rows.empty());
  const std::vector<double>& last = rows.back();
  const Eigen::Vector3d f(last[9], last[10], last[11]);  // disc axes
  const Eigen::Matrix3d& A = d.models[0].mesh().frame.axes;
  const Eigen::Vector3d f_static = A.transpose() * s.reaction_wrench.head<3>();
  EXPECT_NEAR(f.y(), f_static.y(), 1e-3 * std::abs(f_static.y()));  // 1e-5 measured
  EXPECT_NEAR(last[2], -depth, 1e-4);                               // dy: the axis shortened
}

INSTANTIATE_TEST_SUITE_P(ShippedSets, SpineDiscsPress,
                         ::testing::Values("real-disc", "fibre-reinforced"), [](const auto& info) {
                           return std::string(info.param) == "real-disc" ? "Linear" : "Fibre";
                         });

TEST(SpineDiscs, ShippedFibreSetIsMeshedAtItsOwnFinerResolution) {
  const cal::TunedSet set =
      cal::read_tuned_set(cal::shipped_structured_fibre_tuned_set_path(SPINESIM_DATA_DIR));
  const st::SpineDiscs d = st::build_spine_discs(model(), set);
  EXPECT_EQ(d.resolution, "24 sectors x 4 rings x 4 layers");
  ASSERT_EQ(d.models.size(), 17u);
  for (const auto& m : d.models) {
    EXPECT_EQ(m.mesh().num_tets(), 2016);
    EXPECT_GT(m.num_fibre_springs(), 0);
  }
}

// A scoliotic spine's discs rest wedged in its curve: every disc's endplates sit on its
// vertebrae's rest poses (the straight disc's endplates carried by them), and its axis is turned
// halfway between them. A recording of that spine says so in its header, and a still one leaves
// every disc at rest: the wedged discs are stress-free in the curve.
TEST(SpineDiscs, AScolioticSpinesDiscsRestWedgedInItsCurve) {
  sp::ModelOptions o;
  o.scoliosis = sp::scoliosis_curve("lumbar", 30);
  const sp::SpineModel curved = sp::load_spine_model(SPINESIM_DATA_DIR, o);
  ASSERT_GT(curved.rest_posture.size(), 0);
  const std::vector<sp::Pose> P = sp::vertebra_poses(curved, curved.rest_posture);
  const st::SpineDiscs straight = st::build_spine_discs(model(), structured_set());
  const st::SpineDiscs wedged = st::build_spine_discs(curved, structured_set());
  ASSERT_EQ(wedged.models.size(), straight.models.size());
  double largest_wedge = 0;
  for (std::size_t i = 0; i < wedged.models.size(); ++i) {
    const auto& a = straight.models[i].mesh();
    const auto& b = wedged.models[i].mesh();
    const int up = wedged.upper[i], low = wedged.lower[i];
    auto pose = [&](int v) { return v < 0 ? sp::Pose() : P[std::size_t(v)]; };
    int plates = 0;
    for (Eigen::Index k = 0; k < a.V.rows(); ++k) {
      const int s = a.surface(k);
      if (s != int(spinesim::mesh::Surface::superior_endplate) &&
          s != int(spinesim::mesh::Surface::inferior_endplate))
        continue;
      const sp::Pose p = pose(s == int(spinesim::mesh::Surface::superior_endplate) ? up : low);
      EXPECT_LT((b.V.row(k).transpose() - (p.R * a.V.row(k).transpose() + p.t)).norm(), 1e-9)
          << wedged.levels[i] << " node " << k;
      ++plates;
    }
    EXPECT_GT(plates, 20) << wedged.levels[i];
    const double turn =
        std::acos(std::clamp(b.frame.axes.col(1).dot(a.frame.axes.col(1)), -1.0, 1.0));
    largest_wedge = std::max(largest_wedge, turn);
  }
  EXPECT_GT(largest_wedge * 180 / M_PI, 2);  // a 30 deg curve over a few joints

  // The recording carries the curve; a still one leaves the wedged discs at rest.
  std::vector<sh::TickRecord> rows(20);
  for (int k = 0; k < 20; ++k) {
    sh::TickRecord& r = rows[std::size_t(k)];
    r.t_s = 1e-3 * k;
    r.tick = k + 1;
    r.probe_mm = r.force_n = r.proxy_mm = Eigen::Vector3d::Zero();
    r.compliant = true;
    for (int i = 0; i < 17; ++i) r.R[std::size_t(i)].setIdentity(), r.t[std::size_t(i)].setZero();
  }
  st::SpineDiscsRequest rq;
  rq.recording = scratch("curved-still.csv").string();
  {
    sh::HapticRecordingWriter w(rq.recording, "test", &curved, "multirate");
    w.append(rows.data(), rows.size());
    w.finish();
  }
  const sh::RecordedSpine rs = sh::recording_spine(rq.recording);
  EXPECT_EQ(rs.scoliosis.type, "lumbar");
  EXPECT_EQ(rs.scoliosis.cobb_deg, 30);
  EXPECT_EQ(rs.scoliosis.apex, o.scoliosis.apex);
  EXPECT_EQ(rs.scoliosis.convex_right, o.scoliosis.convex_right);
  EXPECT_NE(sh::spine_model_fingerprint(curved), sh::spine_model_fingerprint(model()));
  // A malformed curve line, or a curve the model cannot pose, is refused.
  for (const std::string& line :
       {std::string("# scoliosis: type lumbar, cobb_deg 30, upper_end T12, apex L2, lower_end L4, "
                    "apical_rotation_deg 0, convex up"),
        std::string("# scoliosis: type lumbar, cobb_deg 500, upper_end T12, apex L2, lower_end "
                    "L4, apical_rotation_deg 0, convex left")}) {
    const std::string bad = scratch("curved-bad.csv").string();
    std::ifstream in(rq.recording);
    std::ofstream o(bad);
    std::string l;
    while (std::getline(in, l)) o << (l.rfind("# scoliosis: ", 0) == 0 ? line : l) << "\n";
    o.close();
    EXPECT_THROW(sh::recording_spine(bad), std::invalid_argument) << line;
  }
  rq.out = scratch("curved-still-out").string();
  rq.vertebra_triangles = 0;
  const st::SpineDiscsResult r = st::run_spine_discs(rq, SPINESIM_DATA_DIR);
  for (const auto& p : r.peaks) {
    EXPECT_LT(p.force_n, 1e-6) << p.level;
    EXPECT_LT(std::abs(p.volume_change_min), 1e-12) << p.level;
    EXPECT_EQ(p.rejected_steps, 0) << p.level;
  }
}

TEST(SpineDiscs, BadRequestsAreRefusedBeforeAnythingIsWritten) {
  const std::string rec =
      recording("short.csv", 5, -1, [](int) { return Eigen::Vector3d::Zero(); });
  auto refused = [&](st::SpineDiscsRequest rq, const std::string& needle) {
    try {
      st::run_spine_discs(rq, SPINESIM_DATA_DIR);
      ADD_FAILURE() << "accepted; expected: " << needle;
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find(needle), std::string::npos) << e.what();
    }
    EXPECT_FALSE(fs::exists(rq.out)) << rq.out;
  };
  st::SpineDiscsRequest rq;
  rq.recording = rec;
  rq.out = scratch("never").string();
  st::SpineDiscsRequest bad = rq;
  bad.frame_period_s = 0;
  refused(bad, "--frame-period");
  bad = rq;
  bad.threads = -1;
  refused(bad, "--threads");
  bad = rq;
  bad.vertebra_triangles = 20;
  refused(bad, "--vertebra-triangles");
  bad = rq;
  bad.tuned = std::string(SPINESIM_DATA_DIR) + "/tuned_discs.json";
  refused(bad, "fitted on another mesh");
  bad = rq;  // a folder that cannot be made: a file is in the way
  std::ofstream(scratch("a-file")) << "x";
  bad.out = (scratch("a-file") / "out").string();
  refused(bad, "cannot create the folder");
}

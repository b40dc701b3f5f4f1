// `spinesim calibrate` and the tuned file's use by `spinesim mss` / `mss compare --params`: the
// JSON report, the promise that tuned.json's errors are the ones `mss compare` reproduces, and
// every refusal (exit 1, one line on stderr, no tuned file written). One structured L4-L5 disc
// (360 tets) made once per process, so each calibration takes a fraction of a second.
#include "cli_runner.hpp"

#include "spinesim/mesh/io.hpp"

#include <gtest/gtest.h>
#include <algorithm>
#include <nlohmann/json.hpp>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <sstream>
#include <string>

namespace fs = std::filesystem;
using nlohmann::json;

namespace {

using namespace spinesim::test_cli;

const std::vector<std::string> kTrain = {"compression", "shear-ap", "flexion",
                                         "torsion"};  // the default
const std::vector<std::string> kAllCases = {"compression",     "tension", "shear-ap",
                                            "shear-lat",       "flexion", "extension",
                                            "lateral-bending", "torsion"};

std::string in_quotes(const std::string& path) { return "'" + path + "'"; }

/// A structured disc of `level`, meshed once per process.
const std::string& disc(const std::string& level = "L4-L5") {
  static std::map<std::string, std::string> made;
  auto it = made.find(level);
  if (it != made.end()) return it->second;
  const std::string path = tmp("disc-" + level + ".vtu");
  const CliRun r =
      run_spinesim("mesh disc --level " + level + " --structured --out " + in_quotes(path));
  EXPECT_EQ(r.status, 0) << r.err;
  return made.emplace(level, path).first->second;
}

/// One calibration of disc() per process and flavour: `checked` runs the nonlinear check,
/// `per_spring` the second stage.
struct Calibrated {
  std::string path;  ///< the tuned file
  json printed;      ///< what --json printed
};
const Calibrated& calibrated(bool checked, bool per_spring = false) {
  static std::map<std::pair<bool, bool>, Calibrated> made;
  auto it = made.find({checked, per_spring});
  if (it != made.end()) return it->second;
  Calibrated c;
  c.path = tmp(std::string("tuned") + (per_spring ? "-per-spring" : "") +
               (checked ? "-checked" : "") + ".json");
  const CliRun r = run_spinesim("calibrate --mesh " + in_quotes(disc()) + " --out " +
                                in_quotes(c.path) + " --json" + (checked ? "" : " --no-check") +
                                (per_spring ? " --per-spring" : ""));
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_TRUE(r.err.empty()) << r.err;
  c.printed = json::parse(r.out, nullptr, false);
  return made.emplace(std::make_pair(checked, per_spring), c).first->second;
}

std::vector<std::string> case_names(const json& rows) {
  std::vector<std::string> names;
  for (const auto& r : rows) names.push_back(r.at("name").get<std::string>());
  return names;
}

/// A run refused before it wrote `out`.
void expect_refused_without(const CliRun& r, const std::string& needle, const std::string& out) {
  expect_refused(r, needle);
  EXPECT_FALSE(fs::exists(out)) << out << " was written";
}

}  // namespace

TEST(CalibrateCli, HelpDescribesTheProtocol) {
  const CliRun r = run_spinesim("calibrate --help");
  EXPECT_EQ(r.status, 0);
  for (const char* flag : {"--mesh", "--level", "--train", "--holdout", "--terms", "--out",
                           "--no-check", "--json", "--per-spring", "--smoothness"})
    EXPECT_NE(r.out.find(flag), std::string::npos) << flag;
}

// --json: one object on stdout, the tuned file's contents plus where it went; every case is
// reported untuned and tuned, and the fit beats Van Gelder on what it was trained on.
TEST(CalibrateCli, JsonReportsEveryCaseAndTheFileParses) {
  const Calibrated& c = calibrated(false);
  const json& j = c.printed;
  ASSERT_TRUE(j.is_object()) << "stdout is not one JSON object";
  EXPECT_EQ(j.at("out"), c.path);
  EXPECT_EQ(j.at("mesh_file"), disc());
  EXPECT_EQ(j.at("format"), "spinesim-tuned-disc");
  EXPECT_EQ(j.at("level"), "L4-L5");
  const json& rep = j.at("report");
  EXPECT_EQ(rep.at("ipopt").at("status"), "Solve_Succeeded");
  EXPECT_TRUE(rep.at("ipopt").at("success").get<bool>());

  // Training cases: the default set; held out: every other standard case, each exactly once.
  EXPECT_EQ(case_names(rep.at("train")), kTrain);
  std::set<std::string> seen;
  for (const auto& name : case_names(rep.at("train"))) seen.insert(name);
  for (const auto& name : case_names(rep.at("holdout")))
    EXPECT_TRUE(seen.insert(name).second) << name;
  EXPECT_EQ(seen, std::set<std::string>(kAllCases.begin(), kAllCases.end()));
  for (const char* set : {"train", "holdout"})
    for (const auto& row : rep.at(set)) {
      SCOPED_TRACE(std::string(set) + " " + row.at("name").get<std::string>());
      for (const char* key : {"untuned_error", "tuned_error"}) {
        ASSERT_TRUE(row.contains(key)) << key;
        const double e = row.at(key).get<double>();
        EXPECT_TRUE(std::isfinite(e) && e >= 0) << key << " " << e;
      }
    }
  for (const auto& row : rep.at("train"))
    EXPECT_LT(row.at("tuned_error").get<double>(), row.at("untuned_error").get<double>())
        << row.at("name");

  // The file holds what was printed, minus where it came from and went.
  ASSERT_TRUE(fs::exists(c.path));
  const json file = json::parse(slurp(c.path), nullptr, false);
  ASSERT_FALSE(file.is_discarded()) << "tuned file is not JSON";
  json printed = j;
  printed.erase("out");
  printed.erase("mesh_file");
  EXPECT_EQ(file, printed);
  EXPECT_FALSE(file.at("scales").empty());
  for (const auto& [knob, s] : file.at("scales").items()) EXPECT_GT(s.get<double>(), 0.0) << knob;
}

TEST(CalibrateCli, TrainAndHoldoutAreTheOnesAskedFor) {
  const std::string out = tmp("tuned-subset.json");
  const CliRun r = run_spinesim("calibrate --mesh " + in_quotes(disc()) +
                                " --train compression,flexion --holdout torsion" +
                                " --terms thesis --no-check --json --out " + in_quotes(out));
  ASSERT_EQ(r.status, 0) << r.err;
  const json j = json::parse(r.out);
  EXPECT_EQ(case_names(j["report"]["train"]), (std::vector<std::string>{"compression", "flexion"}));
  EXPECT_EQ(case_names(j["report"]["holdout"]), (std::vector<std::string>{"torsion"}));
  EXPECT_FALSE(j["terms"]["volume_term"].get<bool>());
  EXPECT_EQ(j["scales"].size(), 6u);  // thesis terms: main, radial, torsion per region
  for (const auto& [knob, s] : j["scales"].items())
    EXPECT_EQ(knob.find("volume"), std::string::npos) << knob;
}

// The tuned file's promise: with the nonlinear check, its `tuned_error` per case is what
// `mss compare --params` measures on the same mesh at the check's load scale — and its
// `untuned_error` what plain `mss compare` measures.
TEST(CalibrateCli, TunedErrorsAreWhatMssCompareReproduces) {
  const Calibrated& c = calibrated(true);
  const json& rep = c.printed.at("report");
  ASSERT_EQ(rep.at("ipopt").at("status"), "Solve_Succeeded");
  ASSERT_TRUE(rep.at("check_load_scale").is_number())
      << "the check ran, so its load scale is reported";
  const double load_scale = rep.at("check_load_scale").get<double>();
  std::map<std::string, json> rows;
  for (const char* set : {"train", "holdout"})
    for (const auto& row : rep.at(set)) rows[row.at("name").get<std::string>()] = row;
  ASSERT_EQ(rows.size(), kAllCases.size());

  for (const bool tuned : {true, false}) {
    SCOPED_TRACE(tuned ? "tuned" : "untuned");
    std::ostringstream scale;
    scale.precision(17);
    scale << load_scale;
    const CliRun r = run_spinesim("mss compare --mesh " + in_quotes(disc()) +
                                  (tuned ? " --params " + in_quotes(c.path) : "") +
                                  " --load-scale " + scale.str() + " --json");
    ASSERT_EQ(r.status, 0) << r.err;
    const json j = json::parse(r.out);
    EXPECT_EQ(j.at("mss_constants").get<std::string>().rfind("tuned (", 0) == 0, tuned)
        << j.at("mss_constants");
    ASSERT_EQ(j.at("cases").size(), kAllCases.size());
    for (const auto& cs : j.at("cases")) {
      const std::string name = cs.at("name");
      ASSERT_TRUE(rows.count(name)) << name;
      const double expected = rows[name].at(tuned ? "tuned_error" : "untuned_error").get<double>();
      EXPECT_NEAR(cs.at("displacement_error").get<double>(), expected, 1e-6 * expected) << name;
    }
  }
}

TEST(CalibrateCli, MssWithParamsUsesTheTunedConstants) {
  const Calibrated& c = calibrated(false);
  const CliRun tuned = run_spinesim("mss --mesh " + in_quotes(disc()) + " --params " +
                                    in_quotes(c.path) + " --case compression --json");
  ASSERT_EQ(tuned.status, 0) << tuned.err;
  EXPECT_TRUE(tuned.err.empty()) << tuned.err;
  const json t = json::parse(tuned.out);
  EXPECT_EQ(t.at("mss_constants"), "tuned (" + c.path + ")");
  EXPECT_EQ(t.at("params"), c.path);
  EXPECT_TRUE(t.at("converged").get<bool>());
  EXPECT_EQ(t.at("material"), "real-disc");  // the file's material, not given on the command line
  // The file's terms, not the command line's defaults: the volume term is on.
  EXPECT_TRUE(t.at("options").at("volume_term").get<bool>());
  EXPECT_GT(t.at("springs").at("volume_terms").get<int>(), 0);

  const CliRun untuned =
      run_spinesim("mss --mesh " + in_quotes(disc()) + " --case compression --json");
  ASSERT_EQ(untuned.status, 0) << untuned.err;
  const json u = json::parse(untuned.out);
  EXPECT_EQ(u.at("mss_constants"), "untuned Van Gelder");
  // Same wrench, other stiffness: the plate settles elsewhere.
  const double dy_tuned = t["plate_motion"][1].get<double>(),
               dy_untuned = u["plate_motion"][1].get<double>();
  EXPECT_LT(dy_tuned, 0.0);
  EXPECT_LT(dy_untuned, 0.0);
  EXPECT_GT(std::abs(dy_tuned - dy_untuned), 1e-3 * std::abs(dy_untuned));
}

// A file calibrated with a material JSON file loads without that file: the constants it was
// fitted with are in it.
TEST(CalibrateCli, ParamsFittedWithAMaterialFileLoadWithoutIt) {
  const std::string material = tmp("my-disc.json");
  std::ofstream(material)
      << R"({"name": "my-disc", "E_mpa": 5.0, "nu": 0.42, "density_kg_m3": 1100})";
  const std::string out = tmp("tuned-my-disc.json");
  const CliRun cal = run_spinesim("calibrate --mesh " + in_quotes(disc()) + " --material " +
                                  in_quotes(material) + " --no-check --out " + in_quotes(out));
  ASSERT_EQ(cal.status, 0) << cal.err;
  const CliRun r = run_spinesim("mss --mesh " + in_quotes(disc()) + " --params " + in_quotes(out) +
                                " --case torsion --json");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(json::parse(r.out).at("material"), "my-disc");
  // ... and still refuses the default material when it is asked for.
  expect_refused(run_spinesim("mss --mesh " + in_quotes(disc()) + " --params " + in_quotes(out) +
                              " --material real-disc --case torsion"),
                 "my-disc");
}

// --- calibrate refuses, and writes nothing ------------------------------------------------------

TEST(CalibrateCliRefuses, IpoptNotConverging) {
  const std::string out = tmp("tuned-1-iteration.json");
  const CliRun r = run_spinesim("calibrate --mesh " + in_quotes(disc()) +
                                " --max-iterations 1 --no-check --out " + in_quotes(out));
  EXPECT_EQ(r.status, 1) << r.err;
  EXPECT_EQ(count_lines(r.err), 1) << r.err;
  EXPECT_NE(r.err.find("Ipopt did not converge"), std::string::npos) << r.err;
  EXPECT_NE(r.out.find("Maximum_Iterations_Exceeded"), std::string::npos)
      << r.out;  // the summary says why
  EXPECT_FALSE(fs::exists(out));

  // With --json the object on stdout says so too, and names no output file.
  const CliRun j = run_spinesim("calibrate --mesh " + in_quotes(disc()) +
                                " --max-iterations 1 --no-check --json --out " + in_quotes(out));
  EXPECT_EQ(j.status, 1);
  EXPECT_EQ(count_lines(j.err), 1) << j.err;
  const json printed = json::parse(j.out);
  EXPECT_FALSE(printed["report"]["ipopt"]["success"].get<bool>());
  EXPECT_FALSE(printed.contains("out"));
  EXPECT_FALSE(fs::exists(out));
}

TEST(CalibrateCliRefuses, BadOptions) {
  const std::string out = tmp("tuned-refused.json");
  const std::string mesh = " --mesh " + in_quotes(disc());
  const std::string to = " --out " + in_quotes(out);
  expect_refused_without(
      run_spinesim("calibrate" + mesh + " --lower-scale 2 --upper-scale 0.5" + to), "bounds", out);
  expect_refused_without(run_spinesim("calibrate" + mesh + " --lower-scale 0" + to), "scale", out);
  expect_refused(run_spinesim("calibrate" + mesh), "--out");
  expect_refused_without(run_spinesim("calibrate" + mesh + " --level L4-L5" + to),
                         "--mesh and --level", out);
  expect_refused_without(run_spinesim("calibrate" + to), "--mesh and --level", out);
  expect_refused_without(run_spinesim("calibrate" + mesh + " --terms springs" + to), "--terms",
                         out);
  expect_refused_without(
      run_spinesim("calibrate" + mesh + " --train compression,torsion --holdout torsion" + to),
      "torsion", out);
  expect_refused_without(run_spinesim("calibrate" + mesh + " --train compression,twist" + to),
                         "twist", out);
  expect_refused_without(run_spinesim("calibrate" + mesh + " --order 3" + to), "--order", out);
  // The per-level cell rule is --level all's, without a single --cell-size; refused before meshing.
  expect_refused_without(run_spinesim("calibrate --level L4-L5 --cells-through-height 3" + to),
                         "--level all", out);
  expect_refused_without(run_spinesim("calibrate --level all --cell-size 3 --max-cell-size 4" + to),
                         "--level all", out);
  expect_refused_without(run_spinesim("calibrate --level all --max-cell-size 0.1" + to),
                         "--max-cell-size", out);
  expect_refused_without(run_spinesim("calibrate --level all --cells-through-height 0" + to),
                         "--cells-through-height", out);
  // The structured resolution is the structured disc's; a bad one is refused before meshing.
  expect_refused_without(run_spinesim("calibrate --level L4-L5 --sectors 24" + to), "--structured",
                         out);
  expect_refused_without(run_spinesim("calibrate --level all --structured --rings 1" + to), "rings",
                         out);
  expect_refused_without(run_spinesim("calibrate --level all --structured --sectors 5" + to),
                         "sectors", out);
  expect_refused_without(run_spinesim("calibrate" + mesh + " --material unobtainium" + to),
                         "unobtainium", out);
  expect_refused_without(
      run_spinesim("calibrate --mesh " + in_quotes(tmp("no-such-disc.vtu")) + to), "no-such-disc",
      out);
  expect_refused(
      run_spinesim("calibrate" + mesh + " --out " + in_quotes(tmp("no-such-folder") + "/t.json")),
      "no-such-folder");
}

// A case both trained and held out is refused before any mesh is read or meshed (--level all
// meshes 17 discs): here the mesh does not even exist, and the overlap is what is reported.
TEST(CalibrateCliRefuses, OverlappingCasesBeforeTheMesh) {
  const std::string out = tmp("tuned-overlap.json");
  const CliRun r =
      run_spinesim("calibrate --mesh " + in_quotes(tmp("not-a-disc.vtu")) +
                   " --train compression,torsion --holdout torsion --out " + in_quotes(out));
  expect_refused_without(r, "both trained on and held out", out);
}

TEST(CalibrateCliRefuses, OutputOverTheInputMesh) {
  const std::string mesh = tmp("disc-copy.vtu");
  fs::copy_file(disc(), mesh);
  const std::string before = slurp(mesh);
  expect_refused(
      run_spinesim("calibrate --mesh " + in_quotes(mesh) + " --no-check --out " + in_quotes(mesh)),
      "input mesh");
  EXPECT_EQ(slurp(mesh), before);
}

// --- mss / mss compare refuse a tuned file that does not fit ------------------------------------

TEST(MssParamsRefuses, AnotherMaterial) {
  const std::string params = calibrated(false).path;
  expect_refused(run_spinesim("mss --mesh " + in_quotes(disc()) + " --params " + in_quotes(params) +
                              " --material rubber --case compression"),
                 "rubber");
  expect_refused(run_spinesim("mss compare --mesh " + in_quotes(disc()) + " --params " +
                              in_quotes(params) + " --material rubber --cases compression"),
                 "rubber");
}

TEST(MssParamsRefuses, AMeshOfAnotherLevel) {
  const std::string params = calibrated(false).path;
  const CliRun r = run_spinesim("mss compare --mesh " + in_quotes(disc("L3-L4")) + " --params " +
                                in_quotes(params) + " --cases compression");
  expect_refused(r, "L3-L4");
  EXPECT_NE(r.err.find("L4-L5"), std::string::npos) << r.err;
  expect_refused(run_spinesim("mss --mesh " + in_quotes(disc("L3-L4")) + " --params " +
                              in_quotes(params) + " --case torsion"),
                 "L4-L5");
}

TEST(MssParamsRefuses, ACorruptOrMissingFile) {
  const std::string good = slurp(calibrated(false).path);
  const std::string truncated = tmp("truncated-tuned.json");
  std::ofstream(truncated) << good.substr(0, good.size() / 2);
  expect_refused(run_spinesim("mss --mesh " + in_quotes(disc()) + " --params " +
                              in_quotes(truncated) + " --case compression"),
                 "truncated-tuned.json");
  json j = json::parse(good);
  j["scales"]["torsion.nucleus"] = -1.0;
  const std::string negative = tmp("negative-tuned.json");
  std::ofstream(negative) << j.dump();
  expect_refused(
      run_spinesim("mss compare --mesh " + in_quotes(disc()) + " --params " + in_quotes(negative)),
      "torsion.nucleus");
  expect_refused(run_spinesim("mss --mesh " + in_quotes(disc()) + " --params " + in_quotes(disc()) +
                              " --case compression"),
                 "not valid JSON");  // a mesh given as params
  expect_refused(run_spinesim("mss --mesh " + in_quotes(disc()) + " --params " +
                              in_quotes(tmp("absent.json")) + " --case compression"),
                 "absent.json");
}

TEST(MssParamsRefuses, TermFlagsBesideParams) {
  const std::string params = " --params " + in_quotes(calibrated(false).path);
  for (const char* flag : {"--volume-term", "--disc-volume-term", "--no-radial", "--no-torsion",
                           "--volume-factor 3", "--disc-volume-factor 2"}) {
    SCOPED_TRACE(flag);
    expect_refused(run_spinesim("mss --mesh " + in_quotes(disc()) + params + " " + flag +
                                " --case compression"),
                   "--params");
    expect_refused(run_spinesim("mss compare --mesh " + in_quotes(disc()) + params + " " + flag),
                   "--params");
  }
}

// --- --per-spring: region fit, then one multiplier per main spring --------------------------------

// Both stages reported (region-only beside per-spring, train and holdout, linearised and
// nonlinear), the file is kind per-spring with one multiplier per main spring, and its
// tuned_error is what `mss compare --params` measures on the same mesh.
TEST(CalibrateCliPerSpring, ReportsBothStagesAndMssCompareReproducesThem) {
  const Calibrated& c = calibrated(true, true);
  const json& j = c.printed;
  ASSERT_TRUE(j.is_object());
  EXPECT_EQ(j.at("kind"), "per-spring");
  const std::size_t n = j.at("edge_springs").get<std::size_t>();
  ASSERT_GT(n, 100u);
  ASSERT_EQ(j.at("edge_multipliers").size(), n);
  for (const auto& mu : j.at("edge_multipliers")) {
    EXPECT_GE(mu.get<double>(), 0.1 - 1e-9);
    EXPECT_LE(mu.get<double>(), 10.0 + 1e-9);
  }
  const json& rep = j.at("report");
  EXPECT_TRUE(rep.at("ipopt").at("success").get<bool>());
  const json& ps = rep.at("per_spring");
  EXPECT_TRUE(ps.at("ipopt").at("success").get<bool>()) << ps.at("ipopt");
  EXPECT_EQ(ps.at("edge_springs").get<std::size_t>(), n);
  EXPECT_LE(ps.at("objective").at("final").at("J").get<double>(),
            ps.at("objective").at("start").at("J").get<double>());
  // The start of the second stage is the region fit: same data terms.
  EXPECT_NEAR(ps.at("objective").at("start").at("data").get<double>(),
              rep.at("objective").at("final").at("J").get<double>() -
                  rep.at("weights").at("regularisation").get<double>() *
                      rep.at("objective").at("final").at("regularisation").get<double>(),
              1e-9);
  double region_sum = 0, per_spring_sum = 0;
  for (const char* set : {"train", "holdout"})
    for (const auto& row : rep.at(set)) {
      SCOPED_TRACE(std::string(set) + " " + row.at("name").get<std::string>());
      for (const char* key : {"untuned_error", "region_error", "tuned_error", "region_error_linear",
                              "tuned_error_linear"}) {
        ASSERT_TRUE(row.contains(key)) << key;
        EXPECT_TRUE(std::isfinite(row.at(key).get<double>())) << key;
      }
      if (std::string(set) == "train") {
        region_sum += row.at("region_error_linear").get<double>();
        per_spring_sum += row.at("tuned_error_linear").get<double>();
      }
    }
  EXPECT_LT(per_spring_sum, region_sum);  // more freedom fits the training cases closer
  EXPECT_EQ(rep.at("stiffness_diagonal").at("ratio_region").size(), 6u);

  // The file is what was printed; the region-level scales are in it too.
  const json file = json::parse(slurp(c.path));
  json printed = j;
  printed.erase("out");
  printed.erase("mesh_file");
  EXPECT_EQ(file, printed);
  EXPECT_EQ(file.at("scales").size(), 8u);

  // mss compare --params on the same mesh reproduces the per-spring nonlinear errors.
  std::ostringstream scale;
  scale.precision(17);
  scale << rep.at("check_load_scale").get<double>();
  const CliRun r = run_spinesim("mss compare --mesh " + in_quotes(disc()) + " --params " +
                                in_quotes(c.path) + " --load-scale " + scale.str() + " --json");
  ASSERT_EQ(r.status, 0) << r.err;
  std::map<std::string, double> expected;
  for (const char* set : {"train", "holdout"})
    for (const auto& row : rep.at(set))
      expected[row.at("name")] = row.at("tuned_error").get<double>();
  const json compared = json::parse(r.out);  // named: a range-for over parse(...).at(...) dangles
  for (const auto& cs : compared.at("cases")) {
    const double e = expected.at(cs.at("name").get<std::string>());
    EXPECT_NEAR(cs.at("displacement_error").get<double>(), e, 1e-6 * e) << cs.at("name");
  }
}

// On a transfer mesh only the region-level scales are checked, and the report says why.
TEST(CalibrateCliPerSpring, TransferMeshGetsTheRegionScalesAndTheReportSaysSo) {
  const std::string other = tmp("disc-L4-L5-10-sectors.vtu");
  ASSERT_EQ(
      run_spinesim("mesh disc --level L4-L5 --structured --sectors 10 --out " + in_quotes(other))
          .status,
      0);
  const std::string out = tmp("tuned-per-spring-transfer.json");
  const CliRun r = run_spinesim("calibrate --mesh " + in_quotes(disc()) +
                                " --per-spring --no-check --transfer-mesh " + in_quotes(other) +
                                " --out " + in_quotes(out));
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("per-spring multipliers do not transfer"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("Region-level scales on another mesh"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("region scales"), std::string::npos) << r.out;  // the region-only column
  const json file = json::parse(slurp(out));
  ASSERT_EQ(file["report"]["transfer"].size(), 1u);
  const json& t = file["report"]["transfer"][0];
  EXPECT_EQ(t.at("scales"), "region-level");
  EXPECT_NE(t.at("note").get<std::string>().find("do not transfer"), std::string::npos);
  // The errors there are those of the region-level scales: a region-only file gives the same.
  json region = file;
  region["kind"] = "region";
  region.erase("edge_multipliers");
  region.erase("edge_springs");
  const std::string region_path = tmp("tuned-per-spring-transfer-region.json");
  std::ofstream(region_path) << region.dump();
  std::ostringstream scale;
  scale.precision(17);
  scale << t.at("load_scale").get<double>();  // the transfer check's, with or without --no-check
  const CliRun cmp =
      run_spinesim("mss compare --mesh " + in_quotes(other) + " --params " +
                   in_quotes(region_path) + " --load-scale " + scale.str() + " --json");
  ASSERT_EQ(cmp.status, 0) << cmp.err;
  std::map<std::string, double> expected;
  for (const auto& c : t.at("cases")) expected[c.at("name")] = c.at("tuned_error").get<double>();
  const json compared = json::parse(cmp.out);  // named: a range-for over parse(...).at(...) dangles
  for (const auto& cs : compared.at("cases")) {
    const double e = expected.at(cs.at("name").get<std::string>());
    EXPECT_NEAR(cs.at("displacement_error").get<double>(), e, 1e-6 * e) << cs.at("name");
  }
  // ... and the per-spring file itself is refused there.
  const CliRun refused =
      run_spinesim("mss compare --mesh " + in_quotes(other) + " --params " + in_quotes(out));
  expect_refused(refused, "per-spring");
  EXPECT_NE(refused.err.find("region-level tuned files transfer"), std::string::npos)
      << refused.err;
}

TEST(MssParamsPerSpring, TheModelGetsTheMultipliersOnItsMeshOnly) {
  const Calibrated& c = calibrated(false, true);
  const CliRun ps = run_spinesim("mss --mesh " + in_quotes(disc()) + " --params " +
                                 in_quotes(c.path) + " --case compression --json");
  ASSERT_EQ(ps.status, 0) << ps.err;
  EXPECT_TRUE(ps.err.empty()) << ps.err;
  // The same region scales without the multipliers settle elsewhere: the multipliers are used.
  json region = json::parse(slurp(c.path));
  region["kind"] = "region";
  region.erase("edge_multipliers");
  region.erase("edge_springs");
  const std::string region_path = tmp("tuned-per-spring-as-region.json");
  std::ofstream(region_path) << region.dump();
  const CliRun rg = run_spinesim("mss --mesh " + in_quotes(disc()) + " --params " +
                                 in_quotes(region_path) + " --case compression --json");
  ASSERT_EQ(rg.status, 0) << rg.err;
  const double dy_ps = json::parse(ps.out)["plate_motion"][1].get<double>();
  const double dy_rg = json::parse(rg.out)["plate_motion"][1].get<double>();
  EXPECT_GT(std::abs(dy_ps - dy_rg), 1e-4 * std::abs(dy_rg));

  // Another mesh of the same level: the region file applies, the per-spring one is refused.
  const std::string other = tmp("disc-L4-L5-3-layers.vtu");
  ASSERT_EQ(
      run_spinesim("mesh disc --level L4-L5 --structured --layers 3 --out " + in_quotes(other))
          .status,
      0);
  EXPECT_EQ(run_spinesim("mss --mesh " + in_quotes(other) + " --params " + in_quotes(region_path) +
                         " --case compression")
                .status,
            0);
  for (const std::string verb : {"mss --case compression", "mss compare --cases compression"}) {
    SCOPED_TRACE(verb);
    const std::string sub = verb.substr(0, verb.find(" --"));
    const std::string flags = verb.substr(verb.find(" --"));
    const CliRun r = run_spinesim(sub + " --mesh " + in_quotes(other) + " --params " +
                                  in_quotes(c.path) + flags);
    expect_refused(r, "per-spring");
    EXPECT_NE(r.err.find("do not"), std::string::npos) << r.err;
    EXPECT_TRUE(r.out.empty()) << r.out;
  }
}

TEST(CalibrateCliPerSpringRefuses, BadOptionsAndAFailedSecondStage) {
  const std::string out = tmp("tuned-per-spring-refused.json");
  const std::string mesh = " --mesh " + in_quotes(disc());
  const std::string to = " --out " + in_quotes(out);
  expect_refused_without(run_spinesim("calibrate" + mesh + " --smoothness 0.1" + to),
                         "--per-spring", out);
  expect_refused_without(run_spinesim("calibrate" + mesh + " --per-spring --smoothness -1" + to),
                         "--smoothness", out);
  expect_refused_without(run_spinesim("calibrate --level all --per-spring" + to), "--per-spring",
                         out);

  // The region fit succeeds, the per-spring stage hits its iteration limit: exit 1, one line,
  // no file; the JSON on stdout says which stage failed.
  const CliRun r = run_spinesim(
      "calibrate" + mesh + " --per-spring --per-spring-max-iterations 2 --no-check --json" + to);
  EXPECT_EQ(r.status, 1);
  EXPECT_EQ(count_lines(r.err), 1) << r.err;
  EXPECT_NE(r.err.find("per-spring stage"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(out));
  const json j = json::parse(r.out);
  EXPECT_TRUE(j["report"]["ipopt"]["success"].get<bool>());
  EXPECT_FALSE(j["report"]["per_spring"]["ipopt"]["success"].get<bool>());
  EXPECT_EQ(j["report"]["per_spring"]["ipopt"]["status"], "Maximum_Iterations_Exceeded");
  EXPECT_FALSE(j.contains("out"));
}

namespace spinesim::cli {
namespace {

// The protocol's second mesh: the tuned scales checked on another mesh of the same disc, the
// untuned network beside them (the structured disc calibrated, a 4 mm CGAL disc checked).
TEST(CalibrateCli, TransferMeshIsCheckedUntunedBesideTuned) {
  const std::string other = tmp("disc-L4-L5-4mm.vtu");
  ASSERT_EQ(run_spinesim("mesh disc --level L4-L5 --cell-size 4 --out " + in_quotes(other)).status,
            0);
  const std::string out = tmp("tuned-transfer.json");
  const CliRun r = run_spinesim("calibrate --mesh " + in_quotes(disc()) + " --transfer-mesh " +
                                in_quotes(other) + " --out " + in_quotes(out) + " --json");
  ASSERT_EQ(r.status, 0) << r.err;
  const json j = json::parse(r.out);
  ASSERT_EQ(j["report"]["transfer"].size(), 1u);
  const json& t = j["report"]["transfer"][0];
  EXPECT_EQ(t["mesh"], other);
  EXPECT_GT(t["tets"].get<int>(), 360);  // another mesh than the calibrated one
  std::vector<std::string> names = case_names(t["cases"]), all = kAllCases;
  std::sort(names.begin(), names.end());
  std::sort(all.begin(), all.end());
  EXPECT_EQ(names, all);
  double untuned = 0, tuned = 0;
  for (const auto& c : t["cases"]) {
    EXPECT_GT(c["tuned_error"].get<double>(), 0.0);
    untuned += c["untuned_error"].get<double>();
    tuned += c["tuned_error"].get<double>();
  }
  EXPECT_LT(tuned, untuned);  // the scales carry over: better than Van Gelder on average
  EXPECT_EQ(t["stiffness_ratio_tuned"].size(), 6u);
}

TEST(CalibrateCliRefuses, ATransferMeshOfAnotherLevel) {
  const std::string out = tmp("tuned-transfer-bad.json");
  expect_refused_without(
      run_spinesim("calibrate --mesh " + in_quotes(disc()) + " --transfer-mesh " +
                   in_quotes(disc("L3-L4")) + " --out " + in_quotes(out)),
      "L3-L4", out);
}

}  // namespace
}  // namespace spinesim::cli

namespace spinesim::cli {
namespace {

// --params with the shipped tuned set: the mesh's level picks the entry; a mesh of unknown level
// cannot pick one and is refused.
TEST(MssParamsTunedSet, TheMeshLevelPicksTheEntry) {
  const std::string set = std::string(SPINESIM_DATA_DIR) + "/tuned_discs.json";
  const CliRun r = run_spinesim("mss compare --mesh " + in_quotes(disc("L3-L4")) + " --params " +
                                in_quotes(set) + " --cases compression --load-scale 0.1 --json");
  ASSERT_EQ(r.status, 0) << r.err;
  const json j = json::parse(r.out);
  EXPECT_EQ(j.at("mss_constants"), "tuned (" + set + ")");
  const CliRun untuned = run_spinesim("mss compare --mesh " + in_quotes(disc("L3-L4")) +
                                      " --cases compression --load-scale 0.1 --json");
  ASSERT_EQ(untuned.status, 0) << untuned.err;
  // The L3-L4 entry's scales, not Van Gelder's: a different (and better) answer.
  EXPECT_LT(j.at("cases")[0].at("displacement_error").get<double>(),
            json::parse(untuned.out).at("cases")[0].at("displacement_error").get<double>());

  mesh::TetMesh unknown = mesh::read_vtu(disc("L3-L4"));
  unknown.source = "disc between vertebrae";
  const std::string path = tmp("unknown-level.vtu");
  mesh::write_vtu(path, unknown);
  expect_refused(run_spinesim("mss --mesh " + in_quotes(path) + " --params " + in_quotes(set) +
                              " --case torsion"),
                 "level is unknown");
}

}  // namespace
}  // namespace spinesim::cli

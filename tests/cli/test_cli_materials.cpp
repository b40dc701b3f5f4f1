// `spinesim study materials` (thesis fig. 5.9 with a reference): physical properties of the
// FEM / untuned MSS / tuned MSS comparison on a coarse L4-L5 disc (cell size 4 mm), the CSV's
// shape, and bad input -> exit 1, one line on stderr, no file.
#include "cli_runner.hpp"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <cmath>
#include <filesystem>
#include <map>
#include <set>
#include <sstream>
#include <string>
#include <vector>

namespace fs = std::filesystem;
using nlohmann::json;

namespace {

using namespace spinesim::test_cli;

const char* kCoarse = "study materials --level L4-L5 --cell-size 4 --quiet";

/// CSV rows as column name -> text (header from the first line).
std::vector<std::map<std::string, std::string>> read_csv(const std::string& text) {
  std::vector<std::map<std::string, std::string>> rows;
  std::stringstream ss(text);
  std::string line, cell;
  std::vector<std::string> header;
  while (std::getline(ss, line)) {
    std::vector<std::string> cells;
    std::stringstream ls(line);
    while (std::getline(ls, cell, ',')) cells.push_back(cell);
    if (header.empty()) {
      header = cells;
      continue;
    }
    EXPECT_EQ(cells.size(), header.size()) << line;
    std::map<std::string, std::string> row;
    for (std::size_t i = 0; i < header.size() && i < cells.size(); ++i) row[header[i]] = cells[i];
    rows.push_back(row);
  }
  return rows;
}

const json& material(const json& j, const std::string& name) {
  for (const auto& m : j["materials"])
    if (m["material"] == name) return m;
  ADD_FAILURE() << "material " << name << " missing";
  static const json none;
  return none;
}

double axial(const json& m, const char* model) {
  return m[model]["axial_stiffness_n_per_mm"].get<double>();
}

}  // namespace

// One run, three presets: the orderings and ratios the physics dictates.
TEST(MaterialsStudy, StifferMaterialsStifferDiscAndTheTunedMssMatchesTheFem) {
  const std::string csv = tmp("materials.csv");
  const CliRun r =
      run_spinesim(std::string(kCoarse) +
                   " --materials real-disc,rubber,polyethylene --json --csv '" + csv + "'");
  ASSERT_EQ(r.status, 0) << r.err;
  const json j = json::parse(r.out);
  ASSERT_EQ(j["materials"].size(), 3u);
  const json &real = material(j, "real-disc"), &rubber = material(j, "rubber"),
             &pe = material(j, "polyethylene");

  // FEM axial stiffness follows E (3.22 < 30 < 200 MPa) ...
  EXPECT_GT(axial(pe, "fem"), axial(rubber, "fem"));
  EXPECT_GT(axial(rubber, "fem"), axial(real, "fem"));
  // ... and, per MPa, rises with nu: the endplates confine the near-incompressible rubber (0.49)
  // more than the real disc (0.4557).
  EXPECT_GT(axial(rubber, "fem") / 30.0, axial(real, "fem") / 3.22);

  for (const json* m : {&real, &rubber, &pe}) {
    const std::string name = (*m)["material"];
    ASSERT_TRUE((*m)["calibration"]["success"].get<bool>()) << name;
    const double fem = axial(*m, "fem"), untuned = axial(*m, "untuned"), tuned = axial(*m, "tuned");
    // The calibration's job: tuned within 10 % of the FEM, and closer than Van Gelder's constants.
    EXPECT_NEAR(tuned / fem, 1.0, 0.10) << name;
    EXPECT_LT(std::abs(tuned / fem - 1), std::abs(untuned / fem - 1)) << name;
    EXPECT_LT((*m)["tuned"]["displacement_error"].get<double>(),
              (*m)["untuned"]["displacement_error"].get<double>())
        << name;
    // 500 N compression moves the plate down and loses volume; the untuned spring network
    // (Cauchy solid, nu = 1/4) loses more than the FEM's nu >= 0.45 material.
    for (const char* model : {"fem", "untuned", "tuned"}) {
      EXPECT_LT((*m)[model]["plate_axial_displacement_mm"].get<double>(), 0.0)
          << name << " " << model;
      EXPECT_LT((*m)[model]["volume_change"].get<double>(), 0.0) << name << " " << model;
      EXPECT_EQ((*m)[model]["stiffness_diagonal"].size(), 6u);
    }
    EXPECT_LT((*m)["untuned"]["volume_change"].get<double>(),
              (*m)["fem"]["volume_change"].get<double>())
        << name;
    EXPECT_TRUE((*m)["untuned"]["converged"].get<bool>() && (*m)["tuned"]["converged"].get<bool>())
        << name;
  }
  // The thesis's fig. 5.9 claim: the real disc compresses most, polyethylene least (FEM).
  EXPECT_LT(real["fem"]["plate_axial_displacement_mm"].get<double>(),
            rubber["fem"]["plate_axial_displacement_mm"].get<double>());
  EXPECT_LT(rubber["fem"]["plate_axial_displacement_mm"].get<double>(),
            pe["fem"]["plate_axial_displacement_mm"].get<double>());

  // CSV: one row per material x model, the same numbers as the JSON.
  EXPECT_EQ(j["csv"], csv);
  const auto rows = read_csv(csv_table(csv));
  ASSERT_EQ(rows.size(), 9u);
  std::set<std::string> seen;
  for (const auto& row : rows) {
    seen.insert(row.at("material") + "/" + row.at("model"));
    const double k = std::stod(row.at("axial_stiffness_N_per_mm"));
    EXPECT_NEAR(k, axial(material(j, row.at("material")), row.at("model").c_str()), 1e-6 * k);
    EXPECT_EQ(row.at("axial_stiffness_N_per_mm"), row.at("K_ty_N_per_mm"));
  }
  EXPECT_EQ(seen.size(), 9u);
  for (const char* mat : {"real-disc", "rubber", "polyethylene"})
    for (const char* model : {"fem", "untuned", "tuned"})
      EXPECT_EQ(seen.count(std::string(mat) + "/" + model), 1u);
}

TEST(MaterialsStudy, ReadableTableHasABlockPerQuantityWithUnits) {
  const CliRun r = run_spinesim(std::string(kCoarse) + " --materials real-disc");
  ASSERT_EQ(r.status, 0) << r.err;
  for (const char* text : {"Axial stiffness K6_yy, N/mm", "u_y under 500 N compression, mm",
                           "max |u|", "Volume change dV/V0", "displacement error", "N·mm/deg",
                           "FEM P2", "untuned MSS", "tuned MSS", "real-disc"})
    EXPECT_NE(r.out.find(text), std::string::npos) << text << "\n" << r.out;
}

TEST(MaterialsStudy, HelpStatesTheProtocol) {
  const CliRun r = run_spinesim("study materials --help");
  EXPECT_EQ(r.status, 0);
  for (const char* text : {"--materials", "--csv", "-500 N", "Van Gelder", "Ipopt", "P1 volume"})
    EXPECT_NE(r.out.find(text), std::string::npos) << text;
}

TEST(MaterialsStudy, BadInputIsRefusedWithoutAFile) {
  const std::string csv = tmp("refused.csv");
  expect_refused(
      run_spinesim(std::string(kCoarse) + " --materials real-disc,granite --csv '" + csv + "'"),
      "granite");
  expect_refused(run_spinesim("study materials --level L9-L10 --csv '" + csv + "'"), "L9-L10");
  expect_refused(run_spinesim("study materials --cell-size -1 --csv '" + csv + "'"), "--cell-size");
  expect_refused(run_spinesim("study materials --terms springs --csv '" + csv + "'"), "springs");
  expect_refused(run_spinesim("study materials --materials , --csv '" + csv + "'"), "--materials");
  EXPECT_FALSE(fs::exists(csv));
  const std::string nowhere = (tmp_dir() / "no-such-folder" / "m.csv").string();
  expect_refused(run_spinesim(std::string(kCoarse) + " --csv '" + nowhere + "'"), "--csv");
  EXPECT_FALSE(fs::exists(nowhere));
}

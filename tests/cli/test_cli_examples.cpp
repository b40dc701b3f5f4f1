// examples/ as smoke tests: every study file there is valid by the schema, and each folder's
// studies run in name order (in a copy: a study writes beside itself) and write what their
// options name, each output with its provenance.
#include "cli_runner.hpp"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <filesystem>
#include <string>
#include <vector>

namespace {

using namespace spinesim::test_cli;
using nlohmann::json;
namespace fs = std::filesystem;

const fs::path kExamples = fs::path(SPINESIM_DATA_DIR).parent_path() / "examples";

std::vector<fs::path> studies_in(const fs::path& dir) {
  std::vector<fs::path> out;
  for (const auto& e : fs::directory_iterator(dir))
    if (e.path().extension() == ".json") out.push_back(e.path());
  std::sort(out.begin(), out.end());
  return out;
}

std::vector<fs::path> example_folders() {
  std::vector<fs::path> out;
  for (const auto& e : fs::directory_iterator(kExamples))
    if (e.is_directory()) out.push_back(e.path());
  std::sort(out.begin(), out.end());
  return out;
}

/// The output a study's options name (out, csv, record), checked for its provenance.
void expect_output_with_provenance(const fs::path& file) {
  ASSERT_TRUE(fs::exists(file)) << file;
  if (fs::is_directory(file)) {
    bool any = false;
    for (const auto& e : fs::directory_iterator(file))
      if (e.path().extension() == ".json") {
        EXPECT_TRUE(json::parse(slurp(e.path().string())).contains("provenance")) << e.path();
        any = true;
      }
    EXPECT_TRUE(any) << file << " holds no JSON";
  } else if (file.extension() == ".csv") {
    const std::string text = slurp(file.string());
    EXPECT_NE(text.find("# provenance: {"), std::string::npos) << file;
  } else if (file.extension() == ".json") {
    EXPECT_TRUE(json::parse(slurp(file.string())).contains("provenance")) << file;
  } else if (file.extension() == ".vtu") {
    EXPECT_NE(slurp(file.string()).find("Name=\"provenance\""), std::string::npos) << file;
  }
}

TEST(Examples, EveryExampleIsAValidStudyThatRuns) {
  ASSERT_TRUE(fs::is_directory(kExamples)) << kExamples;
  const std::vector<fs::path> folders = example_folders();
  EXPECT_GE(folders.size(), 4u);
  const fs::path copy = tmp("examples");
  fs::copy(kExamples, copy, fs::copy_options::recursive);
  for (const fs::path& folder : folders) {
    for (const fs::path& original : studies_in(folder)) {
      const fs::path study = copy / folder.filename() / original.filename();
      SCOPED_TRACE(study.string());
      const json s = json::parse(slurp(study.string()));
      EXPECT_TRUE(s.contains("description")) << "an example explains itself";
      if (s.contains("spinesim_sweep")) {  // a sweep plan: its points run, its summary written
        const fs::path out = study.parent_path() / ("sweep-" + study.stem().string());
        const CliRun r =
            run_spinesim("sweep '" + study.string() + "' --out '" + out.string() + "' --quiet");
        ASSERT_EQ(r.status, 0) << r.err;
        expect_output_with_provenance(out / "summary.csv");
        continue;
      }
      const CliRun r = run_spinesim("run '" + study.string() + "'");
      ASSERT_EQ(r.status, 0) << r.err;
      if (s["options"].value("json", false)) EXPECT_TRUE(json::parse(r.out).contains("provenance"));
      for (const char* key : {"out", "csv", "record"})
        if (s["options"].contains(key))
          expect_output_with_provenance(study.parent_path() / s["options"][key].get<std::string>());
    }
  }
}

TEST(Examples, TheSchemaAcceptsEveryExample) {
  if (!has_jsonschema()) GTEST_SKIP() << "python3-jsonschema is not installed";
  const CliRun schema = run_spinesim("run --schema");
  ASSERT_EQ(schema.status, 0) << schema.err;
  const std::string schema_file = tmp("schema.json");
  spit(schema_file, schema.out);
  for (const fs::path& folder : example_folders())
    for (const fs::path& study : studies_in(folder)) {
      if (json::parse(slurp(study.string())).contains("spinesim_sweep")) {
        // A sweep plan is not a study; each of its points is (checked before any point runs).
        const CliRun r = run_spinesim("sweep '" + study.string() + "' --out '" +
                                      tmp("dry-" + folder.filename().string()) + "' --dry-run");
        EXPECT_EQ(r.status, 0) << r.err;
        continue;
      }
      EXPECT_TRUE(schema_accepts(schema_file, study.string())) << study;
    }
}

}  // namespace

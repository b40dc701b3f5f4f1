// Studies as files and the provenance of outputs: --save-study then `run` gives the same
// outputs (all but the record of the command that made them); every output kind carries the
// program, commit, command line and the inputs' SHA-256 (checked against coreutils' sha256sum);
// a wrong study file is refused in one line naming the field; the schema that `run --schema`
// prints accepts the saved studies and refuses the wrong ones (Debian's python3-jsonschema, an
// independent validator, when installed).
#include "cli_runner.hpp"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <filesystem>
#include <regex>
#include <string>

namespace {

using namespace spinesim::test_cli;
using nlohmann::json;
namespace fs = std::filesystem;

/// A fresh folder under the test folder.
std::string folder(const std::string& name) {
  const std::string d = tmp(name);
  fs::create_directories(d);
  return d;
}

/// The small structured L4-L5 disc, meshed once per test program.
const std::string& small_disc() {
  static const std::string path = [] {
    const std::string d = folder("study-disc");
    const std::string p = d + "/disc.vtu";
    const CliRun r =
        run_spinesim("mesh disc --level L4-L5 --structured --out '" + p + "' --quiet");
    EXPECT_EQ(r.status, 0) << r.err;
    return p;
  }();
  return path;
}

/// A VTU file's text without its provenance array (the one part that says how it was made).
std::string vtu_without_provenance(const std::string& path) {
  const std::string text = slurp(path);
  static const std::regex provenance(
      "<DataArray type=\"UInt8\" Name=\"provenance\"[^>]*>[^<]*</DataArray>\\s*");
  EXPECT_TRUE(std::regex_search(text, provenance)) << path << " has no provenance";
  return std::regex_replace(text, provenance, "");
}

json without_provenance(json j) {
  EXPECT_TRUE(j.contains("provenance"));
  j.erase("provenance");
  return j;
}

/// The SHA-256 of a file as coreutils computes it.
std::string sha256sum(const std::string& path) {
  const std::string out = tmp("sha.txt");
  EXPECT_EQ(std::system(("sha256sum '" + path + "' > '" + out + "'").c_str()), 0);
  return slurp(out).substr(0, 64);
}

/// The provenance's common shape: program, a commit, the command line with `command_part`.
void expect_provenance(const json& p, const std::string& command_part) {
  EXPECT_EQ(p.at("program"), "spinesim");
  EXPECT_FALSE(p.at("version").get<std::string>().empty());
  EXPECT_TRUE(std::regex_match(p.at("commit").get<std::string>(),
                               std::regex("[0-9a-f]{40}(-dirty)?|unknown")))
      << p.at("commit");
  EXPECT_NE(p.at("command").get<std::string>().find(command_part), std::string::npos)
      << p.at("command");
  EXPECT_TRUE(p.at("arguments").is_array());
  EXPECT_TRUE(fs::path(p.at("working_directory").get<std::string>()).is_absolute());
}

/// The input `name_end` among the provenance's inputs, with coreutils' hash of `path`.
void expect_input(const json& p, const std::string& name_end, const std::string& path) {
  for (const auto& in : p.at("inputs")) {
    const std::string shown = in.at("path");
    if (shown.size() >= name_end.size() &&
        shown.compare(shown.size() - name_end.size(), name_end.size(), name_end) == 0) {
      EXPECT_EQ(in.at("sha256"), sha256sum(path)) << shown;
      EXPECT_EQ(in.at("bytes").get<std::uintmax_t>(), fs::file_size(path)) << shown;
      return;
    }
  }
  ADD_FAILURE() << "no input " << name_end << " in " << p.at("inputs").dump();
}

// The FEM verb saved as a study in another folder, run from a third: the VTU (field arrays,
// bytes) and the JSON are the original's apart from the provenance, which names the study.
TEST(CliStudy, FemStudyRoundTripsToTheSameOutputs) {
  const std::string work = folder("study-fem"), studies = folder("study-fem/studies");
  const std::string out = work + "/flexion.vtu", study = studies + "/flexion.json";
  const std::string disc = fs::path(small_disc()).lexically_relative(work).string();
  const CliRun first = run_spinesim("fem --mesh '" + disc +
                                        "' --case flexion --order 2 --formulation mixed "
                                        "--out flexion.vtu --json --save-study studies/flexion.json",
                                    "cd '" + work + "' && ");
  ASSERT_EQ(first.status, 0) << first.err;
  const std::string first_vtu = vtu_without_provenance(out);
  const json saved = json::parse(slurp(study));
  EXPECT_EQ(saved["spinesim_study"], 1);
  EXPECT_EQ(saved["verb"], "fem");
  EXPECT_EQ(saved["options"]["order"], 2);  // a number, not text
  EXPECT_EQ(saved["options"]["json"], true);
  EXPECT_EQ(saved["options"]["out"], "../flexion.vtu");  // relative to the study's folder
  EXPECT_EQ(saved["options"]["mesh"], "../" + disc);
  EXPECT_FALSE(saved["options"].contains("material"));  // not given: not saved
  EXPECT_FALSE(saved["options"].contains("save-study"));
  expect_provenance(saved["provenance"], "--save-study");

  fs::remove(out);
  const CliRun again = run_spinesim("run '" + study + "'", "cd / && ");
  ASSERT_EQ(again.status, 0) << again.err;
  EXPECT_EQ(vtu_without_provenance(out), first_vtu);
  // The same answer, but for the provenance and the run's own timings; the paths it echoes are
  // as each run saw them (the study runs in its own folder): the same files.
  const auto answer = [](const std::string& out, const fs::path& ran_in) {
    json j = without_provenance(json::parse(out));
    j.erase("timings");
    for (const char* key : {"mesh", "out"})
      j[key] = fs::weakly_canonical(ran_in / j.at(key).get<std::string>()).string();
    return j;
  };
  EXPECT_EQ(answer(again.out, studies), answer(first.out, work));
  const json p = json::parse(again.out)["provenance"];
  expect_provenance(p, "run");
  expect_input(p, "flexion.json", study);
  expect_input(p, "disc.vtu", small_disc());
  expect_input(p, "real-disc.json", std::string(SPINESIM_DATA_DIR) + "/materials/real-disc.json");
}

// A CSV-writing verb: the table is the same, its provenance line names the command.
TEST(CliStudy, SpineStudyRoundTripsItsCsv) {
  const std::string work = folder("study-spine");
  const std::string csv = work + "/spine.csv", study = work + "/spine.json";
  const CliRun first =
      run_spinesim("spine solve --force T7:0,0,300 --force L1:0,0,100 --csv '" + csv +
                   "' --save-study '" + study + "'");
  ASSERT_EQ(first.status, 0) << first.err;
  const std::string table = csv_table(csv);
  EXPECT_EQ(json::parse(slurp(study))["options"]["force"],
            json::array({"T7:0,0,300", "L1:0,0,100"}));  // a repeated option: an array
  fs::remove(csv);
  const CliRun again = run_spinesim("run '" + study + "' --json");  // options after: added
  ASSERT_EQ(again.status, 0) << again.err;
  EXPECT_EQ(csv_table(csv), table);
  EXPECT_NO_THROW((void)json::parse(again.out));
  EXPECT_NE(slurp(csv).find("\"run\""), std::string::npos);  // the provenance's arguments
}

// Every output kind of one study: JSON on stdout, the JSON file, the CSV, and report.html's
// footer (when the report could be drawn).
TEST(CliStudy, EveryOutputKindRecordsItsProvenance) {
  const std::string out = folder("study-seating");
  const CliRun r = run_spinesim("study seating --out '" + out + "' --json --quiet");
  ASSERT_EQ(r.status, 0) << r.err;
  expect_provenance(json::parse(r.out).at("provenance"), "study seating");
  const json file = json::parse(slurp(out + "/seating.json"));
  expect_provenance(file.at("provenance"), "study seating");
  expect_input(file.at("provenance"), "seating.json",
               std::string(SPINESIM_DATA_DIR) + "/spine/seating.json");
  (void)csv_table(out + "/seating.csv");  // checks the provenance line
  if (fs::exists(out + "/report.html")) {
    const std::string html = slurp(out + "/report.html");
    EXPECT_NE(html.find("<h2>Provenance</h2>"), std::string::npos);
    EXPECT_NE(html.find(file["provenance"]["commit"].get<std::string>()), std::string::npos);
  }
}

// Wrong study files: one line naming the field, nothing run.
TEST(CliStudy, WrongStudyFilesAreRefusedNamingTheField) {
  const std::string d = folder("study-wrong");
  const std::string disc = fs::path(small_disc()).lexically_relative(d).string();
  const std::vector<std::pair<std::string, std::string>> cases = {
      {R"({"verb": "fem"})", "spinesim_study: missing"},
      {R"({"spinesim_study": 2, "verb": "fem"})", "spinesim_study: version 2"},
      {R"({"spinesim_study": 1})", "verb: missing"},
      {R"({"spinesim_study": 1, "verb": "fme"})", "verb: \"fme\" is not a verb of spinesim (did you mean \"fem\"?)"},
      {R"({"spinesim_study": 1, "verb": "fem", "option": {}})", "option: unknown field (did you mean \"options\"?)"},
      {R"({"spinesim_study": 1, "verb": "fem", "options": {"ordr": 2}})", "options.ordr: not an option of `fem` (did you mean \"order\"?)"},
      {R"({"spinesim_study": 1, "verb": "fem", "options": {"json": "yes"}})", "options.json: a flag: true or false"},
      {R"({"spinesim_study": 1, "verb": "fem", "options": {"order": true}})", "options.order: must be a number"},
      {R"({"spinesim_study": 1, "verb": "fem", "options": {"mesh": 3}})", "options.mesh: must be a string"},
      {R"({"spinesim_study": 1, "verb": "fem", "options": {"order": [1, 2]}})", "options.order: takes one value"},
      {R"({"spinesim_study": 1, "verb": "fem", "options": {"mesh": ")" + disc + R"(", "order": 7}})", "FEM order must be 1 (P1) or 2 (P2), got 7"},
      {R"({"spinesim_study": 1, "verb": "fem", "options": {"mesh": ")" + disc + R"(", "order": "x"}})", "options.order: --order: 'x' is not a whole number"},
      {R"({"spinesim_study": 1, "verb": "fem", "description": 5})", "description: must be a string"},
      {R"([1, 2])", "expected a JSON object"},
      {R"({"spinesim_study": 1, "verb": "fem",)", "is not valid JSON"},
  };
  int k = 0;
  for (const auto& [text, needle] : cases) {
    const std::string study = d + "/wrong" + std::to_string(k++) + ".json";
    spit(study, text);
    const CliRun r = run_spinesim("run '" + study + "'");
    SCOPED_TRACE(text);
    expect_refused(r, needle);
    EXPECT_NE(r.err.find(study), std::string::npos) << r.err;  // names the file
  }
}

// The schema `run --schema` prints, checked by an independent validator: it accepts what
// --save-study writes and refuses the wrong fields the program refuses.
TEST(CliStudy, TheSchemaAcceptsSavedStudiesAndRefusesWrongOnes) {
  const CliRun r = run_spinesim("run --schema");
  ASSERT_EQ(r.status, 0) << r.err;
  const json schema = json::parse(r.out);
  EXPECT_TRUE(schema["properties"]["verb"]["enum"].size() > 20u);
  for (const char* verb : {"fem", "mss compare", "study disc-validation", "calibrate", "demo"}) {
    bool found = false;
    for (const auto& v : schema["properties"]["verb"]["enum"]) found |= v == verb;
    EXPECT_TRUE(found) << verb;
  }
  for (const auto& v : schema["properties"]["verb"]["enum"])  // not studies themselves
    EXPECT_TRUE(v != "run" && v != "bench-mesh-one" && v != "bench-fem-one") << v;
  if (!has_jsonschema()) GTEST_SKIP() << "python3-jsonschema is not installed";
  const std::string d = folder("study-schema");
  const std::string schema_file = d + "/schema.json";
  spit(schema_file, r.out);
  const std::string study = d + "/saved.json";
  const CliRun saved = run_spinesim("fem --mesh '" + small_disc() +
                                    "' --case compression --order 1 --quiet --save-study '" +
                                    study + "'");
  ASSERT_EQ(saved.status, 0) << saved.err;
  EXPECT_TRUE(schema_accepts(schema_file, study));
  for (const std::string& wrong :
       {std::string(R"({"spinesim_study": 1, "verb": "fme"})"),
        std::string(R"({"spinesim_study": 1, "verb": "fem", "options": {"ordr": 2}})"),
        std::string(R"({"spinesim_study": 1, "verb": "fem", "options": {"json": "yes"}})"),
        std::string(R"({"spinesim_study": 1, "verb": "fem", "extra": 1})")}) {
    const std::string f = d + "/wrong.json";
    spit(f, wrong);
    EXPECT_FALSE(schema_accepts(schema_file, f)) << wrong;
  }
}

// --save-study's folder is checked before the work, like every output.
TEST(CliStudy, SaveStudyIntoAMissingFolderIsRefusedBeforeTheWork) {
  const CliRun r = run_spinesim("fem --mesh '" + small_disc() + "' --case compression --order 1 "
                                "--save-study '" + tmp("no-such-folder") + "/s.json'");
  expect_refused(r, "does not exist");
  EXPECT_EQ(r.err.find("--save-study: --save-study"), std::string::npos) << r.err;  // once
}

}  // namespace

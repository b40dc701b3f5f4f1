// spinesim run STUDY: a study file (study_file.hpp) run as its verb, in the study's folder;
// --schema prints the study files' JSON Schema.
#include "cli_common.hpp"
#include "study_file.hpp"

#include "spinesim/common/input_file.hpp"
#include "spinesim/common/provenance.hpp"

#include <algorithm>
#include <filesystem>
#include <iostream>
#include <memory>

namespace spinesim::cli {
namespace {
namespace fs = std::filesystem;

struct RunArgs {
  std::string study;
  bool schema = false;
  bool dry_run = false;
  std::vector<std::string> extra;  ///< options after the study, added to its verb's
};

/// Back to the folder the program started in, however the study ends (the Python module runs
/// several studies in one process).
class FolderGuard {
 public:
  FolderGuard() : start_(fs::current_path()) {}
  ~FolderGuard() {
    std::error_code ec;
    fs::current_path(start_, ec);
  }

 private:
  fs::path start_;
};

/// A CLI11 refusal of the study's command line, as the field of the study that caused it.
std::string study_field_error(const std::string& what, const std::vector<std::string>& argv) {
  std::string field;
  for (const auto& a : argv)
    if (a.rfind("--", 0) == 0 && what.find(a) != std::string::npos &&
        a.size() > field.size() + 2)
      field = "options." + a.substr(2);
  return field.empty() ? what : field + ": " + what;
}

void run_study(const RunArgs& a) {
  if (a.schema) {
    const std::unique_ptr<CLI::App> app = make_app();
    std::cout << study_schema(*app).dump(2) << std::endl;
    return;
  }
  if (a.study.empty()) throw std::invalid_argument("run: give a study file (or --schema)");
  const std::string where = "study file '" + a.study + "'";
  const nlohmann::json study = read_json_file(a.study, "study file");
  std::unique_ptr<CLI::App> app = make_app();
  std::vector<std::string> argv = study_arguments(*app, study, where);
  argv.insert(argv.end(), a.extra.begin(), a.extra.end());  // e.g. --json, --quiet
  fs::path folder = fs::path(a.study).parent_path();
  if (folder.empty()) folder = ".";
  if (a.dry_run) {
    std::string line = "(cd " + shell_quoted(folder.string()) + " && spinesim";
    for (const auto& w : argv) line += " " + shell_quoted(w);
    std::cout << line << ")" << std::endl;
    return;
  }
  FolderGuard back;
  fs::current_path(folder);  // relative paths in a study are relative to the study file
  std::vector<std::string> reversed(argv.rbegin(), argv.rend());  // CLI11 parses from the back
  try {
    app->parse(reversed);
  } catch (const CLI::ParseError& e) {
    throw std::invalid_argument(where + ": " + study_field_error(e.what(), argv));
  } catch (const std::invalid_argument& e) {  // a value the verb refused: still the study's
    throw std::invalid_argument(where + ": " + study_field_error(e.what(), argv));
  }
  save_study_if_asked(*app);
}

}  // namespace

void register_run(CLI::App& app) {
  auto a = std::make_shared<RunArgs>();
  auto* cmd = app.add_subcommand(
      "run", "Run a study file: one verb and its options as JSON (write one with --save-study)");
  cmd->add_option("study", a->study, "The study file (JSON)")->type_name("PATH");
  cmd->add_flag("--schema", a->schema, "Print the study files' JSON Schema and stop");
  cmd->add_flag("--dry-run", a->dry_run,
                "Print the command line the study stands for (in its folder) and stop");
  cmd->footer(
      "A study file: {\"spinesim_study\": 1, \"description\": \"…\", \"verb\": \"fem\",\n"
      "  \"options\": {\"mesh\": \"disc.vtu\", \"case\": \"flexion\", \"order\": 2, \"out\": "
      "\"flexion.vtu\"}}\n"
      "Runs in the study file's folder: relative paths are relative to it. A flag is true/false, a\n"
      "number option a number, a repeatable option an array. Every verb writes its own study with\n"
      "--save-study FILE. Options after the study are added to its own (spinesim run s.json --json).\n"
      "See docs/studies.md and examples/.");
  cmd->allow_extras();
  cmd->callback([a, cmd] {
    a->extra = cmd->remaining();
    run_study(*a);
  });
}

}  // namespace spinesim::cli

// Studies as files. A study file (JSON) is one verb of the program with its options:
//
//   {"spinesim_study": 1,
//    "description": "Flexion of the L4-L5 disc, stress fields for ParaView",   (optional text)
//    "verb": "fem",
//    "options": {"mesh": "disc.vtu", "case": "flexion", "order": 2, "out": "flexion.vtu"},
//    "provenance": {…}}                     (optional: written by --save-study, not read)
//
// `spinesim run STUDY` runs it as if its options had been typed after the verb, in the study
// file's folder: relative paths in a study are relative to the file, so a folder with its study
// and its inputs can be moved or shared whole. `--save-study FILE` on every verb writes the study
// of what the verb just did (the options given, paths rebased onto FILE's folder), after it
// succeeded. `spinesim run --schema` prints the files' JSON Schema (one `if` per verb, each
// option's JSON type, unknown fields refused). A wrong study is refused in one line naming the
// field ("options.order", "verb").
//
// Option values: a flag is true or false (false = not given); a number-valued option a number
// (or a string with the number); any other a string; an option that takes several values an
// array.
#pragma once

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include <string>
#include <vector>

namespace spinesim::cli {

/// The study file format's version, "spinesim_study".
inline constexpr int kStudyFileVersion = 1;

/// The verbs of `app` that can run (every sub-command that does not require a further one), as
/// their space-separated paths ("fem", "mss compare", "study disc-validation"), in help order;
/// `run` itself and hidden helpers (the bench's one-run children) excluded.
std::vector<std::string> study_verbs(CLI::App& app);

/// Adds --save-study FILE to every verb of `app` (study_verbs); its folder is checked when the
/// command line is read, before the work.
void add_save_study_options(CLI::App& app);

/// After a successful parse (the verb has run): writes the study file of the verb that ran
/// when --save-study was given. Returns the path written, or "".
std::string save_study_if_asked(CLI::App& app);

/// The study file of the verb `verb` with its given options (not yet written).
nlohmann::json study_of(CLI::App& verb, const std::string& verb_path,
                        const std::string& study_path);

/// A study file turned into a command line: the argument vector after the program's name
/// ("fem", "--mesh", "disc.vtu", …). Throws std::invalid_argument naming `where` and the field
/// for an unknown verb or option, a value of the wrong JSON type, an unknown top-level field or
/// a missing one.
std::vector<std::string> study_arguments(CLI::App& app, const nlohmann::json& study,
                                         const std::string& where);

/// `study` moved from folder `from` to folder `to`: each relative value of an input path option
/// (or a preset-or-path option) that names an existing file or folder in `from` is rewritten
/// relative to `to`; the others (outputs such as --out and --csv, whether or not a file of that
/// name exists, and preset names) stay as they are, so a sweep point's outputs land
/// in its own folder and its inputs are still found. An unknown verb leaves the study as it is.
nlohmann::json rebase_study_inputs(CLI::App& app, nlohmann::json study, const std::string& from,
                                   const std::string& to);

/// The JSON Schema (draft 2020-12) of the study files of `app`.
nlohmann::json study_schema(CLI::App& app);

/// Whether an option of `verb` takes a file or folder (its relative value is rebased when a
/// study is saved to another folder). Preset-or-file options (--material) are rebased only when
/// the value names an existing file.
bool is_path_option(const CLI::Option& option);
bool is_preset_or_path_option(const CLI::Option& option);

}  // namespace spinesim::cli

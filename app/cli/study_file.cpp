#include "study_file.hpp"

#include "suggest.hpp"

#include "spinesim/common/numbers.hpp"
#include "spinesim/common/provenance.hpp"
#include "spinesim/output/files.hpp"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <set>
#include <sstream>
#include <stdexcept>

namespace spinesim::cli {
namespace {
namespace fs = std::filesystem;

// Options that name a file or folder, to write or to read (CLI long names).
const std::set<std::string> kPathOptions = {
    "mesh",   "out",     "csv",       "paths",      "targets",     "held-out", "preset",
    "medit",  "inferior", "superior", "transfer-mesh", "mesh-out", "testdata", "cache-dir",
    "replay", "record",  "write-scene", "database", "chair",       "play",     "cursor-script",
    "screenshot", "loads"};
// Options that take a shipped preset's name or a file.
const std::set<std::string> kPresetOrPathOptions = {
    "material", "params", "disc-joints", "tuned", "script", "vertebrae", "spine",
    "sdk-lib",  "openhaptics-lib", "dhd-lib"};

std::string long_name(const CLI::Option& o) {
  return o.get_lnames().empty() ? o.get_name() : o.get_lnames().front();
}

bool is_flag(const CLI::Option& o) { return o.get_expected_max() == 0; }
bool takes_many(const CLI::Option& o) { return o.get_items_expected_max() > 1; }
bool is_number_option(const CLI::Option& o) {
  const std::string t = o.get_type_name();
  return t.rfind("INT", 0) == 0 || t.rfind("UINT", 0) == 0 || t.rfind("FLOAT", 0) == 0 ||
         t.rfind("NUMBER", 0) == 0;
}

/// The options a study may set: every named option but --help and --save-study.
std::vector<const CLI::Option*> study_options(const CLI::App& verb) {
  std::vector<const CLI::Option*> out;
  for (const CLI::Option* o : verb.get_options()) {
    const std::string name = long_name(*o);
    if (name.empty() || name == "help" || name == "save-study" || name == "help-all") continue;
    out.push_back(o);
  }
  return out;
}

void collect_verbs(CLI::App& app, const std::string& prefix, std::vector<std::string>& out,
                   std::vector<CLI::App*>* apps) {
  for (CLI::App* sub : app.get_subcommands([](CLI::App*) { return true; })) {
    const std::string path = prefix.empty() ? sub->get_name() : prefix + " " + sub->get_name();
    if (path == "run" || sub->get_group().empty()) continue;  // hidden helpers are no studies
    if (sub->get_require_subcommand_min() == 0) {
      out.push_back(path);
      if (apps) apps->push_back(sub);
    }
    collect_verbs(*sub, path, out, apps);
  }
}

CLI::App* find_verb(CLI::App& app, const std::string& verb_path) {
  std::vector<std::string> paths;
  std::vector<CLI::App*> apps;
  collect_verbs(app, "", paths, &apps);
  for (std::size_t i = 0; i < paths.size(); ++i)
    if (paths[i] == verb_path) return apps[i];
  return nullptr;
}

/// The verb that ran: the chain of parsed sub-commands, and its path.
CLI::App* parsed_verb(CLI::App& app, std::string& path) {
  CLI::App* at = &app;
  for (;;) {
    const std::vector<CLI::App*> parsed = at->get_subcommands();
    if (parsed.empty()) return at == &app ? nullptr : at;
    at = parsed.front();
    path += (path.empty() ? "" : " ") + at->get_name();
  }
}

/// A relative path given in the working folder, as seen from `folder`.
std::string rebased(const std::string& value, const fs::path& folder) {
  const fs::path p(value);
  if (value.empty() || p.is_absolute()) return value;
  const fs::path absolute = fs::absolute(p).lexically_normal();
  const fs::path rel = absolute.lexically_relative(fs::absolute(folder).lexically_normal());
  return rel.empty() ? value : rel.string();
}

nlohmann::json option_value(const CLI::Option& o, const fs::path& study_folder) {
  if (is_flag(o)) return true;
  const std::string name = long_name(o);
  const bool path = kPathOptions.count(name) > 0 ||
                    (kPresetOrPathOptions.count(name) > 0);
  auto one = [&](const std::string& text) -> nlohmann::json {
    if (is_number_option(o)) {
      try {
        const double v = to_double(text, name);
        if (std::floor(v) == v && std::abs(v) < 9e15) return std::int64_t(v);
        return v;
      } catch (const std::exception&) {
        return text;  // refused on the run exactly as when typed
      }
    }
    if (!path) return text;
    if (kPresetOrPathOptions.count(name) > 0 && !fs::exists(text)) return text;  // a preset
    return rebased(text, study_folder);
  };
  const std::vector<std::string>& results = o.results();
  if (takes_many(o)) {
    nlohmann::json a = nlohmann::json::array();
    for (const auto& r : results) a.push_back(one(r));
    return a;
  }
  return one(results.empty() ? std::string() : results.back());
}

/// A JSON value as the text the option would have been typed with.
std::string value_text(const nlohmann::json& v) {
  if (v.is_string()) return v.get<std::string>();
  if (v.is_number_integer()) return std::to_string(v.get<std::int64_t>());
  if (v.is_number_unsigned()) return std::to_string(v.get<std::uint64_t>());
  return v.dump();  // a double: the shortest text that reads back to it
}

std::string json_type(const nlohmann::json& v) {
  if (v.is_boolean()) return "true/false";
  if (v.is_number()) return "a number";
  if (v.is_string()) return "a string";
  if (v.is_array()) return "an array";
  if (v.is_object()) return "an object";
  return "null";
}

/// " (did you mean \"x\"?)" for a near miss, else "".
std::string did_you_mean(const std::string& word, const std::vector<std::string>& known) {
  const std::string best = nearest(word, known);
  return best.empty() ? "" : " (did you mean \"" + best + "\"?)";
}

}  // namespace

bool is_path_option(const CLI::Option& option) { return kPathOptions.count(long_name(option)) > 0; }
bool is_preset_or_path_option(const CLI::Option& option) {
  return kPresetOrPathOptions.count(long_name(option)) > 0;
}

std::vector<std::string> study_verbs(CLI::App& app) {
  std::vector<std::string> out;
  collect_verbs(app, "", out, nullptr);
  return out;
}

void add_save_study_options(CLI::App& app) {
  std::vector<std::string> paths;
  std::vector<CLI::App*> apps;
  collect_verbs(app, "", paths, &apps);
  for (CLI::App* verb : apps)
    verb->add_option("--save-study", "Also write this verb and its options as a study file "
                                     "(JSON; rerun with `spinesim run FILE`)")
        ->type_name("PATH")
        ->check(CLI::Validator(
            [](std::string& path) {  // before the work, so nothing is lost at its end
              try {
                output::require_output_folder(path, "--save-study");
                return std::string();
              } catch (const std::exception& e) {  // CLI11 puts the option's name first
                const std::string why = e.what(), name = "--save-study ";
                return why.rfind(name, 0) == 0 ? why.substr(name.size()) : why;
              }
            },
            "", "save-study folder"));
}

nlohmann::json study_of(CLI::App& verb, const std::string& verb_path,
                        const std::string& study_path) {
  fs::path folder = fs::path(study_path).parent_path();
  if (folder.empty()) folder = ".";
  nlohmann::json options = nlohmann::json::object();
  for (const CLI::Option* o : study_options(verb))
    if (o->count() > 0) options[long_name(*o)] = option_value(*o, folder);
  nlohmann::json study = {{"spinesim_study", kStudyFileVersion},
                          {"verb", verb_path},
                          {"options", options}};
  return study;
}

std::string save_study_if_asked(CLI::App& app) {
  std::string path;
  CLI::App* verb = parsed_verb(app, path);
  if (!verb) return "";
  const CLI::Option* save = verb->get_option_no_throw("--save-study");
  if (!save || save->count() == 0) return "";
  const std::string file = save->as<std::string>();
  output::write_json_file(file, study_of(*verb, path, file));
  return file;
}

std::vector<std::string> study_arguments(CLI::App& app, const nlohmann::json& study,
                                         const std::string& where) {
  const auto refuse = [&](const std::string& field, const std::string& why) {
    return std::invalid_argument(where + ": " + field + ": " + why);
  };
  if (!study.is_object()) throw std::invalid_argument(where + ": expected a JSON object");
  const std::vector<std::string> top = {"spinesim_study", "description", "verb", "options",
                                        "provenance"};
  for (const auto& item : study.items())
    if (std::find(top.begin(), top.end(), item.key()) == top.end())
      throw refuse(item.key(), "unknown field" + did_you_mean(item.key(), top) +
                                   " (known: spinesim_study, description, verb, options, "
                                   "provenance)");
  if (!study.contains("spinesim_study"))
    throw refuse("spinesim_study", "missing (the format's version, " +
                                       std::to_string(kStudyFileVersion) + ")");
  if (study.at("spinesim_study") != kStudyFileVersion)
    throw refuse("spinesim_study", "version " + study.at("spinesim_study").dump() +
                                       " is not one this program reads (" +
                                       std::to_string(kStudyFileVersion) + ")");
  if (study.contains("description")) {
    const auto& d = study.at("description");
    const bool lines = d.is_array() && std::all_of(d.begin(), d.end(),
                                                   [](const auto& x) { return x.is_string(); });
    if (!d.is_string() && !lines)
      throw refuse("description", "must be a string or an array of strings");
  }
  if (!study.contains("verb")) throw refuse("verb", "missing (e.g. \"fem\", \"study disc-validation\")");
  if (!study.at("verb").is_string()) throw refuse("verb", "must be a string, not " + json_type(study.at("verb")));
  const std::string verb_path = study.at("verb").get<std::string>();
  CLI::App* verb = find_verb(app, verb_path);
  if (!verb) {
    const std::vector<std::string> verbs = study_verbs(app);
    throw refuse("verb", "\"" + verb_path + "\" is not a verb of spinesim" +
                             did_you_mean(verb_path, verbs) + " (run --schema lists them)");
  }
  std::vector<std::string> argv;
  std::istringstream words(verb_path);
  for (std::string w; words >> w;) argv.push_back(w);
  if (!study.contains("options")) return argv;
  const nlohmann::json& options = study.at("options");
  if (!options.is_object()) throw refuse("options", "must be an object of option: value");
  const std::vector<const CLI::Option*> known = study_options(*verb);
  std::vector<std::string> names;
  for (const CLI::Option* o : known) names.push_back(long_name(*o));
  for (const auto& item : options.items()) {
    const std::string field = "options." + item.key();
    const auto it = std::find(names.begin(), names.end(), item.key());
    if (it == names.end())
      throw refuse(field, "not an option of `" + verb_path + "`" + did_you_mean(item.key(), names));
    const CLI::Option& o = *known[std::size_t(it - names.begin())];
    const nlohmann::json& v = item.value();
    const std::string flag = o.nonpositional() ? "--" + item.key() : "";
    if (is_flag(o)) {
      if (!v.is_boolean()) throw refuse(field, "a flag: true or false, not " + json_type(v));
      if (v.get<bool>()) argv.push_back(flag);
      continue;
    }
    const auto scalar = [&](const nlohmann::json& x) {
      if (x.is_string()) return;
      if (x.is_number() && is_number_option(o)) return;
      throw refuse(field, (is_number_option(o) ? "must be a number, not " : "must be a string, not ") +
                              json_type(x));
    };
    std::vector<std::string> values;
    if (v.is_array()) {
      if (!takes_many(o)) throw refuse(field, "takes one value, not an array");
      if (v.empty()) throw refuse(field, "an empty array: leave the option out instead");
      for (const auto& x : v) {
        scalar(x);
        values.push_back(value_text(x));
      }
    } else {
      scalar(v);
      values.push_back(value_text(v));
    }
    for (const auto& s : values) {  // "--force a --force b": also for one-value-per-flag options
      if (!flag.empty()) argv.push_back(flag);
      argv.push_back(s);
    }
  }
  return argv;
}

nlohmann::json study_schema(CLI::App& app) {
  std::vector<std::string> paths;
  std::vector<CLI::App*> apps;
  collect_verbs(app, "", paths, &apps);
  nlohmann::json per_verb = nlohmann::json::array();
  for (std::size_t i = 0; i < apps.size(); ++i) {
    nlohmann::json props = nlohmann::json::object();
    for (const CLI::Option* o : study_options(*apps[i])) {
      nlohmann::json one;
      if (is_flag(*o))
        one = {{"type", "boolean"}};
      else if (is_number_option(*o))
        one = {{"type", {"number", "string"}}};
      else
        one = {{"type", "string"}};
      if (!is_flag(*o) && takes_many(*o))
        one = {{"anyOf", {one, {{"type", "array"}, {"items", one}, {"minItems", 1}}}}};
      one["description"] = o->get_description();
      props[long_name(*o)] = one;
    }
    per_verb.push_back(
        {{"if", {{"properties", {{"verb", {{"const", paths[i]}}}}}}},
         {"then",
          {{"properties",
            {{"options",
              {{"type", "object"}, {"properties", props}, {"additionalProperties", false}}}}}}}});
  }
  nlohmann::json text = {{"type", "string"}};
  nlohmann::json lines = {{"type", "array"}, {"items", text}};
  nlohmann::json description = {{"anyOf", nlohmann::json::array({text, lines})}};
  return {{"$schema", "https://json-schema.org/draft/2020-12/schema"},
          {"title", "spinesim study file"},
          {"description",
           "One verb of the spinesim program with its options; run with `spinesim run FILE`. "
           "Relative paths are relative to the study file's folder."},
          {"type", "object"},
          {"required", {"spinesim_study", "verb"}},
          {"additionalProperties", false},
          {"properties",
           {{"spinesim_study", {{"const", kStudyFileVersion}}},
            {"description", description},
            {"verb", {{"enum", paths}}},
            {"options", {{"type", "object"}}},
            {"provenance", {{"type", "object"}}}}},
          {"allOf", per_verb}};
}

nlohmann::json rebase_study_inputs(CLI::App& app, nlohmann::json study, const std::string& from,
                                   const std::string& to) {
  CLI::App* verb = find_verb(app, study.value("verb", ""));
  if (!verb || !study.contains("options") || !study["options"].is_object()) return study;
  const fs::path base = fs::absolute(from).lexically_normal();
  const fs::path target = fs::absolute(to).lexically_normal();
  auto moved = [&](nlohmann::json& v) {
    if (!v.is_string()) return;
    const fs::path p(v.get<std::string>());
    std::error_code ec;
    if (p.empty() || p.is_absolute() || !fs::exists(base / p, ec)) return;
    v = (base / p).lexically_normal().lexically_relative(target).string();
  };
  // What a verb writes stays relative, even when a file of that name exists beside the plan: a
  // point's outputs go into its own folder, never over a file of the plan's.
  static const std::set<std::string> outputs = {
      "out", "csv", "record", "medit", "mesh-out", "write-scene", "screenshot", "save-study"};
  for (auto& item : study["options"].items()) {
    const CLI::Option* o = verb->get_option_no_throw("--" + item.key());
    if (!o || outputs.count(item.key()) > 0 ||
        !(is_path_option(*o) || is_preset_or_path_option(*o)))
      continue;
    if (item.value().is_array())
      for (auto& v : item.value()) moved(v);
    else
      moved(item.value());
  }
  return study;
}

}  // namespace spinesim::cli

#include "spinesim/calibration/tuned_set.hpp"

#include "json_file.hpp"

#include <filesystem>
#include <fstream>
#include <stdexcept>

namespace spinesim::calibration {

namespace {
constexpr const char* kSetFormat = "spinesim-tuned-disc-set";
constexpr int kSetVersion = 1;
}  // namespace

nlohmann::json to_json(const TunedSet& set) {
  nlohmann::json levels = nlohmann::json::object();
  for (const auto& [level, disc] : set.levels) levels[level] = to_json(disc);
  return {{"format", kSetFormat},          {"version", kSetVersion},
          {"material", set.material_name}, {"generated_by", set.generated_by},
          {"settings", set.settings},      {"levels", levels}};
}

TunedSet tuned_set_from_json(const nlohmann::json& j) {
  // A "format" that is not a string is not a set's (json::value would throw a type_error, which
  // is not a one-line refusal: the fuzzer found it); the single-disc reader then names the error.
  const auto format = j.is_object() ? j.find("format") : j.end();
  if (format == j.end() || !format->is_string() || *format != kSetFormat)
    throw std::invalid_argument(std::string("not a tuned-disc set (\"format\": \"") + kSetFormat +
                                "\" missing)");
  if (j.value("version", 0) != kSetVersion)
    throw std::invalid_argument("tuned-disc set version " +
                                j.value("version", nlohmann::json()).dump() + " is not supported");
  TunedSet set;
  set.material_name = j.value("material", "");
  set.generated_by = j.value("generated_by", "");
  set.settings = j.value("settings", nlohmann::json::object());
  if (!j.contains("levels") || !j["levels"].is_object() || j["levels"].empty())
    throw std::invalid_argument("tuned-disc set has no levels");
  for (const auto& [level, entry] : j["levels"].items()) {
    TunedDisc d;
    try {
      d = tuned_disc_from_json(entry);
    } catch (const std::invalid_argument& e) {
      throw std::invalid_argument("level " + level + ": " + e.what());
    }
    if (d.per_spring())
      throw std::invalid_argument("level " + level +
                                  ": per-spring scales belong to one mesh; a tuned set holds "
                                  "region-level scales that transfer");
    if (d.level != level)
      throw std::invalid_argument("level " + level + ": its entry says level '" + d.level + "'");
    if (d.material_name != set.material_name)
      throw std::invalid_argument("level " + level + ": material '" + d.material_name +
                                  "' is not the set's '" + set.material_name + "'");
    set.levels.emplace(level, std::move(d));
  }
  return set;
}

TunedSet read_tuned_set(const std::string& path) {
  const nlohmann::json j = detail::read_json_file(path, "tuned-disc set");
  return detail::naming_file(path, [&] { return tuned_set_from_json(j); });
}

std::string shipped_tuned_set_path(const std::string& data_dir) {
  return data_dir + "/tuned_discs.json";
}

std::string shipped_fibre_tuned_set_path(const std::string& data_dir) {
  return data_dir + "/tuned_fibre_discs.json";
}

std::string shipped_structured_tuned_set_path(const std::string& data_dir) {
  return data_dir + "/tuned_structured_discs.json";
}

std::string shipped_structured_fibre_tuned_set_path(const std::string& data_dir) {
  return data_dir + "/tuned_structured_fibre_discs.json";
}

std::string tuned_set_path(const std::string& params, const std::vector<ShippedSet>& shipped) {
  if (shipped.empty()) throw std::invalid_argument("tuned_set_path: no shipped sets");
  if (params.empty()) return shipped.front().path;
  std::string names;
  for (const ShippedSet& s : shipped) {
    if (params == s.name) return s.path;
    names += (names.empty() ? "" : ", ") + s.name;
  }
  if (!std::filesystem::exists(params))
    throw std::invalid_argument("--params '" + params +
                                "': no such file (or name a shipped set: " + names + ")");
  return params;
}

mesh::StructuredDiscOptions structured_resolution(const TunedSet& set) {
  mesh::StructuredDiscOptions o;
  const auto it = set.settings.find("structured");
  if (it == set.settings.end()) return o;
  try {
    o.sectors = it->at("sectors").get<int>();
    o.rings = it->at("rings").get<int>();
    o.layers = it->at("layers").get<int>();
    o.match_area = it->value("match_area", false);
  } catch (const nlohmann::json::exception&) {
    throw std::invalid_argument(
        "tuned set: settings.structured must have integer sectors, rings and layers (and a "
        "boolean match_area)");
  }
  mesh::validate(o);
  return o;
}

const TunedDisc& tuned_level(const TunedSet& set, const std::string& level) {
  auto it = set.levels.find(level);
  if (it != set.levels.end()) return it->second;
  std::string known;
  for (const auto& [name, _] : set.levels) known += (known.empty() ? "" : ", ") + name;
  throw std::invalid_argument("no tuned disc for level '" + level + "' (the set has " + known +
                              ")");
}

TunedDisc read_tuned_for_mesh(const std::string& path, const mesh::TetMesh* mesh) {
  const nlohmann::json j =
      detail::read_json_file(path, "tuned-disc file");  // read once, whichever kind
  // A "format" that is not a string is not a set's (json::value would throw a type_error, which
  // is not a one-line refusal: the fuzzer found it); the single-disc reader then names the error.
  const auto format = j.is_object() ? j.find("format") : j.end();
  if (format == j.end() || !format->is_string() || *format != kSetFormat)
    return detail::naming_file(path, [&] { return tuned_disc_from_json(j); });
  const TunedSet set = detail::naming_file(path, [&] { return tuned_set_from_json(j); });
  if (!mesh) return set.levels.begin()->second;
  const std::string level = disc_level(*mesh);
  if (level.empty())
    throw std::invalid_argument(
        "'" + path +
        "' holds one tuned disc per level, and this mesh's level is unknown: give "
        "that level's tuned.json");
  try {
    return tuned_level(set, level);
  } catch (const std::invalid_argument& e) {
    throw std::invalid_argument("'" + path + "': " + e.what());
  }
}

}  // namespace spinesim::calibration

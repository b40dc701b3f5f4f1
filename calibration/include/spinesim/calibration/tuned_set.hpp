// The shipped tuned discs: one region-level TunedDisc per spine level, one material, in one
// small JSON file (data/tuned_discs.json, written by `spinesim calibrate --level all`):
//   {"format": "spinesim-tuned-disc-set", "version": 1, "material": "real-disc",
//    "generated_by": "...", "settings": {"cell_size_mm": 2, ...}, "levels": {"T1-T2": {tuned disc}, ..., "L5-S1": {...}}}
// Each entry is exactly a tuned.json (tuned_disc.hpp), so the spine scene and the haptic loop
// load a level's parameters the same way `spinesim mss --params` loads a file.
#pragma once

#include "spinesim/calibration/tuned_disc.hpp"
#include "spinesim/mesh/structured_disc.hpp"

#include <map>
#include <string>
#include <vector>

namespace spinesim::calibration {

struct TunedSet {
  std::string material_name;
  std::string generated_by;  ///< the command that wrote it
  nlohmann::json settings =
      nlohmann::json::object();  ///< how to regenerate it (mesh cell size, ...)
  std::map<std::string, TunedDisc> levels;
};

nlohmann::json to_json(const TunedSet& set);
/// Parses and validates every entry (tuned_disc_from_json); all entries must share the set's
/// material, carry their own level and be region-level (a per-spring entry would not transfer to
/// the meshes the set is used on). Throws std::invalid_argument with a one-line message.
TunedSet tuned_set_from_json(const nlohmann::json& j);
TunedSet read_tuned_set(const std::string& path);

/// The shipped file's path under a data folder: DATA_DIR/tuned_discs.json.
std::string shipped_tuned_set_path(const std::string& data_dir);
/// The shipped fibre-network set (the nonlinear fibre-reinforced disc, fitted at the palpated
/// discs' resolution): DATA_DIR/tuned_fibre_discs.json.
std::string shipped_fibre_tuned_set_path(const std::string& data_dir);

/// The shipped sets of the spine's offline (structured) discs: the linear calibration
/// (DATA_DIR/tuned_structured_discs.json) and the fibre network of the nonlinear fibre-reinforced
/// disc (DATA_DIR/tuned_structured_fibre_discs.json).
std::string shipped_structured_tuned_set_path(const std::string& data_dir);
std::string shipped_structured_fibre_tuned_set_path(const std::string& data_dir);

/// A shipped set a command offers by name ("real-disc", "fibre-reinforced").
struct ShippedSet {
  std::string name;
  std::string path;
};
/// The tuned set a user named with --params: empty names the first of `shipped`; a shipped
/// set's name gives its path; anything else must be an existing file. Throws
/// std::invalid_argument (one line, listing the shipped names) otherwise.
std::string tuned_set_path(const std::string& params, const std::vector<ShippedSet>& shipped);

/// The structured-disc resolution a set was calibrated on (its settings' "structured" object,
/// written by `calibrate --level all --structured`); the default resolution when the set records
/// none. Throws std::invalid_argument (one line) for a malformed or invalid resolution.
mesh::StructuredDiscOptions structured_resolution(const TunedSet& set);

/// One level's entry; throws std::invalid_argument naming the levels present when missing.
const TunedDisc& tuned_level(const TunedSet& set, const std::string& level);

/// What `--params FILE` means: a tuned.json, or a tuned set from which the entry of `mesh`'s disc
/// level is taken (so `--params data/tuned_discs.json` works for any level's mesh). Without a
/// mesh (nullptr) a set gives its first entry (every entry has the same terms and material).
/// Throws std::invalid_argument for an unreadable file, or a set and a mesh of unknown or
/// missing level.
TunedDisc read_tuned_for_mesh(const std::string& path, const mesh::TetMesh* mesh);

}  // namespace spinesim::calibration

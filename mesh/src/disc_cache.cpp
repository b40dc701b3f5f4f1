#include "spinesim/mesh/disc_cache.hpp"

#include "cache_identity.hpp"

#include "spinesim/common/input_file.hpp"
#include "spinesim/mesh/io.hpp"

#include <cstdio>
#include <filesystem>
#include <sstream>

namespace spinesim::mesh {

namespace fs = std::filesystem;

std::string disc_cache_key(const std::string& level, const MeshOptions& o,
                           const std::string& data_dir) {
  std::ostringstream os;
  os.precision(17);
  os << "disc " << level << " program " << detail::program_identity() << " frame";
  const DiscFrame f = disc_level_frame(level, data_dir);
  for (int k = 0; k < 3; ++k) os << ' ' << f.origin_mm[k];
  for (int k = 0; k < 9; ++k) os << ' ' << f.axes(k / 3, k % 3);
  std::string morphometry;
  try {
    morphometry = read_regular_file((fs::path(data_dir) / "disc_morphometry.csv").string(),
                                    "the disc morphometry");
  } catch (const std::exception&) {  // the mesher says what is missing
  }
  os << " morphometry " << detail::fnv1a(morphometry) << " options " << o.cell_size_mm << ' '
     << o.facet_distance_mm << ' ' << o.facet_size_mm << ' ' << o.edge_size_mm << ' '
     << o.facet_angle_deg << ' ' << o.radius_edge_ratio << ' ' << o.odt << o.lloyd << o.perturb
     << o.exude << ' ' << o.seed;
  char hex[17];
  std::snprintf(hex, sizeof hex, "%016llx",
                static_cast<unsigned long long>(detail::fnv1a(os.str())));
  return os.str() + " hash " + hex;
}

TetMesh cached_disc_level(const std::string& level, const MeshOptions& options,
                          const std::string& data_dir, const std::string& cache_dir, bool* hit) {
  if (hit) *hit = false;
  if (cache_dir.empty()) return mesh_disc_level(level, options, data_dir);
  const std::string key = disc_cache_key(level, options, data_dir);
  char cell[32];
  std::snprintf(cell, sizeof cell, "%.3g", options.cell_size_mm);
  const std::string prefix = "disc-" + level + "-" + cell + "mm-";
  const std::string path =
      (fs::path(cache_dir) / (prefix + key.substr(key.size() - 16) + ".vtu")).string();
  std::error_code ec;
  if (fs::is_regular_file(path, ec)) {
    try {
      TetMesh m = read_vtu(path);
      // The file's source is the key, a newline and the mesh's own source.
      if (m.source.size() > key.size() && m.source.compare(0, key.size() + 1, key + "\n") == 0) {
        m.source.erase(0, key.size() + 1);
        if (hit) *hit = true;
        return m;
      }
    } catch (const std::exception&) {  // a damaged file: meshed again below, and replaced
    }
  }
  TetMesh m = mesh_disc_level(level, options, data_dir);
  try {  // a cache that cannot be written costs the next run time, nothing else
    fs::create_directories(cache_dir, ec);
    for (const auto& e : fs::directory_iterator(cache_dir, ec))
      if (e.path().filename().string().rfind(prefix, 0) == 0 && e.path().extension() == ".vtu" &&
          e.path().string() != path)
        fs::remove(e.path(), ec);
    TetMesh keyed = m;
    keyed.source = key + "\n" + m.source;  // the whole key: a hash collision is a miss
    write_vtu(path, keyed);
  } catch (const std::exception&) {}
  return m;
}

}  // namespace spinesim::mesh

#include "spinesim/mesh/vertebra_cache.hpp"

#include "cache_identity.hpp"

#include "spinesim/common/atomic_file.hpp"

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>

namespace spinesim::mesh {

namespace fs = std::filesystem;
using detail::fnv1a;
using detail::program_identity;

namespace {

constexpr char kMagic[8] = {'S', 'P', 'V', 'C', 'v', '1', '\n', '\0'};

void put(std::ostringstream& os, const Eigen::Vector3d& x) {
  for (int k = 0; k < 3; ++k) os << x[k] << ' ';
}

std::string file_prefix(const ParametricVertebra& v, int target_triangles) {
  return v.name + "-" + std::to_string(target_triangles) + "-";
}

// The surface in `path` when it is whole and carries `key`; false otherwise.
bool read_cached(const std::string& path, const std::string& key, TriSurface* s) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return false;
  char magic[8];
  std::uint64_t key_size = 0, nv = 0, nf = 0;
  if (!in.read(magic, 8) || !std::equal(magic, magic + 8, kMagic)) return false;
  if (!in.read(reinterpret_cast<char*>(&key_size), 8) || key_size != key.size()) return false;
  std::string stored(key_size, '\0');
  if (!in.read(stored.data(), std::streamsize(key_size)) || stored != key) return false;
  if (!in.read(reinterpret_cast<char*>(&nv), 8) || !in.read(reinterpret_cast<char*>(&nf), 8))
    return false;
  if (nv == 0 || nf == 0 || nv > (1u << 26) || nf > (1u << 26)) return false;
  Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor> V(Eigen::Index(nv), 3);
  Eigen::Matrix<int, Eigen::Dynamic, 3, Eigen::RowMajor> F(Eigen::Index(nf), 3);
  if (!in.read(reinterpret_cast<char*>(V.data()), std::streamsize(sizeof(double) * 3 * nv)) ||
      !in.read(reinterpret_cast<char*>(F.data()), std::streamsize(sizeof(int) * 3 * nf)))
    return false;
  if (in.peek() != std::char_traits<char>::eof()) return false;
  if (!V.allFinite() || F.minCoeff() < 0 || F.maxCoeff() >= int(nv)) return false;
  s->V = V;
  s->F = F;
  return true;
}

void write_cached(const std::string& path, const std::string& key, const TriSurface& s) {
  const Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor> V = s.V;
  const Eigen::Matrix<int, Eigen::Dynamic, 3, Eigen::RowMajor> F = s.F;
  write_atomically("vertebra cache", path, [&](std::ostream& os) {
    const std::uint64_t key_size = key.size(), nv = std::uint64_t(V.rows()),
                        nf = std::uint64_t(F.rows());
    os.write(kMagic, 8);
    os.write(reinterpret_cast<const char*>(&key_size), 8);
    os.write(key.data(), std::streamsize(key.size()));
    os.write(reinterpret_cast<const char*>(&nv), 8);
    os.write(reinterpret_cast<const char*>(&nf), 8);
    os.write(reinterpret_cast<const char*>(V.data()), std::streamsize(sizeof(double) * V.size()));
    os.write(reinterpret_cast<const char*>(F.data()), std::streamsize(sizeof(int) * F.size()));
  });
}

}  // namespace

std::string default_cache_dir() {
  if (const char* d = std::getenv("SPINESIM_CACHE_DIR"); d && *d) return d;
  if (const char* d = std::getenv("XDG_CACHE_HOME"); d && *d) return std::string(d) + "/spinesim";
  if (const char* d = std::getenv("HOME"); d && *d) return std::string(d) + "/.cache/spinesim";
  return "";
}

std::string vertebra_cache_key(const ParametricVertebra& v, int target_triangles) {
  std::ostringstream os;
  os.precision(17);
  os << "vertebra " << v.name << " triangles " << target_triangles << " program "
     << program_identity() << " frame ";
  put(os, v.frame.origin_mm);
  for (int k = 0; k < 3; ++k) put(os, v.frame.axes.col(k));
  os << "body " << v.body_height_mm << ' ' << v.lower_width_mm << ' ' << v.lower_depth_mm << ' '
     << v.upper_width_mm << ' ' << v.upper_depth_mm << ' ' << v.waist << " parts";
  for (const SweptBox& b : v.parts) {
    put(os, b.a);
    put(os, b.b);
    put(os, b.up);
    os << b.half_width_mm << ' ' << b.half_height_mm << ' ' << b.rounding_mm << ';';
  }
  char hex[17];
  std::snprintf(hex, sizeof hex, "%016llx", static_cast<unsigned long long>(fnv1a(os.str())));
  return os.str() + " hash " + hex;
}

VertebraSurface cached_vertebra_surface(const ParametricVertebra& v, int target_triangles,
                                        const std::string& cache_dir, bool* hit) {
  if (hit) *hit = false;
  if (cache_dir.empty()) return mesh_vertebra(v, target_triangles);
  const std::string key = vertebra_cache_key(v, target_triangles);
  const std::string prefix = file_prefix(v, target_triangles);
  const std::string path =
      (fs::path(cache_dir) / (prefix + key.substr(key.size() - 16) + ".bin")).string();
  VertebraSurface out;
  if (read_cached(path, key, &out.surface)) {
    out.name = v.name;
    out.frame = v.frame;
    if (hit) *hit = true;
    return out;
  }
  out = mesh_vertebra(v, target_triangles);
  try {  // a cache that cannot be written costs the next run time, nothing else
    std::error_code ec;
    fs::create_directories(cache_dir, ec);
    for (const auto& e : fs::directory_iterator(cache_dir, ec))
      if (e.path().filename().string().rfind(prefix, 0) == 0 && e.path().extension() == ".bin" &&
          e.path().string() != path)  // not another run's file being written (".bin.tmp-…")
        fs::remove(e.path(), ec);
    write_cached(path, key, out.surface);
  } catch (const std::exception&) {}
  return out;
}

}  // namespace spinesim::mesh

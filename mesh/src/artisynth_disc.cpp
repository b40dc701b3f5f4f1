// The ArtiSynth lumbosacral model's hexahedral discs as spinesim discs; see artisynth_disc.hpp.
#include "spinesim/mesh/artisynth_disc.hpp"

#include "spinesim/common/input_file.hpp"
#include "spinesim/mesh/io.hpp"

#include <Eigen/Geometry>

#include <algorithm>
#include <array>
#include <cmath>
#include <filesystem>
#include <map>
#include <sstream>
#include <stdexcept>

namespace spinesim::mesh {
namespace {

const std::vector<std::string> kRings = {"AN_R1", "AN_R2", "AN_R3", "AN_R4"};

std::string file(const std::string& folder, const std::string& prefix, const std::string& part,
                 const std::string& ext) {
  return folder + "/" + prefix + "_" + part + ext;
}

/// Rows of whitespace-separated numbers of a text file (empty lines skipped).
std::vector<std::vector<double>> rows(const std::string& path) {
  const std::string text = read_regular_file(path, "ArtiSynth disc file");
  std::vector<std::vector<double>> out;
  std::istringstream in(text);
  std::string line;
  for (int number = 1; std::getline(in, line); ++number) {
    std::istringstream words(line);
    std::vector<double> row;
    std::string w;
    while (words >> w) {
      char* end = nullptr;
      const double v = std::strtod(w.c_str(), &end);
      if (end == w.c_str() || *end != '\0' || !std::isfinite(v))
        throw std::invalid_argument(path + ":" + std::to_string(number) + ": '" + w +
                                    "' is not a number");
      row.push_back(v);
    }
    if (!row.empty()) out.push_back(std::move(row));
  }
  return out;
}

long id_of(double v, const std::string& path) {
  if (v != std::floor(v) || v < 1) throw std::invalid_argument(path + ": node id " + std::to_string(v) + " is not a positive integer");
  return long(v);
}

struct Parts {
  std::map<long, Eigen::Vector3d> nodes_m;         ///< id -> file coordinates, m
  std::vector<std::pair<std::array<long, 8>, int>> hexes;  ///< node ids, region
};

void read_part(const std::string& folder, const std::string& prefix, const std::string& part,
               int region, Parts& p) {
  const std::string node_file = file(folder, prefix, part, ".node");
  for (const auto& r : rows(node_file)) {
    if (r.size() != 4) throw std::invalid_argument(node_file + ": a node line needs id x y z");
    const long id = id_of(r[0], node_file);
    const Eigen::Vector3d x(r[1], r[2], r[3]);
    const auto [it, fresh] = p.nodes_m.emplace(id, x);
    if (!fresh && (it->second - x).norm() > 1e-12)
      throw std::invalid_argument(node_file + ": node " + std::to_string(id) +
                                  " has other coordinates than in another part");
  }
  const std::string elem_file = file(folder, prefix, part, ".elem");
  for (const auto& r : rows(elem_file)) {
    if (r.size() < 8) throw std::invalid_argument(elem_file + ": a hexahedron needs 8 node ids");
    std::array<long, 8> h{};
    for (int k = 0; k < 8; ++k) h[k] = id_of(r[k], elem_file);
    p.hexes.push_back({h, region});
  }
}

/// The six tets of a hexahedron (local order: 0-3 one face, 4-7 the opposite, 4+k above k) by
/// pulling from its lowest-numbered vertex; `index` gives each local vertex's global number.
std::vector<std::array<int, 4>> pulled_tets(const std::array<int, 8>& index) {
  static const int faces[6][4] = {{0, 1, 2, 3}, {4, 5, 6, 7}, {0, 1, 5, 4},
                                  {1, 2, 6, 5}, {2, 3, 7, 6}, {3, 0, 4, 7}};
  int apex = 0;
  for (int k = 1; k < 8; ++k)
    if (index[k] < index[apex]) apex = k;
  std::vector<std::array<int, 4>> tets;
  for (const auto& f : faces) {
    if (std::find(f, f + 4, apex) != f + 4) continue;
    int w = 0;  // the face's lowest-numbered vertex: its diagonal runs from there
    for (int k = 1; k < 4; ++k)
      if (index[f[k]] < index[f[w]]) w = k;
    const int a = f[w], b = f[(w + 1) % 4], c = f[(w + 2) % 4], d = f[(w + 3) % 4];
    tets.push_back({index[apex], index[a], index[b], index[c]});
    tets.push_back({index[apex], index[a], index[c], index[d]});
  }
  return tets;
}

std::vector<long> id_list(const std::string& path) {
  std::vector<long> ids;
  for (const auto& r : rows(path))
    for (double v : r) ids.push_back(id_of(v, path));
  return ids;
}

/// Area centroid of the boundary faces whose three vertices carry `label`.
Eigen::Vector3d endplate_centroid(const TetMesh& m, int label) {
  const Eigen::MatrixX3i faces = boundary_faces(m.T);
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  double area = 0;
  for (Eigen::Index f = 0; f < faces.rows(); ++f) {
    if (m.surface(faces(f, 0)) != label || m.surface(faces(f, 1)) != label ||
        m.surface(faces(f, 2)) != label)
      continue;
    const Eigen::Vector3d a = m.V.row(faces(f, 0)), b = m.V.row(faces(f, 1)), c = m.V.row(faces(f, 2));
    const double A = 0.5 * (b - a).cross(c - a).norm();
    sum += A * (a + b + c) / 3;
    area += A;
  }
  if (!(area > 0)) throw std::invalid_argument("ArtiSynth disc: no endplate faces labelled " + std::to_string(label));
  return sum / area;
}

DiscFrame disc_frame(const TetMesh& m) {
  const Eigen::Vector3d lower = endplate_centroid(m, 1), upper = endplate_centroid(m, 2);
  DiscFrame f;
  f.origin_mm = 0.5 * (lower + upper);
  const Eigen::Vector3d y = (upper - lower).normalized();
  const Eigen::Vector3d z = (Eigen::Vector3d::UnitZ() - y.z() * y).normalized();
  f.axes << y.cross(z), y, z;
  return f;
}

}  // namespace

std::string artisynth_level_prefix(const std::string& level) {
  static const std::map<std::string, std::string> table = {
      {"L1-L2", "L12"}, {"L2-L3", "L23"}, {"L3-L4", "L34"}, {"L4-L5", "L45"}, {"L5-S1", "L51"},
      {"L12", "L12"},   {"L23", "L23"},   {"L34", "L34"},   {"L45", "L45"},   {"L51", "L51"}};
  const auto it = table.find(level);
  if (it == table.end())
    throw std::invalid_argument("the ArtiSynth model has no disc '" + level +
                                "' (L1-L2, L2-L3, L3-L4, L4-L5, L5-S1)");
  return it->second;
}

TetMesh read_artisynth_disc(const std::string& folder, const std::string& level) {
  const std::string prefix = artisynth_level_prefix(level);
  Parts p;
  for (const auto& ring : kRings) read_part(folder, prefix, ring, int(Region::annulus), p);
  read_part(folder, prefix, "NP", int(Region::nucleus), p);
  // Nodes in id order; metres to mm in our frame.
  std::map<long, int> index;
  TetMesh m;
  m.V.resize(Eigen::Index(p.nodes_m.size()), 3);
  for (const auto& [id, x] : p.nodes_m) {
    const int i = int(index.size());
    index[id] = i;
    m.V.row(i) = to_spinesim_frame(1000.0 * x, UpAxis::z).transpose();
  }
  std::vector<std::array<int, 4>> tets;
  std::vector<int> regions;
  for (const auto& [hex, region] : p.hexes) {
    std::array<int, 8> h{};
    for (int k = 0; k < 8; ++k) {
      const auto it = index.find(hex[k]);
      if (it == index.end())
        throw std::invalid_argument(prefix + ": a hexahedron uses node " + std::to_string(hex[k]) +
                                    ", which no .node file gives");
      h[k] = it->second;
    }
    for (auto t : pulled_tets(h)) {
      Eigen::Matrix3d J;
      J << m.V.row(t[1]) - m.V.row(t[0]), m.V.row(t[2]) - m.V.row(t[0]), m.V.row(t[3]) - m.V.row(t[0]);
      const double det = J.transpose().determinant();
      if (!(std::abs(det) > 1e-9)) throw std::invalid_argument(prefix + ": a hexahedron splits into a degenerate tetrahedron");
      if (det < 0) std::swap(t[2], t[3]);
      tets.push_back(t);
      regions.push_back(region);
    }
  }
  m.T.resize(Eigen::Index(tets.size()), 4);
  m.region.resize(Eigen::Index(tets.size()));
  for (std::size_t t = 0; t < tets.size(); ++t) {
    for (int k = 0; k < 4; ++k) m.T(Eigen::Index(t), k) = tets[t][k];
    m.region(Eigen::Index(t)) = regions[t];
  }
  // Labels: the outer wall first, the endplates over it.
  m.surface = Eigen::VectorXi::Zero(m.V.rows());
  const auto label = [&](const std::string& path, int value) {
    for (long id : id_list(path)) {
      const auto it = index.find(id);
      if (it == index.end()) throw std::invalid_argument(path + ": unknown node " + std::to_string(id));
      m.surface(it->second) = value;
    }
  };
  label(file(folder, prefix, "AN_R4A", ".txt"), int(Surface::outer_wall));
  for (const auto& part : {"AN_R1", "AN_R2", "AN_R3", "AN_R4", "NP"}) {
    label(file(folder, prefix, std::string(part) + "U", ".txt"), int(Surface::inferior_endplate));
    label(file(folder, prefix, std::string(part) + "O", ".txt"), int(Surface::superior_endplate));
  }
  m.frame = disc_frame(m);
  m.source = "ArtiSynth lumbosacral spine (Remus 2021) disc " + prefix;
  validate(m);
  return m;
}

PeerFibres read_artisynth_fibres(const std::string& folder, const std::string& level) {
  const std::string prefix = artisynth_level_prefix(level);
  std::map<long, Eigen::Vector3d> nodes;
  for (const std::string part : {"AN_R1", "AN_R2", "AN_R3", "AN_R4"})
    for (const auto& r : rows(file(folder, prefix, part, ".node")))
      if (r.size() == 4) nodes[long(r[0])] = to_spinesim_frame(1000.0 * Eigen::Vector3d(r[1], r[2], r[3]), UpAxis::z);
  PeerFibres out;
  for (int ring = 1; ring <= 4; ++ring)
    for (const char* side : {"A", "I"}) {
      const std::string path = file(folder, prefix, "AN_R" + std::to_string(ring) + side, ".fiber");
      // Only some rings have an inner-face file; each file holds both crossing families.
      if (std::string(side) == "I" && !std::filesystem::exists(path)) continue;
      std::istringstream in(read_regular_file(path, "ArtiSynth fibre file"));
      std::string line;
      std::getline(in, line);  // the count
      while (std::getline(in, line)) {
        std::istringstream w(line);
        std::vector<Eigen::Vector3d> path_mm;
        long id = 0;
        while (w >> id) {
          const auto it = nodes.find(id);
          if (it == nodes.end()) throw std::invalid_argument(path + ": unknown node " + std::to_string(id));
          path_mm.push_back(it->second);
        }
        if (path_mm.size() >= 2) {
          out.paths.push_back(std::move(path_mm));
          out.ring.push_back(ring);
        } else if (line.find("end") != std::string::npos) {
          break;
        }
      }
    }
  if (out.paths.empty()) throw std::invalid_argument(prefix + ": no fibres in the .fiber files");
  return out;
}

PeerFibreField peer_fibre_field(const TetMesh& m, const PeerFibres& fibres) {
  struct Segment {
    Eigen::Vector3d a, d;  ///< start, unit direction
    double length;
  };
  std::vector<Segment> segments;
  for (const auto& path : fibres.paths)
    for (std::size_t k = 0; k + 1 < path.size(); ++k) {
      const Eigen::Vector3d e = path[k + 1] - path[k];
      if (e.norm() > 0) segments.push_back({path[k], e.normalized(), e.norm()});
    }
  const auto distance = [](const Segment& s, const Eigen::Vector3d& c) {
    const double t = std::clamp((c - s.a).dot(s.d), 0.0, s.length);
    return (s.a + t * s.d - c).norm();
  };
  PeerFibreField f;
  f.direction_1 = Eigen::MatrixX3d::Zero(m.num_tets(), 3);
  f.direction_2 = Eigen::MatrixX3d::Zero(m.num_tets(), 3);
  const double cos20 = std::cos(20.0 * M_PI / 180.0);
  for (Eigen::Index t = 0; t < m.num_tets(); ++t) {
    if (m.region(t) != int(Region::annulus)) continue;
    Eigen::Vector3d c = Eigen::Vector3d::Zero();
    for (int k = 0; k < 4; ++k) c += 0.25 * m.V.row(m.T(t, k)).transpose();
    const Segment* first = nullptr;
    double best = 1e300;
    for (const auto& s : segments)
      if (const double d = distance(s, c); d < best) best = d, first = &s;
    if (!first) continue;
    const Segment* second = nullptr;
    best = 1e300;
    for (const auto& s : segments)
      if (std::abs(s.d.dot(first->d)) < cos20)
        if (const double d = distance(s, c); d < best) best = d, second = &s;
    f.direction_1.row(t) = first->d.transpose();
    if (second) f.direction_2.row(t) = second->d.transpose();
  }
  return f;
}

}  // namespace spinesim::mesh

// Structured (sweep) disc mesh — see structured_disc.hpp for the construction.
#include "spinesim/mesh/structured_disc.hpp"
#include "spinesim/common/constants.hpp"

#include <Eigen/Dense>

#include <algorithm>
#include <array>
#include <cassert>
#include <cmath>
#include <stdexcept>
#include <string>
#include <vector>

namespace spinesim::mesh {
namespace {

// One triangle of the cross-section: node indices within a layer, and its region.
struct SectionTriangle {
  std::array<int, 3> v;
  Region region;
};

// Layer-local node numbering: 0 = centre, 1 + (k - 1) sectors + i = ring k (1-based), sector i.
struct SectionNumbering {
  int sectors, rings;
  int per_layer() const { return 1 + rings * sectors; }
  int ring_node(int k, int i) const { return 1 + (k - 1) * sectors + (i % sectors); }
};

double cross2(const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
  return a.x() * b.y() - a.y() * b.x();
}

// `sectors` curve parameters θ_i of `o`, equally spaced in arc length, counter-clockwise from
// the posterior midpoint θ = -π/2 (the bottom of the notch). Arc length from a 4096-chord
// polyline, inverted by linear interpolation: the points are exactly on the curve, equally
// spaced to the accuracy of that polyline.
std::vector<double> equal_arc_angles(const KidneyOutline& o, int sectors) {
  constexpr int kChords = 4096;
  std::vector<double> arc(kChords + 1, 0.0);
  auto theta = [&](double k) { return -0.5 * kPi + 2 * kPi * k / kChords; };
  for (int k = 0; k < kChords; ++k)
    arc[k + 1] = arc[k] + (o.point(theta(k + 1)) - o.point(theta(k))).norm();
  std::vector<double> angles(static_cast<std::size_t>(sectors));
  for (int i = 0; i < sectors; ++i) {
    const double target = arc.back() * i / sectors;
    const auto it = std::upper_bound(arc.begin(), arc.end(), target);
    const int k = int(it - arc.begin()) - 1;  // arc[k] <= target < arc[k + 1]
    angles[std::size_t(i)] = theta(k + (target - arc[k]) / (arc[k + 1] - arc[k]));
  }
  return angles;
}

// (x, z) of every node of one layer's cross-section at height y, mm: the centroid, then the
// rings (outline points at `angles`, scaled by s · area_factor about the centroid).
std::vector<Eigen::Vector2d> section_points(const ParametricDisc& disc, double y_mm,
                                            const SectionNumbering& num,
                                            const std::vector<double>& scales,
                                            const std::vector<double>& angles, bool match_area) {
  const KidneyOutline o = disc.outline_at(y_mm);
  const Eigen::Vector2d c = o.centroid_mm();
  std::vector<Eigen::Vector2d> rim;
  for (double t : angles) rim.push_back(o.point(t) - c);
  double factor = 1.0;
  if (match_area) {  // stretch the rim polygon about the centroid to the outline's exact area
    double twice_area = 0;
    for (std::size_t i = 0; i < rim.size(); ++i)
      twice_area += cross2(rim[i], rim[(i + 1) % rim.size()]);
    factor = std::sqrt(2 * o.area_mm2() / twice_area);
  }
  std::vector<Eigen::Vector2d> p;
  p.reserve(std::size_t(num.per_layer()));
  p.push_back(c);
  for (double s : scales)
    for (const Eigen::Vector2d& q : rim) p.push_back(c + s * factor * q);
  return p;
}

// Fan + split quads; quads split along the shorter diagonal of the section `p`.
std::vector<SectionTriangle> triangulate_section(const SectionNumbering& num, int nucleus_rings,
                                                 const std::vector<Eigen::Vector2d>& p) {
  std::vector<SectionTriangle> tris;
  for (int i = 0; i < num.sectors; ++i)
    tris.push_back({{0, num.ring_node(1, i), num.ring_node(1, i + 1)}, Region::nucleus});
  for (int k = 1; k < num.rings; ++k) {
    const Region region = k + 1 <= nucleus_rings ? Region::nucleus : Region::annulus;
    for (int i = 0; i < num.sectors; ++i) {
      // Counter-clockwise in (x, z), like the fan: inner i, outer i, outer i+1, inner i+1.
      const int a = num.ring_node(k, i), b = num.ring_node(k + 1, i);
      const int c = num.ring_node(k + 1, i + 1), d = num.ring_node(k, i + 1);
      if ((p[a] - p[c]).squaredNorm() <= (p[b] - p[d]).squaredNorm()) {
        tris.push_back({{a, b, c}, region});
        tris.push_back({{a, c, d}, region});
      } else {
        tris.push_back({{a, b, d}, region});
        tris.push_back({{b, c, d}, region});
      }
    }
  }
  return tris;
}

// Every section triangle must keep one orientation (nested rings, no fold-over).
void check_section(const std::vector<SectionTriangle>& tris, const std::vector<Eigen::Vector2d>& p,
                   const std::string& level) {
  double scale2 = 0;
  for (const auto& q : p) scale2 = std::max(scale2, q.squaredNorm());
  for (const auto& t : tris) {
    const double a2 = cross2(p[t.v[1]] - p[t.v[0]], p[t.v[2]] - p[t.v[0]]);
    if (!(a2 > 1e-9 * scale2))
      throw std::runtime_error(
          "structured disc " + level +
          ": degenerate or folded cross-section triangle (outline not star-shaped "
          "about its centroid at this resolution)");
  }
}

double signed_volume6(const Eigen::MatrixX3d& V, const std::array<int, 4>& t) {
  const Eigen::Vector3d a = V.row(t[0]), b = V.row(t[1]), c = V.row(t[2]), d = V.row(t[3]);
  return (b - a).cross(c - a).dot(d - a);
}

}  // namespace

void validate(const StructuredDiscOptions& opt) {
  if (opt.sectors < 6 || opt.rings < 2 || opt.layers < 1)
    throw std::invalid_argument(
        "structured disc: need sectors >= 6, rings >= 2 (rim and nucleus boundary), "
        "layers >= 1 (got " +
        std::to_string(opt.sectors) + ", " + std::to_string(opt.rings) + ", " +
        std::to_string(opt.layers) + ")");
  // tets = 3 layers sectors (2 rings - 1), in double: the product of absurd counts overflows int.
  const double tets = 3.0 * opt.layers * opt.sectors * (2.0 * opt.rings - 1.0);
  if (tets > opt.max_elements)
    throw std::invalid_argument(
        "structured disc: " + std::to_string(opt.sectors) + " sectors, " +
        std::to_string(opt.rings) + " rings and " + std::to_string(opt.layers) + " layers make " +
        std::to_string(static_cast<long long>(tets)) + " tetrahedra, more than the limit of " +
        std::to_string(static_cast<long long>(opt.max_elements)));
}

std::vector<double> structured_ring_scales(int rings) {
  if (rings < 2)
    throw std::invalid_argument("structured disc: need rings >= 2 (got " + std::to_string(rings) +
                                ")");
  const double sn = std::sqrt(kNucleusAreaFraction);
  const int nn = std::clamp(int(std::lround(rings * sn)), 1, rings - 1);
  const int na = rings - nn;
  std::vector<double> s;
  for (int k = 1; k <= nn; ++k)
    s.push_back(k == nn ? sn : sn * std::sqrt(double(k) / nn));  // equal areas
  for (int k = 1; k <= na; ++k) s.push_back(k == na ? 1.0 : sn + (1.0 - sn) * k / na);
  return s;
}

TetMesh mesh_structured_disc(const DiscDimensions& dims, const StructuredDiscOptions& opt,
                             const DiscFrame& placement) {
  validate(opt);
  const ParametricDisc disc(dims);
  const std::vector<double> scales = structured_ring_scales(opt.rings);
  const int nucleus_rings = int(std::count_if(
      scales.begin(), scales.end(), [](double s) { return s <= std::sqrt(kNucleusAreaFraction); }));
  const SectionNumbering num{opt.sectors, opt.rings};
  const int n = num.per_layer();
  const double h = dims.height_mm;
  // One set of curve parameters for every layer: each section is then the same polygon
  // stretched in x and z about the centroid, so triangles keep their orientation.
  const std::vector<double> angles = equal_arc_angles(disc.outline_at(0.0), opt.sectors);
  auto section = [&](double y) {
    return section_points(disc, y, num, scales, angles, opt.match_area);
  };

  // 1. Nodes, layer by layer (global index = layer · n + layer-local index).
  TetMesh m;
  m.V.resize(Eigen::Index(opt.layers + 1) * n, 3);
  m.surface = Eigen::VectorXi::Zero(m.V.rows());
  for (int l = 0; l <= opt.layers; ++l) {
    const double y = l == opt.layers ? 0.5 * h : -0.5 * h + h * l / opt.layers;
    const auto p = section(y);
    for (int j = 0; j < n; ++j) {
      const Eigen::Index v = Eigen::Index(l) * n + j;
      m.V.row(v) << p[std::size_t(j)].x(), y, p[std::size_t(j)].y();
      if (l == 0)
        m.surface(v) = int(Surface::inferior_endplate);
      else if (l == opt.layers)
        m.surface(v) = int(Surface::superior_endplate);
      else if (j >= num.ring_node(opt.rings, 0))
        m.surface(v) = int(Surface::outer_wall);
    }
  }

  // 2. Cross-section triangulation, checked at both endplates (the sections in between are
  //    stretched copies of them).
  const auto tris = triangulate_section(num, nucleus_rings, section(0.0));
  check_section(tris, section(-0.5 * h), dims.level);
  check_section(tris, section(0.5 * h), dims.level);

  // 3. Sweep: prism (a, b, c) × layer with a < b < c, vertical quads split from their
  //    lowest-index vertex: tets (a b c c'), (a b b' c'), (a a' b' c').
  m.T.resize(Eigen::Index(3) * opt.layers * Eigen::Index(tris.size()), 4);
  m.region.resize(m.T.rows());
  Eigen::Index t = 0;
  for (int l = 0; l < opt.layers; ++l) {
    for (const SectionTriangle& tri : tris) {
      std::array<int, 3> s = tri.v;
      std::sort(s.begin(), s.end());
      const int a = l * n + s[0], b = l * n + s[1], c = l * n + s[2];
      const int a1 = a + n, b1 = b + n, c1 = c + n;
      for (std::array<int, 4> tet :
           {std::array<int, 4>{a, b, c, c1}, std::array<int, 4>{a, b, b1, c1},
            std::array<int, 4>{a, a1, b1, c1}}) {
        if (signed_volume6(m.V, tet) < 0) std::swap(tet[2], tet[3]);
        assert(signed_volume6(m.V, tet) > 0);
        m.T.row(t) << tet[0], tet[1], tet[2], tet[3];
        m.region(t++) = int(tri.region);
      }
    }
  }
  m.source = "structured disc " + dims.level + " (" + std::to_string(opt.sectors) + " sectors, " +
             std::to_string(opt.rings) + " rings, " + std::to_string(opt.layers) + " layers" +
             (opt.match_area ? ", area-matched)" : ")");

  // 4. Placement: x' = origin + axes x (as mesh_parametric_disc).
  m.V = (m.V * placement.axes.transpose()).rowwise() + placement.origin_mm.transpose();
  if (placement.axes.determinant() < 0) m.T.col(1).swap(m.T.col(2));  // mirrored frame
  m.frame = placement;
  return m;
}

}  // namespace spinesim::mesh

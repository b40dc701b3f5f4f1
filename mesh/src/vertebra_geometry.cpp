// Parametric vertebrae and the schematic sacrum (vertebra_geometry.hpp).
#include "spinesim/mesh/vertebra_geometry.hpp"
#include "spinesim/common/constants.hpp"

#include "spinesim/common/atomic_file.hpp"
#include "spinesim/common/csv_table.hpp"
#include "spinesim/mesh/disc_geometry.hpp"
#include "spinesim/mesh/mesher.hpp"

#include <Eigen/Geometry>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <filesystem>
#include <iomanip>
#include <map>
#include <stdexcept>
#include <utility>

namespace spinesim::mesh {
namespace {

namespace fs = std::filesystem;

// Assumptions that have no per-level column (also stated in data/vertebra_morphometry.csv):
// the C7-T1 disc, which places T1's upper endplate, is 5 mm high (the thoracic discs of
// disc_morphometry.csv are 4.5-7.2 mm), and the first sacral segment is 24 mm high.
constexpr double kC7T1DiscHeightMm = 5.0;
constexpr double kSacralBodyHeightMm = 24.0;

std::string upper(std::string s) {
  for (char& c : s) c = char(std::toupper(static_cast<unsigned char>(c)));
  return s;
}

std::string canonical_body(const std::string& name) {
  const std::string n = upper(trim(name));
  const auto& known = scene_body_names();
  if (std::find(known.begin(), known.end(), n) != known.end()) return n;
  std::string list;
  for (const auto& k : known) list += (list.empty() ? "" : ", ") + k;
  throw std::invalid_argument("unknown vertebra '" + name + "' (known: " + list + ")");
}

double lerp(double a, double b, double t) { return a + (b - a) * t; }

// The kidney outline of unit width and depth: a body's cross-section of width w and depth d is
// this one scaled by (w, d) about the centroid, so one outline serves every query.
const KidneyOutline& unit_outline() {
  static const KidneyOutline outline(1.0, 1.0);
  return outline;
}

// Frame from two axis points: y from `bottom` to `top`, x = global x made orthogonal to y.
DiscFrame body_frame(const Eigen::Vector3d& bottom, const Eigen::Vector3d& top) {
  DiscFrame f;
  f.origin_mm = 0.5 * (bottom + top);
  const Eigen::Vector3d y = (top - bottom).normalized();
  Eigen::Vector3d x = (Eigen::Vector3d::UnitX() - y.x() * y).normalized();
  Eigen::Vector3d z = x.cross(y);
  if (z.z() < 0) {
    x = -x;
    z = -z;
  }
  f.axes.col(0) = x;
  f.axes.col(1) = y;
  f.axes.col(2) = z;
  return f;
}

SweptBox swept(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& up,
               double half_width, double half_height) {
  SweptBox s;
  s.a = a;
  s.b = b;
  s.up = up;
  s.half_width_mm = half_width;
  s.half_height_mm = half_height;
  s.rounding_mm = 0.9 * std::min(half_width, half_height);
  return s;
}

// The neural arch of a thoracic or lumbar vertebra in its local frame (see the header).
std::vector<SweptBox> neural_arch(const VertebraMorphometry& m, const ParametricVertebra& v) {
  const double H = v.body_height_mm;
  const double ph = std::min(m.pedicle_height_mm, 0.6 * H);
  const double pw = m.pedicle_width_mm;
  const double yp = H / 2 - 0.5 * ph - 0.1 * H;  // pedicles leave the upper half of the body
  const double depth = lerp(v.lower_depth_mm, v.upper_depth_mm, (yp + H / 2) / H);
  const double z_wall = unit_outline().min_z_mm() * depth;  // posterior wall of the body
  const double xp = m.canal_width_mm / 2 + pw / 2;
  const Eigen::Vector3d Y = Eigen::Vector3d::UnitY();

  std::vector<SweptBox> parts;
  const double lamina_half_h = m.lamina_height_fraction * H / 2;
  const Eigen::Vector3d mid(0, yp - 0.1 * H, z_wall - m.canal_depth_mm - m.lamina_thickness_mm / 2);
  for (double side : {-1.0, 1.0}) {
    // The pedicle leaves the body well inside its outline and converges medially towards it
    // (the transverse pedicle angle), so the arch is joined to the body, not tangent to it.
    const double width = lerp(v.lower_width_mm, v.upper_width_mm, (yp + H / 2) / H);
    const Eigen::Vector3d root(side * std::min(xp, 0.3 * width), yp, z_wall + 0.5 * pw);
    const Eigen::Vector3d pillar(side * xp, yp, z_wall - 0.45 * m.canal_depth_mm);
    parts.push_back(swept(root, pillar, Y, pw / 2, ph / 2));                           // pedicle
    parts.push_back(swept(pillar, mid, Y, m.lamina_thickness_mm / 2, lamina_half_h));  // lamina
    // Transverse process: from the pillar, swept back and raised by the table's angles.
    const double sweep = m.transverse_sweep_deg * kRadPerDeg,
                 rise = m.transverse_rise_deg * kRadPerDeg;
    const Eigen::Vector3d dir(side * std::cos(sweep) * std::cos(rise), std::sin(rise),
                              -std::sin(sweep) * std::cos(rise));
    const double length = std::max(m.transverse_span_mm / 2 - xp, 2.0 * m.facet_radius_mm);
    parts.push_back(
        swept(pillar, pillar + length * dir, Y, m.facet_radius_mm, 1.3 * m.facet_radius_mm));
    // Articular processes: superior from the pillar upward, inferior from the lamina downward,
    // both leaning back.
    const Eigen::Vector3d lean(0, 1, -0.3);
    const Eigen::Vector3d sup = pillar + Eigen::Vector3d(0, 0.25 * ph, -1.0);
    parts.push_back(swept(sup, sup + m.facet_length_mm * lean.normalized(),
                          Eigen::Vector3d::UnitZ(), m.facet_radius_mm, m.facet_radius_mm));
    const Eigen::Vector3d inf_root =
        mid + 0.75 * (pillar - mid) - Eigen::Vector3d(0, 0.6 * lamina_half_h, 0);
    const Eigen::Vector3d down(0, -1, -0.3);
    parts.push_back(swept(inf_root, inf_root + m.facet_length_mm * down.normalized(),
                          Eigen::Vector3d::UnitZ(), m.facet_radius_mm, m.facet_radius_mm));
  }
  const double alpha = m.spinous_angle_deg * kRadPerDeg;
  const Eigen::Vector3d spine_dir(0, -std::sin(alpha), -std::cos(alpha));
  parts.push_back(swept(mid, mid + m.spinous_length_mm * spine_dir,
                        Eigen::Vector3d(0, std::cos(alpha), -std::sin(alpha)),
                        m.spinous_thickness_mm / 2, m.spinous_height_mm / 2));
  return parts;
}

// The sacrum below the S1 body: wings, a plate running down and back, the S1 superior
// articular processes and a median crest. Every size is an assumption (a schematic sacrum,
// about 100 mm wide and 100 mm long, data/vertebra_morphometry.csv notes).
std::vector<SweptBox> sacral_parts(const ParametricVertebra& v) {
  const double H = v.body_height_mm, D = v.lower_depth_mm;
  const Eigen::Vector3d X = Eigen::Vector3d::UnitX(), Y = Eigen::Vector3d::UnitY();
  std::vector<SweptBox> parts;
  parts.push_back(swept({-48, -0.1 * H, -0.25 * D}, {48, -0.1 * H, -0.25 * D}, Y, 12, 11));
  const Eigen::Vector3d top(0, 0, -0.45 * D);
  const Eigen::Vector3d down_back(0, -std::cos(35 * kRadPerDeg), -std::sin(35 * kRadPerDeg));
  const Eigen::Vector3d plate_end = top + 55 * down_back;
  const Eigen::Vector3d plate_up = down_back.cross(X);  // the plate is wide along x
  parts.push_back(swept(top, plate_end, X, 9, 40));
  parts.back().up = X;
  const Eigen::Vector3d tip = plate_end + 50 * Eigen::Vector3d(0, -0.9, 0.2).normalized();
  parts.push_back(swept(plate_end, tip, X, 7, 18));
  for (double side : {-1.0, 1.0}) {
    const Eigen::Vector3d root(side * 16, H / 2 - 4, -0.5 * D - 8);
    parts.push_back(swept(root, root + Eigen::Vector3d(0, 12, -4), Eigen::Vector3d::UnitZ(), 5, 5));
  }
  parts.push_back(swept(top - 6 * plate_up, plate_end - 12 * plate_up, X, 4, 5));
  return parts;
}

}  // namespace

const std::vector<std::string>& scene_body_names() {
  static const std::vector<std::string> names = {"T1", "T2", "T3", "T4",  "T5",  "T6",
                                                 "T7", "T8", "T9", "T10", "T11", "T12",
                                                 "L1", "L2", "L3", "L4",  "L5",  "S1"};
  return names;
}

VertebraMorphometry vertebra_morphometry(const std::string& level, const std::string& data_dir) {
  const std::string name = canonical_body(level);
  if (name == "S1")
    throw std::invalid_argument("vertebra_morphometry: the sacrum has no row (it is schematic)");
  const auto table = read_csv((fs::path(data_dir) / "vertebra_morphometry.csv").string());
  const std::size_t row = table.find("level", name);
  auto num = [&](const char* column) {
    const double x = table.number(row, column);
    if (!(x >= 0))
      throw std::invalid_argument(table.path + " " + name + " " + column + ": negative");
    return x;
  };
  VertebraMorphometry m;
  m.level = name;
  m.pedicle_width_mm = num("pedicle_width_mm");
  m.pedicle_height_mm = num("pedicle_height_mm");
  m.canal_width_mm = num("canal_width_mm");
  m.canal_depth_mm = num("canal_depth_mm");
  m.lamina_thickness_mm = num("lamina_thickness_mm");
  m.lamina_height_fraction = num("lamina_height_fraction");
  m.spinous_length_mm = num("spinous_length_mm");
  m.spinous_height_mm = num("spinous_height_mm");
  m.spinous_thickness_mm = num("spinous_thickness_mm");
  m.spinous_angle_deg = num("spinous_angle_deg");
  m.transverse_span_mm = num("transverse_span_mm");
  m.transverse_sweep_deg = num("transverse_sweep_deg");
  m.transverse_rise_deg = num("transverse_rise_deg");
  m.facet_radius_mm = num("facet_radius_mm");
  m.facet_length_mm = num("facet_length_mm");
  return m;
}

double SweptBox::signed_distance(const Eigen::Vector3d& p) const {
  const Eigen::Vector3d axis = b - a;
  const double length = axis.norm();
  const Eigen::Vector3d t = length > 0 ? Eigen::Vector3d(axis / length) : Eigen::Vector3d::UnitY();
  Eigen::Vector3d u = up - up.dot(t) * t;
  if (u.norm() < 1e-9) u = t.unitOrthogonal();
  u.normalize();
  const Eigen::Vector3d w = t.cross(u);
  const Eigen::Vector3d d = p - 0.5 * (a + b);
  // Half extents: along the axis the box reaches past both ends by its smaller half size, so
  // that consecutive parts joined at a point overlap.
  const double r = rounding_mm;
  const Eigen::Vector3d half(0.5 * length + std::min(half_width_mm, half_height_mm), half_height_mm,
                             half_width_mm);
  const Eigen::Vector3d q =
      Eigen::Vector3d(std::abs(d.dot(t)), std::abs(d.dot(u)), std::abs(d.dot(w))) - half +
      Eigen::Vector3d::Constant(r);
  return q.cwiseMax(0.0).norm() + std::min(q.maxCoeff(), 0.0) - r;
}

bool ParametricVertebra::contains(const Eigen::Vector3d& p) const {
  const double h = body_height_mm;
  if (std::abs(p.y()) <= h / 2) {
    const double f = (p.y() + h / 2) / h, s = 1.0 - waist * (1.0 - std::pow(2 * p.y() / h, 2));
    const double w = s * lerp(lower_width_mm, upper_width_mm, f);
    const double d = s * lerp(lower_depth_mm, upper_depth_mm, f);
    if (unit_outline().contains(Eigen::Vector2d(p.x() / w, p.z() / d))) return true;
  }
  for (const auto& part : parts)
    if (part.signed_distance(p) <= 0) return true;
  return false;
}

Eigen::Vector3d ParametricVertebra::bounding_center_mm() const {
  Eigen::AlignedBox3d box;
  const double w = std::max(lower_width_mm, upper_width_mm),
               d = std::max(lower_depth_mm, upper_depth_mm);
  box.extend(Eigen::Vector3d(-w, -body_height_mm, -d));
  box.extend(Eigen::Vector3d(w, body_height_mm, d));
  for (const auto& part : parts) {
    const double pad = std::max(part.half_width_mm, part.half_height_mm) * 1.5;
    box.extend(part.a - Eigen::Vector3d::Constant(pad));
    box.extend(part.a + Eigen::Vector3d::Constant(pad));
    box.extend(part.b - Eigen::Vector3d::Constant(pad));
    box.extend(part.b + Eigen::Vector3d::Constant(pad));
  }
  return box.center();
}

double ParametricVertebra::bounding_radius_mm() const {
  const Eigen::Vector3d c = bounding_center_mm();
  const double w = std::max(lower_width_mm, upper_width_mm),
               d = std::max(lower_depth_mm, upper_depth_mm);
  double r = (Eigen::Vector3d(w, body_height_mm, d).cwiseAbs() + c.cwiseAbs()).norm();
  for (const auto& part : parts) {
    const double pad = std::max(part.half_width_mm, part.half_height_mm) * 1.5;
    r = std::max(r, (part.a - c).norm() + pad);
    r = std::max(r, (part.b - c).norm() + pad);
  }
  return r;
}

ParametricVertebra parametric_vertebra(const std::string& name_in, const std::string& data_dir) {
  const std::string name = canonical_body(name_in);
  const auto& names = scene_body_names();
  const std::size_t i = std::size_t(std::find(names.begin(), names.end(), name) - names.begin());
  const auto& levels = disc_levels();
  ParametricVertebra v;
  v.name = name;

  if (name == "S1") {
    const DiscDimensions above = disc_dimensions("L5-S1", data_dir);
    const DiscFrame disc = disc_frame_in_spine("L5-S1", data_dir);
    const Eigen::Vector3d axis = disc.axes.col(1);
    const Eigen::Vector3d top = disc.origin_mm - 0.5 * above.height_mm * axis;
    v.frame = body_frame(top - kSacralBodyHeightMm * axis, top);
    v.body_height_mm = kSacralBodyHeightMm;
    v.lower_width_mm = v.upper_width_mm = above.lower_width_mm;
    v.lower_depth_mm = v.upper_depth_mm = above.lower_depth_mm;
    v.parts = sacral_parts(v);
    return v;
  }

  // The disc below (i → i+1) and the disc above (i−1 → i; for T1 the C7-T1 joint of table F.2).
  const DiscDimensions below = disc_dimensions(levels[i], data_dir);
  const DiscFrame below_frame = disc_frame_in_spine(levels[i], data_dir);
  const Eigen::Vector3d bottom =
      below_frame.origin_mm + 0.5 * below.height_mm * below_frame.axes.col(1);
  Eigen::Vector3d top;
  v.lower_width_mm = below.upper_width_mm;
  v.lower_depth_mm = below.upper_depth_mm;
  if (i == 0) {
    const auto joints = read_csv((fs::path(data_dir) / "thesis" / "F2_joint_markers.csv").string());
    const std::size_t r = joints.find("location", "C7-T1");
    const Eigen::Vector3d c7t1(joints.number(r, "x_mm"), joints.number(r, "y_mm"),
                               joints.number(r, "z_mm"));
    const Eigen::Vector3d axis = (c7t1 - below_frame.origin_mm).normalized();
    top = c7t1 - 0.5 * kC7T1DiscHeightMm * axis;
    v.upper_width_mm = v.lower_width_mm;
    v.upper_depth_mm = v.lower_depth_mm;
  } else {
    const DiscDimensions above = disc_dimensions(levels[i - 1], data_dir);
    const DiscFrame above_frame = disc_frame_in_spine(levels[i - 1], data_dir);
    top = above_frame.origin_mm - 0.5 * above.height_mm * above_frame.axes.col(1);
    v.upper_width_mm = above.lower_width_mm;
    v.upper_depth_mm = above.lower_depth_mm;
  }
  v.frame = body_frame(bottom, top);
  v.body_height_mm = (top - bottom).norm();
  if (!(v.body_height_mm > 1.0))
    throw std::invalid_argument("vertebra " + name + ": the discs around it leave no body (" +
                                std::to_string(v.body_height_mm) + " mm)");
  v.parts = neural_arch(vertebra_morphometry(name, data_dir), v);
  return v;
}

TriSurface boundary_surface(const TetMesh& m) {
  // Outward faces of a positively oriented tet (a, b, c, d): (b, c, d), (a, d, c), (a, b, d),
  // (a, c, b). A face is on the boundary when no other tet has it.
  static constexpr int kFaces[4][3] = {{1, 2, 3}, {0, 3, 2}, {0, 1, 3}, {0, 2, 1}};
  std::map<std::array<int, 3>, std::pair<std::array<int, 3>, int>> faces;
  for (Eigen::Index t = 0; t < m.T.rows(); ++t)
    for (const auto& f : kFaces) {
      std::array<int, 3> tri = {m.T(t, f[0]), m.T(t, f[1]), m.T(t, f[2])};
      std::array<int, 3> key = tri;
      std::sort(key.begin(), key.end());
      auto [it, inserted] = faces.emplace(key, std::make_pair(tri, 1));
      if (!inserted) ++it->second.second;
    }
  std::vector<int> new_index(std::size_t(m.V.rows()), -1);
  std::vector<std::array<int, 3>> tris;
  int count = 0;
  for (const auto& [key, value] : faces) {
    if (value.second != 1) continue;
    std::array<int, 3> tri = value.first;
    for (int& v : tri) {
      if (new_index[std::size_t(v)] < 0) new_index[std::size_t(v)] = count++;
      v = new_index[std::size_t(v)];
    }
    tris.push_back(tri);
  }
  TriSurface s;
  s.V.resize(count, 3);
  for (Eigen::Index v = 0; v < m.V.rows(); ++v)
    if (new_index[std::size_t(v)] >= 0) s.V.row(new_index[std::size_t(v)]) = m.V.row(v);
  s.F.resize(Eigen::Index(tris.size()), 3);
  for (std::size_t f = 0; f < tris.size(); ++f)
    s.F.row(Eigen::Index(f)) << tris[f][0], tris[f][1], tris[f][2];
  return s;
}

VertebraSurface mesh_vertebra(const ParametricVertebra& v, int target_triangles) {
  if (target_triangles < 100 || target_triangles > 2000000)
    throw std::invalid_argument("vertebra " + v.name + ": " + std::to_string(target_triangles) +
                                " triangles asked; give 100 to 2,000,000");
  LabeledBody body;
  body.label = [&v](const Eigen::Vector3d& p) { return v.contains(p) ? 1 : 0; };
  body.center_mm = v.bounding_center_mm();
  body.bounding_radius_mm = v.bounding_radius_mm();
  body.name = "parametric vertebra " + v.name;

  // Facet size from an area estimate (a triangle of Mesh_3's facet size e averages about
  // 0.3 e² here); one correction pass brings the count near the target.
  const double area_estimate = 8.0 * body.bounding_radius_mm * body.bounding_radius_mm;
  double e = std::sqrt(area_estimate / (0.3 * target_triangles));
  TriSurface surface;
  for (int pass = 0; pass < 3; ++pass) {
    MeshOptions opt;
    opt.facet_size_mm = e;
    opt.facet_distance_mm = 0.2 * e;
    opt.cell_size_mm = 4.0 * e;
    opt.radius_edge_ratio = 3.0;
    opt.perturb = opt.exude = false;
    opt.max_elements = 20.0 * target_triangles + 1e5;
    surface = boundary_surface(mesh_labeled_body(body, opt));
    const double ratio = double(surface.F.rows()) / target_triangles;
    if (ratio > 0.8 && ratio < 1.3) break;
    e *= std::sqrt(ratio);
  }
  VertebraSurface out;
  out.name = v.name;
  out.frame = v.frame;
  out.surface.F = surface.F;
  out.surface.V = (surface.V * v.frame.axes.transpose()).rowwise() + v.frame.origin_mm.transpose();
  return out;
}

void write_obj(const std::string& path, const TriSurface& s, const std::string& comment) {
  write_atomically("write_obj", path, [&](std::ostream& os) {
    if (!comment.empty()) os << "# " << comment << "\n";
    os << "# units: mm; frame: x lateral (right = -x), y superior, z anterior\n";
    os << std::setprecision(9);
    for (Eigen::Index v = 0; v < s.V.rows(); ++v)
      os << "v " << s.V(v, 0) << ' ' << s.V(v, 1) << ' ' << s.V(v, 2) << '\n';
    for (Eigen::Index f = 0; f < s.F.rows(); ++f)
      os << "f " << s.F(f, 0) + 1 << ' ' << s.F(f, 1) + 1 << ' ' << s.F(f, 2) + 1 << '\n';
  });
}

Eigen::Vector3d surface_centroid(const TriSurface& s) {
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  double area = 0;
  for (Eigen::Index f = 0; f < s.F.rows(); ++f) {
    const Eigen::Vector3d a = s.V.row(s.F(f, 0)), b = s.V.row(s.F(f, 1)), c = s.V.row(s.F(f, 2));
    const double A = 0.5 * (b - a).cross(c - a).norm();
    sum += A * (a + b + c) / 3.0;
    area += A;
  }
  if (!(area > 0)) throw std::invalid_argument("vertebra surface has zero area");
  return sum / area;
}

SurfaceCheck check_surface(const TriSurface& s) {
  SurfaceCheck c;
  std::map<std::pair<int, int>, std::pair<int, int>> edges;  // (min, max) → (forward, backward)
  for (Eigen::Index f = 0; f < s.F.rows(); ++f) {
    for (int k = 0; k < 3; ++k) {
      const int a = s.F(f, k), b = s.F(f, (k + 1) % 3);
      auto& e = edges[{std::min(a, b), std::max(a, b)}];
      (a < b ? e.first : e.second) += 1;
    }
    const Eigen::Vector3d p0 = s.V.row(s.F(f, 0)), p1 = s.V.row(s.F(f, 1)), p2 = s.V.row(s.F(f, 2));
    c.volume_mm3 += p0.dot(p1.cross(p2)) / 6.0;
    c.area_mm2 += 0.5 * (p1 - p0).cross(p2 - p0).norm();
  }
  bool opposite = true;
  for (const auto& [key, count] : edges) {
    const int total = count.first + count.second;
    if (total == 1) ++c.boundary_edges;
    if (total > 2) ++c.nonmanifold_edges;
    if (count.first != 1 || count.second != 1) opposite = false;
  }
  c.closed = c.boundary_edges == 0 && c.nonmanifold_edges == 0 && !edges.empty();
  c.oriented = c.closed && opposite;
  return c;
}

}  // namespace spinesim::mesh

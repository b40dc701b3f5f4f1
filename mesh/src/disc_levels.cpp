// The 17 thoracolumbar disc levels: their sourced dimensions (data/disc_morphometry.csv) and
// where each disc sits in the thesis spine model (data/thesis/F1_vertebra_cm.csv, table F.1
// vertebra centres; data/thesis/F2_joint_markers.csv, table F.2 joint points).
//
// Disc frame (DiscFrame, columns x lateral, y axial, z anterior, right-handed):
//   origin = the F.2 joint point of the level;
//   y = unit vector from the inferior vertebra's F.1 centre to the superior's; for L5-S1
//       (F.1 has no sacrum) from the L5-S1 joint point to the L5 centre;
//   x = global x made orthogonal to y (Gram-Schmidt) — the thesis spine is symmetric about
//       x = 0, so this is exactly global x there;
//   z = x × y, which points anteriorly (positive global z) whenever y points upward.
// All coordinates in mm, frame x lateral (body's right = -x), y superior, z anterior.
#include "spinesim/mesh/disc_geometry.hpp"

#include "spinesim/common/csv_table.hpp"

#include <Eigen/Geometry>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <stdexcept>
#include <string>
#include <vector>

namespace spinesim::mesh {
namespace {

namespace fs = std::filesystem;

/// The x_mm, y_mm, z_mm cells of row r.
Eigen::Vector3d point(const CsvTable& t, std::size_t r) {
  return {t.number(r, "x_mm"), t.number(r, "y_mm"), t.number(r, "z_mm")};
}

std::string upper(std::string s) {
  for (char& c : s) c = char(std::toupper(static_cast<unsigned char>(c)));
  return s;
}

/// "l4-l5" -> "L4-L5"; throws for a name that is not one of disc_levels().
std::string canonical_level(const std::string& level) {
  const std::string name = upper(trim(level));
  const auto& known = disc_levels();
  if (std::find(known.begin(), known.end(), name) != known.end()) return name;
  std::string list;
  for (const auto& k : known) list += (list.empty() ? "" : ", ") + k;
  throw std::invalid_argument("unknown disc level '" + level + "' (known: " + list + ")");
}

}  // namespace

const std::vector<std::string>& disc_levels() {
  static const std::vector<std::string> levels = {
      "T1-T2",   "T2-T3",   "T3-T4",  "T4-T5", "T5-T6", "T6-T7", "T7-T8", "T8-T9", "T9-T10",
      "T10-T11", "T11-T12", "T12-L1", "L1-L2", "L2-L3", "L3-L4", "L4-L5", "L5-S1"};
  return levels;
}

DiscDimensions disc_dimensions(const std::string& level, const std::string& data_dir) {
  const std::string name = canonical_level(level);
  const CsvTable table = read_csv((fs::path(data_dir) / "disc_morphometry.csv").string());
  const std::size_t row = table.find("level", name);
  auto value = [&](const char* column) {
    const double v = table.number(row, column);
    if (!(v > 0))
      throw std::invalid_argument(table.path + ": " + name + " " + column + " must be > 0 mm");
    return v;
  };
  DiscDimensions d;
  d.level = name;
  d.lower_width_mm = value("lower_width_mm");
  d.lower_depth_mm = value("lower_depth_mm");
  d.upper_width_mm = value("upper_width_mm");
  d.upper_depth_mm = value("upper_depth_mm");
  d.height_mm = value("height_mm");
  return d;
}

DiscFrame disc_frame_in_spine(const std::string& level, const std::string& data_dir) {
  const std::string name = canonical_level(level);
  const std::string superior = name.substr(0, name.find('-'));
  const std::string inferior = name.substr(name.find('-') + 1);

  const fs::path thesis = fs::path(data_dir) / "thesis";
  const CsvTable joints = read_csv((thesis / "F2_joint_markers.csv").string());
  const CsvTable centres = read_csv((thesis / "F1_vertebra_cm.csv").string());

  DiscFrame frame;
  frame.origin_mm = point(joints, joints.find("location", name));

  const Eigen::Vector3d top = point(centres, centres.find("segment", superior));
  // F.1 has no sacrum: below L5 the joint point stands in for the inferior centre.
  const Eigen::Vector3d bottom =
      inferior == "S1" ? frame.origin_mm : point(centres, centres.find("segment", inferior));
  Eigen::Vector3d y = top - bottom;
  if (!(y.norm() > 1e-9))
    throw std::invalid_argument("disc " + name + ": coincident vertebra centres");
  y.normalize();

  Eigen::Vector3d x = Eigen::Vector3d::UnitX() - y.x() * y;  // global x, orthogonal to the axis
  if (!(x.norm() > 1e-9))
    throw std::invalid_argument("disc " + name + ": axis is parallel to global x");
  x.normalize();
  Eigen::Vector3d z = x.cross(y);
  if (z.z() < 0) {  // keep z anterior; flipping x and z together keeps the frame right-handed
    x = -x;
    z = -z;
  }
  frame.axes.col(0) = x;
  frame.axes.col(1) = y;
  frame.axes.col(2) = z;
  return frame;
}

}  // namespace spinesim::mesh

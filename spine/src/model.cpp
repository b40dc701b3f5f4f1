// Builds the spine model from data/ (spine/README.md): no number of the model is in this file.
#include "spinesim/spine/model.hpp"
#include "spinesim/spine/kinematics.hpp"
#include "spinesim/spine/rib_cage.hpp"
#include "spinesim/spine/scoliosis.hpp"
#include "spinesim/common/constants.hpp"

#include "spinesim/common/csv_table.hpp"
#include "spinesim/common/input_file.hpp"

#include "json_fields.hpp"
#include "subject.hpp"

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <optional>
#include <sstream>
#include <stdexcept>

namespace spinesim::spine {
namespace {
namespace fs = std::filesystem;
using detail::number;
using detail::read_json;
using detail::vec3;
using Eigen::Vector3d;
using nlohmann::json;

std::string upper(std::string s) {
  s.erase(std::remove_if(s.begin(), s.end(), [](unsigned char c) { return std::isspace(c); }),
          s.end());
  for (char& c : s) c = char(std::toupper(static_cast<unsigned char>(c)));
  return s;
}

std::string joined(const std::vector<std::string>& names) {
  std::string s;
  for (const auto& n : names) s += (s.empty() ? "" : ", ") + n;
  return s;
}

Vector3d row_point(const CsvTable& t, std::size_t r, const std::string& prefix = "") {
  return {t.number(r, prefix + "x_mm"), t.number(r, prefix + "y_mm"), t.number(r, prefix + "z_mm")};
}

/// F.4 groups the joints: thoracic joints (upper vertebra T*) use T1-T12, L1-L2…L4-L5 use L1-L5.
std::string stiffness_group(const std::string& joint) {
  if (joint == "L5-S1") return "L5-S1";
  return joint[0] == 'T' ? "T1-T12" : "L1-L5";
}

/// Body a muscle segment name refers to: a vertebra, the ribs (T6) or the ground.
int segment_body(const std::string& segment, const json& config, const std::string& file) {
  std::string name = segment;
  const json& aliases = config.at("muscle_segment_aliases");
  if (aliases.contains(name)) name = aliases.at(name).get<std::string>();
  for (const auto& g : config.at("ground_segments"))
    if (g.get<std::string>() == name) return kGround;
  const auto& names = vertebra_names();
  const auto it = std::find(names.begin(), names.end(), name);
  if (it == names.end())
    throw std::runtime_error(
        file + ": muscle segment '" + segment +
        "' is not a vertebra, a ground segment or an alias (spine_model.json)");
  return int(it - names.begin());
}

void add_line_geometry(Line& line) {
  line.rest_length_mm = (line.a_mm - line.b_mm).norm();
  if (!(line.rest_length_mm > 1e-6))
    throw std::runtime_error("line element " + line.name + " has zero length");
}

/// One muscle table (F.8-F.19 layout): the right side as listed, the left its mirror image.
/// `group` names the muscle group; empty means the table has a "group" column.
void load_muscle_table(SpineModel& m, const fs::path& file, const std::string& group,
                       const json& config) {
  const CsvTable t = read_csv(file.string());
  for (std::size_t r = 0; r < t.rows.size(); ++r) {
    Muscle right;
    right.group = group.empty() ? t.text(r, "group") : group;
    right.side = "right";
    right.name = t.text(r, "muscle") + "_R";
    right.body_a = segment_body(t.text(r, "proximal_segment"), config, t.path);
    right.body_b = segment_body(t.text(r, "distal_segment"), config, t.path);
    right.a_mm = row_point(t, r, "proximal_");
    right.b_mm = row_point(t, r, "distal_");
    right.pcsa_mm2 = t.number(r, "pcsa_mm2");
    right.max_stress_mpa = t.number(r, "max_stress_mpa");
    if (!(right.pcsa_mm2 > 0) || !(right.max_stress_mpa > 0))
      throw std::runtime_error(t.path + ": " + right.name + " needs pCSA > 0 and max stress > 0");
    add_line_geometry(right);
    Muscle left = right;  // the tables list the right side; the left is its mirror image
    left.side = "left";
    left.name = t.text(r, "muscle") + "_L";
    left.a_mm.x() = -left.a_mm.x();
    left.b_mm.x() = -left.b_mm.x();
    m.muscles.push_back(right);
    m.muscles.push_back(left);
  }
}

/// The thesis's lumbar muscles (F.8-F.19) and, unless switched off, the LifeMOD default trunk muscles that
/// appendix F names without data (spine_model.json "trunk_muscles": data/spine/trunk_muscles.csv, sourced there).
void load_muscles(SpineModel& m, const fs::path& data, const json& config, bool trunk_muscles) {
  static const std::pair<const char*, const char*> files[] = {
      {"F8_F9_multifidus.csv", "multifidus"},
      {"F10_F11_erector_spinae.csv", "erector spinae"},
      {"F12_F13_psoas_major.csv", "psoas major"},
      {"F14_F15_quadratus_lumborum.csv", "quadratus lumborum"},
      {"F16_F17_external_oblique.csv", "external oblique"},
      {"F18_F19_internal_oblique.csv", "internal oblique"}};
  for (const auto& [file, group] : files)
    load_muscle_table(m, data / "thesis" / file, group, config);
  if (trunk_muscles)
    load_muscle_table(m, data / "spine" / config.at("trunk_muscles").get<std::string>(), "",
                      config);
}

/// Ligaments across every joint (geometry: spine_model.json "ligaments", an assumption there).
void load_ligaments(SpineModel& m, const fs::path& data, const json& config) {
  const CsvTable stiff = read_csv((data / "thesis" / "F6_F7_ligament_stiffness.csv").string());
  const CsvTable discs = read_csv((data / "disc_morphometry.csv").string());
  const json& geo = config.at("ligaments");
  const std::size_t cervical = stiff.find("region", "cervical"),
                    lumbar = stiff.find("region", "lumbar");
  static const char* types[] = {"ISL", "LF", "ALL", "PLL", "JC"};
  for (std::size_t j = 0; j < m.joints.size(); ++j) {
    const Joint& joint = m.joints[j];
    const bool thoracic = joint.name[0] == 'T';
    const std::string region = thoracic ? "thoracic" : "lumbar";
    const std::size_t d = discs.find("level", joint.name);
    const double half_depth =
        0.25 * (discs.number(d, "lower_depth_mm") + discs.number(d, "upper_depth_mm"));
    const double canal = number(geo.at("canal_depth_mm"), region, "spine_model.json ligaments");
    const double facet =
        number(geo.at("facet_half_width_mm"), region, "spine_model.json ligaments");
    const double spinous =
        number(geo.at("spinous_length_mm"), region, "spine_model.json ligaments");
    const Vector3d up = m.vertebrae[j].centre_mm;
    // Below L5-S1 is the sacrum, which F.1 does not list: mirror L5's centre about the joint.
    const Vector3d low = j + 1 < m.vertebrae.size() ? m.vertebrae[j + 1].centre_mm
                                                    : Vector3d(2 * joint.point_mm - up);
    for (const char* type : types) {
      std::string col = std::string(type) + "_n_per_mm";
      std::transform(col.begin(), col.end(), col.begin(),
                     [](unsigned char c) { return char(std::tolower(c)); });
      // F.7's note: thoracic ligaments take the mean of the cervical and lumbar values.
      const double k = thoracic ? 0.5 * (stiff.number(cervical, col) + stiff.number(lumbar, col))
                                : stiff.number(lumbar, col);
      const std::string t = type;
      double dz = 0;  // z offset from each vertebra's centre
      double dx = 0;
      if (t == "ALL") dz = half_depth;
      if (t == "PLL") dz = -half_depth;
      if (t == "LF") dz = -half_depth - canal;
      if (t == "ISL") dz = -half_depth - canal - 0.5 * spinous;
      if (t == "JC") {
        dz = -half_depth - 0.5 * canal;
        dx = facet;
      }
      for (int side : (t == "JC" ? std::vector<int>{-1, 1} : std::vector<int>{0})) {
        Ligament l;
        l.type = t;
        l.joint = int(j);
        l.k_n_per_mm = k;
        l.name = t + (side < 0 ? "_R" : side > 0 ? "_L" : "") + " " + joint.name;
        l.body_a = int(j);
        l.body_b = j + 1 < m.vertebrae.size() ? int(j + 1) : kGround;
        l.a_mm = up + Vector3d(-side * dx, 0, dz);  // the body's right is −x
        l.b_mm = low + Vector3d(-side * dx, 0, dz);
        add_line_geometry(l);
        m.ligaments.push_back(l);
      }
    }
  }
}

void check_input_scales(const ModelOptions& o) {
  const std::pair<const char*, double> scales[] = {{"muscle strength", o.muscle_strength},
                                                   {"joint stiffness", o.joint_stiffness},
                                                   {"ligament stiffness", o.ligament_stiffness}};
  for (const auto& [what, v] : scales)
    if (!(v >= kInputScaleRange[0] && v <= kInputScaleRange[1])) {
      std::ostringstream os;
      os << "the " << what << " scale must lie within " << kInputScaleRange[0] << " … "
         << kInputScaleRange[1] << " (1: the tables' values), not " << v;
      throw std::invalid_argument(os.str());
    }
  if (!(o.inclination_deg >= kInclinationRangeDeg[0] &&
        o.inclination_deg <= kInclinationRangeDeg[1])) {
    std::ostringstream os;
    os << "the forward inclination must lie within " << kInclinationRangeDeg[0] << " … "
       << kInclinationRangeDeg[1] << " deg, not " << o.inclination_deg;
    throw std::invalid_argument(os.str());
  }
}

/// ModelOptions' uncertain inputs: strength, stiffnesses and the inclination of gravity.
void apply_input_scales(SpineModel& m, const ModelOptions& o) {
  for (Muscle& mu : m.muscles) mu.max_stress_mpa *= o.muscle_strength;
  for (Joint& j : m.joints) {
    for (double* k : {&j.k_flexion, &j.k_extension, &j.k_lateral, &j.k_torsion})
      *k *= o.joint_stiffness;
    j.coupling *= o.joint_stiffness;
  }
  for (Ligament& l : m.ligaments) l.k_n_per_mm *= o.ligament_stiffness;
  if (o.inclination_deg != 0) {
    // Turning the body forward by φ turns gravity backward by φ in the body's frame: down
    // (0, −1, 0) becomes (0, −cos φ, sin φ), forward.
    const Eigen::Matrix3d turn =
        Eigen::AngleAxisd(-o.inclination_deg * kRadPerDeg, Vector3d::UnitX()).toRotationMatrix();
    for (PointLoad& w : m.weights) w.force_n = turn * w.force_n;
  }
}

void load_weights(SpineModel& m, const json& config, const std::string& file, bool arms_forward) {
  const double g_n_per_kg = m.gravity_mm_s2 / 1000.0;  // N per kg
  const Vector3d down(0, -1, 0);
  const json& pct = config.at("vertebra_mass_percent");
  for (std::size_t i = 0; i < m.vertebrae.size(); ++i) {
    Vertebra& v = m.vertebrae[i];
    v.mass_kg = number(pct, v.name, file) / 100.0 * m.scale.trunk_mass * m.body_mass_kg;
    m.weights.push_back({v.name + " weight", int(i), v.centre_mm, v.mass_kg * g_n_per_kg * down});
  }
  const json& head = config.at("head_neck");
  const double head_kg = m.segment_mass_percent.head_neck / 100.0 * m.body_mass_kg;
  m.weights.push_back({"head and neck weight",
                       vertebra_index(head.at("carried_by").get<std::string>()),
                       vec3(head, "point_mm", file), head_kg * g_n_per_kg * down});
  const json& arms = config.at("arms");
  const double arm_kg = m.segment_mass_percent.arm_each / 100.0 * m.body_mass_kg;
  const int carrier = vertebra_index(arms.at("carried_by").get<std::string>());
  Vector3d p = vec3(arms, arms_forward ? "forward_point_mm" : "hanging_point_mm", file);
  for (int side : {-1, 1}) {
    const Vector3d q(side * std::abs(p.x()), p.y(), p.z());
    m.weights.push_back({std::string(side < 0 ? "right" : "left") + " arm weight", carrier, q,
                         arm_kg * g_n_per_kg * down});
  }
}

}  // namespace

const std::vector<std::string>& vertebra_names() {
  static const std::vector<std::string> names = {"T1", "T2", "T3", "T4",  "T5",  "T6",
                                                 "T7", "T8", "T9", "T10", "T11", "T12",
                                                 "L1", "L2", "L3", "L4",  "L5"};
  return names;
}

const std::vector<std::string>& joint_names() {
  static const std::vector<std::string> names = {
      "T1-T2",   "T2-T3",   "T3-T4",  "T4-T5", "T5-T6", "T6-T7", "T7-T8", "T8-T9", "T9-T10",
      "T10-T11", "T11-T12", "T12-L1", "L1-L2", "L2-L3", "L3-L4", "L4-L5", "L5-S1"};
  return names;
}

int vertebra_index(const std::string& name) {
  const auto& names = vertebra_names();
  const auto it = std::find(names.begin(), names.end(), upper(name));
  if (it == names.end())
    throw std::invalid_argument("unknown vertebra '" + name + "' (known: " + joined(names) + ")");
  return int(it - names.begin());
}

int joint_index(const std::string& name) {
  const auto& names = joint_names();
  const auto it = std::find(names.begin(), names.end(), upper(name));
  if (it == names.end())
    throw std::invalid_argument("unknown joint '" + name + "' (known: " + joined(names) + ")");
  return int(it - names.begin());
}

std::vector<int> parse_fusion(const std::string& levels) {
  std::vector<int> joints;
  std::string item;
  std::stringstream ss(levels);
  while (std::getline(ss, item, ',')) {
    const std::string s = upper(item);
    if (s.empty()) continue;
    // "L3-L4-L5": consecutive vertebrae; every neighbouring pair is one fused joint.
    std::vector<std::string> parts;
    std::stringstream ps(s);
    std::string p;
    while (std::getline(ps, p, '-')) parts.push_back(p);
    if (parts.size() < 2)
      throw std::invalid_argument("fusion level '" + item + "' needs two vertebrae, e.g. L3-L4");
    for (std::size_t k = 0; k + 1 < parts.size(); ++k) {
      const std::string joint = parts[k] + "-" + parts[k + 1];
      const auto& names = joint_names();
      if (std::find(names.begin(), names.end(), joint) == names.end())
        throw std::invalid_argument(
            "fusion level '" + item + "': " + joint +
            " is not a joint of adjacent vertebrae (known: " + joined(names) + ")");
      const int j = joint_index(joint);
      // Given twice (L3-L4,L3-L4) or overlapping (L3-L4-L5,L4-L5): a typo, refused not merged.
      if (std::find(joints.begin(), joints.end(), j) != joints.end())
        throw std::invalid_argument("fusion level '" + item + "': joint " + joint +
                                    " is already fused by an earlier level");
      joints.push_back(j);
    }
  }
  if (joints.empty()) throw std::invalid_argument("no fusion level given");
  std::sort(joints.begin(), joints.end());
  return joints;
}

const char* ligaments_name(Ligaments l) {
  switch (l) {
    case Ligaments::On:
      return "on";
    case Ligaments::Off:
      return "off";
    case Ligaments::Auto:
      break;
  }
  return "auto";
}

Ligaments parse_ligaments(const std::string& name) {
  for (Ligaments l : {Ligaments::Auto, Ligaments::On, Ligaments::Off})
    if (name == ligaments_name(l)) return l;
  throw std::invalid_argument("unknown ligament setting '" + name +
                              "' (known: auto, on, off)");
}

bool has_ligaments(const ModelOptions& options) {
  switch (options.ligaments) {
    case Ligaments::On:
      return true;
    case Ligaments::Off:
      return false;
    case Ligaments::Auto:
      break;
  }
  // F.4 is the whole motion segment, ligaments included; a disc joint is the disc alone.
  return !options.disc_joints.empty();
}

IapStiffness iap_from_appendix_c(const std::string& path, double length_scale) {
  const json c = read_json(path);
  IapStiffness s;
  const double volume = number(c, "V_L1L5_mm3", path) * length_scale * length_scale * length_scale;
  const auto& areas = c.at("section_areas_mm2");
  if (!areas.is_array() || areas.empty())
    throw std::runtime_error(path + ": section_areas_mm2 must be a non-empty array");
  for (const auto& a : areas) s.s_mean_mm2 += a.get<double>();
  s.s_mean_mm2 *= length_scale * length_scale / double(areas.size());  // (3.1)
  s.h_l1l5_mm = volume / s.s_mean_mm2;                                // (3.2)
  s.h_mm = number(c, "abdominal_height_factor", path) * s.h_l1l5_mm;  // (3.3)
  s.a_mm = std::sqrt(s.s_mean_mm2);                                   // (3.4)
  // P = ρ_Hg g h: mmHg → Pa → MPa.
  s.pressure_mpa = number(c, "mercury_density_kg_m3", path) * number(c, "gravity_m_s2", path) *
                   number(c, "iap_mmhg", path) * 1e-3 * 1e-6;
  s.k_y = 0.5 * s.pressure_mpa * s.a_mm * s.a_mm;  // (3.9), "N/mm" as the thesis writes it
  s.k_x = 0.5 * s.pressure_mpa * s.a_mm * s.h_mm;  // (3.10)
  s.bushing_k_xz = 4 * s.k_x;                      // (3.15)
  s.bushing_k_y = 4 * s.k_y;                       // (3.16), printed "k_y = 4k_y"
  s.bushing_m_xz_per_deg = s.k_y * kRadPerDeg * s.a_mm * s.a_mm;  // (3.17)
  s.bushing_m_y_per_deg = s.k_x * kRadPerDeg * s.a_mm * s.a_mm;   // (3.18)
  return s;
}

SpineModel load_spine_model(const std::string& data_dir, const ModelOptions& options) {
  const fs::path data(data_dir), thesis = data / "thesis";
  const std::string config_file = (data / "spine" / "spine_model.json").string();
  const json config = read_json(config_file);
  SpineModel m;
  m.data_dir = data_dir;
  m.gravity_mm_s2 = number(config, "gravity_m_s2", config_file) * 1000.0;
  m.muscle_q = number(config, "muscle_short_range_stiffness_q", config_file);
  m.rom_bump_factor = number(config, "joint_rom_bump_factor", config_file);
  m.rom_bump_onset = number(config, "joint_rom_bump_onset_deg", config_file) * kRadPerDeg;
  m.chest_front_mm = vec3(config, "chest_front_mm", config_file);
  m.ribs_body = vertebra_index(config.at("ribs").at("fixed_to").get<std::string>());
  if (!(m.muscle_q > 0) || !(m.rom_bump_factor >= 1) || !(m.rom_bump_onset > 0))
    throw std::runtime_error(config_file +
                             ": need muscle q > 0, a ROM bump factor >= 1 and a bump onset > 0");

  for (const double f : {options.co_contraction, options.muscle_tone})
    if (!(f >= 0 && f <= 0.5))
      throw std::invalid_argument(
          "co-contraction and muscle tone are fractions of the muscles' maximum force, 0 … 0.5");
  m.muscle_floor = options.co_contraction;
  m.muscle_tone = options.muscle_tone;
  check_input_scales(options);
  try {
    m.subject = options.subject;
    m.scale = detail::subject_scale(config, config_file, m.subject, m.segment_mass_percent);
    m.body_mass_kg = m.subject.body_mass_kg;
    const CsvTable cm = read_csv((thesis / "F1_vertebra_cm.csv").string());
    for (const auto& name : vertebra_names())
      m.vertebrae.push_back({name, row_point(cm, cm.find("segment", name)), 0});

    const CsvTable markers = read_csv((thesis / "F2_joint_markers.csv").string());
    const CsvTable k = read_csv((thesis / "F4_joint_torsional_stiffness.csv").string());
    const CsvTable rom = read_csv((thesis / "F5_range_of_motion.csv").string());
    const CsvTable discs = read_csv((data / "disc_morphometry.csv").string());
    for (const auto& name : joint_names()) {
      Joint j;
      j.name = name;
      j.point_mm = row_point(markers, markers.find("location", name));
      const std::size_t g = k.find("level_group", stiffness_group(name));
      j.k_flexion = k.number(g, "flexion_nmm_per_deg") * kDegPerRad;
      j.k_extension = k.number(g, "extension_nmm_per_deg") * kDegPerRad;
      j.k_lateral = k.number(g, "lateral_bending_nmm_per_deg") * kDegPerRad;
      j.k_torsion = k.number(g, "axial_torsion_nmm_per_deg") * kDegPerRad;
      const std::size_t r = rom.find("level", name);
      j.rom_flexion = rom.number(r, "flexion_deg") * kRadPerDeg;
      j.rom_extension = rom.number(r, "extension_deg") * kRadPerDeg;
      j.rom_lateral = rom.number(r, "lateral_bending_deg") * kRadPerDeg;
      j.rom_torsion = rom.number(r, "torsion_deg") * kRadPerDeg;
      const std::size_t d = discs.find("level", name);
      j.disc_height_mm = discs.number(d, "height_mm");
      j.disc_width_mm = 0.5 * (discs.number(d, "lower_width_mm") + discs.number(d, "upper_width_mm"));
      j.disc_depth_mm = 0.5 * (discs.number(d, "lower_depth_mm") + discs.number(d, "upper_depth_mm"));
      if (!(j.k_flexion > 0 && j.k_extension > 0 && j.k_lateral > 0 && j.k_torsion > 0))
        throw std::runtime_error(k.path + ": joint stiffness of " + name + " must be > 0");
      m.joints.push_back(j);
    }
    if (!options.disc_joints.empty()) apply_disc_joints(m.joints, options.disc_joints, data_dir);
    for (int f : options.fused_joints) {
      if (f < 0 || f >= int(m.joints.size()))
        throw std::invalid_argument("fused joint index out of range");
      m.joints[std::size_t(f)].fused = true;
    }
    for (const auto& name : config.at("recruited_joints"))
      m.recruited_joints.push_back(joint_index(name.get<std::string>()));

    if (options.gravity) load_weights(m, config, config_file, options.arms_forward);
    if (has_ligaments(options)) load_ligaments(m, data, config);
    if (options.muscles) load_muscles(m, data, config, options.trunk_muscles);
    m.iap = iap_from_appendix_c((thesis / "appendix_c_iap.json").string(), m.scale.length);
    if (options.iap) {
      const json c = read_json((thesis / "appendix_c_iap.json").string());
      m.has_bushing = true;
      m.bushing.body = m.ribs_body;
      m.bushing.point_mm =
          vec3(c, "bushing_location_mm", (thesis / "appendix_c_iap.json").string());
      m.bushing.k_translation_n_per_mm =
          Vector3d(m.iap.bushing_k_xz, m.iap.bushing_k_y, m.iap.bushing_k_xz);
      m.bushing.k_rotation_nmm_per_rad =
          Vector3d(m.iap.bushing_m_xz_per_deg, m.iap.bushing_m_y_per_deg,
                   m.iap.bushing_m_xz_per_deg) /
          kRadPerDeg;
    }
    detail::scale_to_subject(m, m.scale);
    apply_input_scales(m, options);
    if (options.rib_cage)
      m.rib_cage =
          std::make_shared<const RibCage>(build_rib_cage(data_dir, m.vertebrae, m.scale.length));
    if (options.scoliosis.cobb_deg != 0) rest_in_scoliosis(m, options);
  } catch (const nlohmann::json::exception& e) {
    throw std::runtime_error(config_file + ": " + e.what());
  }
  return m;
}

void rest_in_scoliosis(SpineModel& m, const ModelOptions& options) {
  if (options.rib_cage)
    throw std::invalid_argument(
        "scoliosis: not with the rib cage (the ribs' scoliotic shape is not modelled)");
  const ScoliosisPosture p = scoliotic_posture(m, options.scoliosis);
  m.rest_posture = p.theta;
  m.scoliosis = options.scoliosis;
  for (std::size_t k = 0; k < m.joints.size(); ++k)
    m.joints[k].rest_rad = p.theta.segment<3>(3 * Eigen::Index(k));
  // The ligaments are slack-free and the IAP bushing rests in the curve, as the joints do.
  const std::vector<Pose> P = vertebra_poses(m, p.theta);
  for (Ligament& l : m.ligaments)
    l.rest_length_mm = (place(P, l.body_a, l.a_mm) - place(P, l.body_b, l.b_mm)).norm();
  if (m.has_bushing) {
    m.bushing.rest_rotation = P[std::size_t(m.bushing.body)].R;
    m.bushing.rest_translation_mm = P[std::size_t(m.bushing.body)].t;
  }
}

namespace {

/// A nonlinear disc joint's per-direction secants (N·mm/rad: flexion, extension, lateral
/// bending, torsion), when the entry has them; each finite and within 1 … 1e10.
std::optional<Eigen::Vector4d> read_secants(const json& entry, const std::string& who) {
  if (!entry.contains("secant_nmm_per_rad")) return std::nullopt;
  const json& s = entry.at("secant_nmm_per_rad");
  const char* keys[4] = {"flexion", "extension", "lateral_bending", "torsion"};
  Eigen::Vector4d out;
  for (int k = 0; k < 4; ++k) {
    if (!s.is_object() || !s.contains(keys[k]) || !s.at(keys[k]).is_number())
      throw std::invalid_argument(who +
                                  "'secant_nmm_per_rad' needs numbers for flexion, "
                                  "extension, lateral_bending and torsion");
    out(k) = s.at(keys[k]).get<double>();
    if (!(out(k) >= 1 && out(k) <= 1e10))
      throw std::invalid_argument(who + "the " + keys[k] +
                                  " secant lies outside 1 … 1e10 N·mm/rad");
  }
  return out;
}

}  // namespace

void apply_disc_joints(std::vector<Joint>& joints, const std::string& name_or_path,
                       const std::string& data_dir) {
  const fs::path path = resolve_preset(
      name_or_path, (fs::path(data_dir) / "spine" / "disc_joints").string(), "disc joints");
  const std::string who = "disc joints '" + path.string() + "': ";
  const json j = read_json_file(path.string(), "disc joints file");
  if (!j.is_object() || !j.contains("joints") || !j.at("joints").is_object())
    throw std::invalid_argument(who + "expected a 'joints' object");
  require_known_keys(
      j,
      {"formulation", "generated_by", "joints", "material", "moment_nm", "provenance", "source",
       "units"},
      who + "the file");
  // Every level named must be one of the spine's (a typo or an "L6-L7" is not silently unused).
  for (const auto& level : j.at("joints").items()) {
    if (std::none_of(joints.begin(), joints.end(),
                     [&](const Joint& jt) { return jt.name == level.key(); }))
      throw std::invalid_argument(who + "unknown level '" + level.key() + "'");
    require_known_keys(level.value(),
                       {"K_nmm_per_rad", "cell_size_mm", "diagonal_nmm_per_deg", "joint_point_mm",
                        "mesh_asymmetry_removed", "plate_center_mm", "rest_tangent_nmm_per_rad",
                        "secant_moment_nm", "secant_nmm_per_rad", "secant_rotation_deg", "tets",
                        "thesis_F4_nmm_per_deg"},
                       who + level.key());
  }
  const std::string source = j.contains("source") && j.at("source").is_string()
                                 ? j.at("source").get<std::string>()
                                 : path.filename().string();
  for (Joint& joint : joints) {
    if (!j.at("joints").contains(joint.name))
      throw std::invalid_argument(who + "no stiffness for joint " + joint.name);
    const json& e = j.at("joints").at(joint.name);
    const json* rows =
        e.is_object() && e.contains("K_nmm_per_rad") ? &e.at("K_nmm_per_rad") : nullptr;
    Eigen::Matrix3d K;
    bool ok = rows && rows->is_array() && rows->size() == 3;
    for (int r = 0; ok && r < 3; ++r) {
      const json& row = rows->at(std::size_t(r));
      ok = row.is_array() && row.size() == 3;
      for (int c = 0; ok && c < 3; ++c) {
        ok = row.at(std::size_t(c)).is_number();
        if (ok) K(r, c) = row.at(std::size_t(c)).get<double>();
      }
    }
    if (!ok)
      throw std::invalid_argument(who + joint.name +
                                  ": 'K_nmm_per_rad' must be 3 rows of 3 numbers");
    if (!K.allFinite() || (K - K.transpose()).norm() > 1e-6 * K.norm())
      throw std::invalid_argument(who + joint.name + ": the stiffness is not finite and symmetric");
    const Eigen::Matrix3d sym = 0.5 * (K + K.transpose());
    const Eigen::Vector3d eig = Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(sym).eigenvalues();
    if (!(eig.minCoeff() > 0))
      throw std::invalid_argument(who + joint.name + ": the stiffness is not positive definite");
    // A spinal joint's rotational stiffness is of order 1e5 N·mm/rad (F.4: 1e3-1e7 across the
    // spine and its fusions); beyond 1 … 1e10 N·mm/rad the numbers are not a disc's.
    if (!(eig.minCoeff() >= 1 && eig.maxCoeff() <= 1e10))
      throw std::invalid_argument(
          who + joint.name + ": the stiffness lies outside 1 … 1e10 N·mm/rad (eigenvalues " +
          std::to_string(eig.minCoeff()) + " … " + std::to_string(eig.maxCoeff()) + ")");
    joint.k_flexion = joint.k_extension = sym(0, 0);
    joint.k_torsion = sym(1, 1);
    joint.k_lateral = sym(2, 2);
    // A nonlinear disc's joint: flexion and extension apart; the coupling must keep the spring
    // convex on both sides (the softer of the two with the coupling positive definite).
    if (const auto secant = read_secants(e, who + joint.name + ": ")) {
      joint.k_flexion = (*secant)(0), joint.k_extension = (*secant)(1);
      joint.k_lateral = (*secant)(2), joint.k_torsion = (*secant)(3);
      Eigen::Matrix3d softer = sym;
      softer.diagonal() << std::min(joint.k_flexion, joint.k_extension), joint.k_torsion,
          joint.k_lateral;
      if (!(Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(softer).eigenvalues().minCoeff() > 0))
        throw std::invalid_argument(who + joint.name +
                                    ": the secants with the coupling are not positive definite");
    }
    joint.coupling = sym;
    joint.coupling.diagonal().setZero();
    joint.stiffness_source = source;
  }
}

}  // namespace spinesim::spine

// A spine for a given body: the reference body's tables scaled to a subject (subject.hpp). Every
// number comes from spine_model.json's "anthropometry", with its sources there.
#include "subject.hpp"

#include "json_fields.hpp"

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <sstream>
#include <stdexcept>

namespace spinesim::spine {

const char* sex_name(Sex sex) { return sex == Sex::Female ? "female" : "male"; }

Sex parse_sex(const std::string& name) {
  if (name == "male") return Sex::Male;
  if (name == "female") return Sex::Female;
  throw std::invalid_argument("unknown sex '" + name + "' (known: male, female)");
}

Subject resolve_subject(const std::string& data_dir, Subject subject) {
  const std::string file = data_dir + "/spine/spine_model.json";
  const nlohmann::json config = detail::read_json(file);
  SegmentMassPercent percent;
  try {
    detail::subject_scale(config, file, subject, percent);
  } catch (const nlohmann::json::exception& e) {
    throw std::runtime_error(file + ": " + e.what());
  }
  return subject;
}

std::vector<NamedBody> named_bodies(const std::string& data_dir) {
  const std::string file = data_dir + "/spine/spine_model.json";
  const nlohmann::json config = detail::read_json(file);
  std::vector<NamedBody> out;
  try {
    const nlohmann::json& bodies = config.at("anthropometry").at("bodies");
    for (auto it = bodies.begin(); it != bodies.end(); ++it) {
      NamedBody b;
      b.name = it.key();
      b.source = it->at("source").get<std::string>();
      b.subject.height_m = detail::number(*it, "height_m", file);
      b.subject.body_mass_kg = detail::number(*it, "body_mass_kg", file);
      b.subject.sex = parse_sex(it->at("sex").get<std::string>());
      out.push_back(b);
    }
  } catch (const nlohmann::json::exception& e) {
    throw std::runtime_error(file + ": anthropometry.bodies: " + e.what());
  } catch (const std::invalid_argument& e) {
    throw std::runtime_error(file + ": anthropometry.bodies: " + e.what());
  }
  // The file's keys come back sorted by name; the bodies go smallest first.
  std::stable_sort(out.begin(), out.end(), [](const NamedBody& a, const NamedBody& b) {
    return a.subject.height_m < b.subject.height_m;
  });
  for (NamedBody& b : out) {
    try {
      b.subject = resolve_subject(data_dir, b.subject);
    } catch (const std::invalid_argument& e) {
      throw std::runtime_error(file + ": anthropometry.bodies." + b.name + ": " + e.what());
    }
  }
  return out;
}

NamedBody named_body(const std::string& data_dir, const std::string& name) {
  std::string known;
  for (const NamedBody& b : named_bodies(data_dir)) {
    if (b.name == name) return b;
    known += (known.empty() ? "" : ", ") + b.name;
  }
  throw std::invalid_argument("unknown body '" + name + "' (known: " + known + ")");
}

namespace detail {
namespace {

std::string fixed(double v, int decimals) {
  std::ostringstream os;
  os << std::fixed << std::setprecision(decimals) << v;
  return os.str();
}

SegmentMassPercent read_percent(const nlohmann::json& table, const std::string& file) {
  SegmentMassPercent p;
  p.trunk = number(table, "trunk", file);
  p.head_neck = number(table, "head_neck", file);
  p.arm_each = number(table, "arm_each", file);
  p.pelvis = number(table, "pelvis", file);
  p.forearm_hand_each = number(table, "forearm_hand_each", file);
  return p;
}

/// [min, max] of `key` in `j`: two finite numbers, min < max.
std::pair<double, double> range(const nlohmann::json& j, const std::string& key,
                                const std::string& file) {
  const nlohmann::json& r = j.at(key);
  if (!r.is_array() || r.size() != 2 || !r[0].is_number() || !r[1].is_number() ||
      !(r[0].get<double>() < r[1].get<double>()))
    throw std::runtime_error(file + ": anthropometry." + key + " must be [min, max]");
  return {r[0].get<double>(), r[1].get<double>()};
}

}  // namespace

SubjectScale subject_scale(const nlohmann::json& config, const std::string& file,
                           Subject& subject, SegmentMassPercent& percent) {
  const nlohmann::json& a = config.at("anthropometry");
  const double h0 = number(config, "reference_height_m", file);
  const double m0 = number(config, "body_mass_kg", file);
  if (!std::isfinite(subject.height_m) || !std::isfinite(subject.body_mass_kg) ||
      subject.height_m < 0 || subject.body_mass_kg < 0)
    throw std::invalid_argument("a subject's height and mass must be finite numbers > 0");
  if (subject.height_m == 0) subject.height_m = h0;
  if (subject.body_mass_kg == 0) subject.body_mass_kg = m0;
  const double h = subject.height_m, m = subject.body_mass_kg;
  const auto [h_min, h_max] = range(a, "height_range_m", file);
  const auto [bmi_min, bmi_max] = range(a, "body_mass_index_range_kg_m2", file);
  if (h < h_min || h > h_max)
    throw std::invalid_argument("height " + fixed(h, 3) + " m is outside " + fixed(h_min, 2) +
                                "-" + fixed(h_max, 2) +
                                " m, the adult range the scaling laws are applied to");
  const double bmi = m / (h * h);
  if (bmi < bmi_min || bmi > bmi_max)
    throw std::invalid_argument(
        "body mass " + fixed(m, 1) + " kg at " + fixed(h, 3) + " m is a body-mass index of " +
        fixed(bmi, 1) + " kg/m^2, outside " + fixed(bmi_min, 0) + "-" + fixed(bmi_max, 0) +
        ", the range the scaling laws are applied to");

  const nlohmann::json& table = a.at("segment_mass_percent");
  const SegmentMassPercent male = read_percent(table.at("male"), file);
  percent = subject.sex == Sex::Female ? read_percent(table.at("female"), file) : male;

  // Muscle volume V = c (m h) + V_0 (Handsfield et al. 2014); pCSA = V / fibre length, and the
  // fibre length grows with height.
  const double c = number(a, "muscle_volume_cm3_per_kg_m", file),
               v0 = number(a, "muscle_volume_intercept_cm3", file);
  SubjectScale s;
  s.length = h / h0;
  s.mass = m / m0;
  s.muscle = (c * m * h + v0) / (c * m0 * h0 + v0) / s.length;
  s.trunk_mass = percent.trunk / male.trunk;
  return s;
}

void scale_to_subject(SpineModel& m, const SubjectScale& scale) {
  const double s = scale.length, s3 = s * s * s;
  for (Vertebra& v : m.vertebrae) v.centre_mm *= s;
  for (Joint& j : m.joints) {
    j.point_mm *= s;
    j.disc_height_mm *= s;
    j.disc_width_mm *= s;
    j.disc_depth_mm *= s;
    j.k_flexion *= s3;
    j.k_extension *= s3;
    j.k_lateral *= s3;
    j.k_torsion *= s3;
    j.coupling *= s3;
  }
  const auto scale_line = [s](Line& l) {
    l.a_mm *= s;
    l.b_mm *= s;
    l.rest_length_mm *= s;
  };
  for (Ligament& l : m.ligaments) {
    scale_line(l);
    l.k_n_per_mm *= s;
  }
  for (Muscle& mu : m.muscles) {
    scale_line(mu);
    mu.pcsa_mm2 *= scale.muscle;
  }
  for (PointLoad& w : m.weights) w.point_mm *= s;
  for (ContactPoint& c : m.contacts) c.point_mm *= s;
  m.bushing.point_mm *= s;
  m.chest_front_mm *= s;
}

}  // namespace detail
}  // namespace spinesim::spine

#include "cli_common.hpp"

#include "spinesim/common/numbers.hpp"
#include "spinesim/spine/scoliosis.hpp"

#include <cmath>
#include <cstdlib>
#include <iostream>
#include <sstream>
#include <stdexcept>

namespace spinesim::cli {

void require_plain_numbers(CLI::App& app) {
  for (CLI::Option* opt : app.get_options()) {
    const std::string type = opt->get_type_name();
    const bool integer = type.rfind("INT", 0) == 0 || type.rfind("UINT", 0) == 0;
    if (!integer && type.rfind("FLOAT", 0) != 0) continue;
    opt->check(CLI::Validator(
        [integer](std::string& text) -> std::string {
          if (integer ? is_plain_number(text, true) : is_plain_number(text)) {
            if (integer || std::isfinite(std::strtod(text.c_str(), nullptr))) return "";
          }
          return "'" + text + "' is not " +
                 (integer ? "a whole number" : "a finite number in plain decimal notation");
        },
        ""));
  }
  for (CLI::App* sub : app.get_subcommands([](CLI::App*) { return true; }))
    require_plain_numbers(*sub);
}

void add_output_flags(CLI::App* cmd, bool& json, bool& quiet, const std::string& what) {
  cmd->add_flag("--json", json, "Print " + what + " on stdout");
  cmd->add_flag("--quiet", quiet, "No progress on stderr");
}

void add_subject_options(CLI::App* cmd, SubjectFlags& flags) {
  cmd->add_option("--height", flags.height_m,
                  "Body height, m (default: the thesis's reference body, 1.778 m); the spine's "
                  "lengths and stiffnesses scale with it (spine/README.md)");
  cmd->add_option("--mass", flags.mass_kg,
                  "Body mass, kg (default 70); segment masses and muscle strength follow it");
  cmd->add_option("--sex", flags.sex, "male or female: de Leva's segment masses of that sex")
      ->check(CLI::IsMember({"male", "female"}))
      ->capture_default_str();
  add_named_subject_option(cmd, flags, "--height, --mass or --sex");
}

void add_named_subject_option(CLI::App* cmd, SubjectFlags& flags, const std::string& instead_of) {
  cmd->add_option("--subject", flags.named,
                  "A sourced body instead of " + instead_of +
                      ": reference (the thesis's), p5-female (1.501 m, 49.0 kg) or p95-male (1.880 "
                      "m, 101.2 kg); data/spine/spine_model.json anthropometry.bodies");
}

spine::Subject subject_of(const SubjectFlags& flags) {
  if (flags.height_m < 0) throw std::invalid_argument("--height must be a number > 0 m");
  if (flags.mass_kg < 0) throw std::invalid_argument("--mass must be a number > 0 kg");
  if (!flags.named.empty()) {
    if (flags.height_m != 0 || flags.mass_kg != 0 || flags.sex != "male")
      throw std::invalid_argument(
          "--subject names a whole body: give it without a height, mass or sex");
    return spine::named_body(studies::data_dir(), flags.named).subject;
  }
  spine::Subject s;
  s.height_m = flags.height_m;
  s.body_mass_kg = flags.mass_kg;
  s.sex = spine::parse_sex(flags.sex);
  return s;
}

void add_scoliosis_options(CLI::App* cmd, ScoliosisFlags& f) {
  cmd->add_option("--scoliosis", f.type,
                  "A scoliotic spine resting in its curve: thoracic (T5-T11, apex T8, convex "
                  "right), thoracolumbar (T10-L2, apex T12, right) or lumbar (T12-L4, apex L2, "
                  "left); with --cobb (spine/README.md)");
  cmd->add_option("--cobb", f.cobb_deg,
                  "--scoliosis: the Cobb angle between the end vertebrae, deg");
  cmd->add_option("--apex", f.apex, "--scoliosis: the apical vertebra (default: the type's)");
  cmd->add_option("--curve-ends", f.ends,
                  "--scoliosis: the end vertebrae, upper,lower, e.g. T6,T12 (default: the type's)");
  cmd->add_option("--apical-rotation", f.apical_rotation_deg,
                  "--scoliosis: the apical vertebra's axial rotation toward the convexity, deg "
                  "(default 0)");
  cmd->add_option("--convex", f.convex, "--scoliosis: right or left (default: the type's)")
      ->check(CLI::IsMember({"right", "left"}));
}

spine::ScoliosisCurve scoliosis_of(const ScoliosisFlags& f) {
  if (f.type.empty()) {
    if (f.cobb_deg != 0 || !f.apex.empty() || !f.ends.empty() || !f.convex.empty() ||
        f.apical_rotation_deg != 0)
      throw std::invalid_argument(
          "--cobb, --apex, --curve-ends, --apical-rotation and --convex are for --scoliosis");
    return {};
  }
  if (f.cobb_deg == 0) throw std::invalid_argument("--scoliosis needs --cobb DEG");
  spine::ScoliosisCurve c = spine::scoliosis_curve(f.type, f.cobb_deg);
  if (!f.apex.empty()) c.apex = f.apex;
  if (!f.ends.empty()) {
    const auto ends = split_list(f.ends);
    if (ends.size() != 2)
      throw std::invalid_argument("--curve-ends " + f.ends + ": give upper,lower, e.g. T6,T12");
    c.upper_end = ends[0];
    c.lower_end = ends[1];
  }
  if (!f.convex.empty()) c.convex_right = f.convex == "right";
  c.apical_rotation_deg = f.apical_rotation_deg;
  if (!f.apex.empty() || !f.ends.empty() || !f.convex.empty()) c.type = "custom (" + c.type + ")";
  spine::check_scoliosis_curve(c);
  return c;
}

void add_model_input_options(CLI::App* cmd, ModelInputFlags& f) {
  cmd->add_option("--muscle-strength", f.muscle_strength,
                  "Multiplies every muscle's maximum stress (its strength; 1: F.8-F.19's)")
      ->capture_default_str();
  cmd->add_option("--joint-stiffness", f.joint_stiffness,
                  "Multiplies every joint's rotational stiffness (F.4's, or the --disc-joints')")
      ->capture_default_str();
  cmd->add_option("--ligament-stiffness", f.ligament_stiffness,
                  "Multiplies every F.6/F.7 ligament's stiffness (when the model has them: "
                  "--ligaments)")
      ->capture_default_str();
  cmd->add_option("--inclination", f.inclination_deg,
                  "Standing posture: the body above the hips pitched forward by this angle, deg "
                  "(gravity turns with it in the pelvis's frame; 0: upright)")
      ->capture_default_str();
}

void apply_model_inputs(const ModelInputFlags& f, spine::ModelOptions& o) {
  o.muscle_strength = f.muscle_strength;
  o.joint_stiffness = f.joint_stiffness;
  o.ligament_stiffness = f.ligament_stiffness;
  o.inclination_deg = f.inclination_deg;
  const std::pair<const char*, double> scales[] = {{"--muscle-strength", f.muscle_strength},
                                                   {"--joint-stiffness", f.joint_stiffness},
                                                   {"--ligament-stiffness", f.ligament_stiffness}};
  for (const auto& [flag, v] : scales)
    if (!(v >= spine::kInputScaleRange[0] && v <= spine::kInputScaleRange[1]))
      throw std::invalid_argument(std::string(flag) + " must lie within " +
                                  significant(spine::kInputScaleRange[0], 2) + " … " +
                                  significant(spine::kInputScaleRange[1], 2) + " (1: the tables')");
  if (!(f.inclination_deg >= spine::kInclinationRangeDeg[0] &&
        f.inclination_deg <= spine::kInclinationRangeDeg[1]))
    throw std::invalid_argument("--inclination must lie within " +
                                significant(spine::kInclinationRangeDeg[0], 2) + " … " +
                                significant(spine::kInclinationRangeDeg[1], 2) + " deg");
}

void add_ligaments_option(CLI::App* cmd, std::string& ligaments) {
  cmd->add_option("--ligaments", ligaments,
                  "The F.6/F.7 ligaments: auto (only with --disc-joints: F.4's whole-segment "
                  "springs include them), on (with F.4 the thesis's model, which counts them "
                  "twice) or off")
      ->check(CLI::IsMember({"auto", "on", "off"}))
      ->capture_default_str();
}

void add_rib_cage_option(CLI::App* cmd, bool& rib_cage) {
  cmd->add_flag("--rib-cage", rib_cage,
                "Add the rib cage: 24 ribs and the sternum on the thoracic vertebrae "
                "(costovertebral joints, costal cartilage; data/spine/rib_cage.json). Default: "
                "none, as in the thesis");
}

void add_plate_load_options(CLI::App* cmd, std::string& motion, std::string& wrench,
                            std::string& load_case, std::string& center) {
  cmd->add_option("--motion", motion, "Plate motion tx,ty,tz,rx,ry,rz (mm, degrees)");
  cmd->add_option("--wrench", wrench,
                  "Applied wrench Fx,Fy,Fz,Mx,My,Mz (N, N·mm) about the centre");
  cmd->add_option(
      "--case", load_case,
      "Named load case in the disc frame: compression, tension, shear-ap, shear-lat, flexion, "
      "extension, lateral-bending, torsion");
  cmd->add_option("--center", center,
                  "Plate centre x,y,z (mm); default: mean of the superior endplate nodes");
}

}  // namespace spinesim::cli

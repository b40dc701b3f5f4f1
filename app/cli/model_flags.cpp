#include "model_flags.hpp"

#include <cmath>
#include <stdexcept>

namespace spinesim::cli {

void add_model_flags(CLI::App* cmd, ModelFlags& f) {
  cmd->add_flag("--no-radial", f.no_radial, "Without the radial springs (thesis 5.3-5.5)");
  cmd->add_flag("--no-torsion", f.no_torsion,
                "Without the torsional angle springs (thesis 5.6-5.8)");
  cmd->add_flag("--volume-term", f.volume_term,
                "Add the per-tetrahedron volume penalty (beyond the thesis)");
  cmd->add_flag("--disc-volume-term", f.disc_volume_term,
                "Add the whole-disc volume penalty (beyond the thesis)");
  cmd->add_option("--volume-factor", f.volume_factor,
                  "c_v of the per-tetrahedron term, k_v = c_v K / V0_t")
      ->capture_default_str();
  cmd->add_option("--disc-volume-factor", f.disc_volume_factor,
                  "c_g of the whole-disc term, k_g = c_g K / V0")
      ->capture_default_str();
  f.damping_option = cmd->add_option(
      "--damping", f.damping_n_s_per_mm,
      "Ambient damping K_d per node, N·s/mm (default: critical for the first axial mode)");
}

mss::MssOptions model_options(const ModelFlags& f) {
  mss::MssOptions o;
  o.radial_springs = !f.no_radial;
  o.torsion_springs = !f.no_torsion;
  o.volume_term = f.volume_term;
  o.disc_volume_term = f.disc_volume_term;
  if (!std::isfinite(f.volume_factor) || f.volume_factor <= 0 ||
      !std::isfinite(f.disc_volume_factor) || f.disc_volume_factor <= 0)
    throw std::invalid_argument(
        "--volume-factor and --disc-volume-factor must be finite numbers > 0");
  o.volume_factor = f.volume_factor;
  o.disc_volume_factor = f.disc_volume_factor;
  if (f.damping_option && f.damping_option->count() > 0) {
    if (!std::isfinite(f.damping_n_s_per_mm) || f.damping_n_s_per_mm < 0)
      throw std::invalid_argument("--damping must be a finite number >= 0 N·s/mm");
    o.damping_n_s_per_mm = f.damping_n_s_per_mm;
  }
  return o;
}

std::string model_variant(const ModelFlags& f) {
  std::string v = f.no_radial ? "no-radial" : "radial";
  if (f.volume_term) v += "+volume-term";
  if (f.disc_volume_term) v += "+disc-volume-term";
  if (f.no_torsion) v += "+no-torsion";
  return v;
}

}  // namespace spinesim::cli

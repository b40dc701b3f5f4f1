#include "spinesim/studies/mss_run.hpp"

#include "spinesim/calibration/tuned_disc.hpp"
#include "spinesim/common/timer.hpp"
#include "spinesim/studies/format.hpp"

#include <algorithm>

namespace spinesim::studies {

bool StepStats::step(mss::Simulator& sim, mss::State& s, const mss::Boundary& bc) {
  const Timer t0;
  const mss::StepReport rep = sim.step(s, bc);
  const double dt = t0.seconds();
  if (!rep.ok) {
    diverged = true;
    message = one_line(rep.message);
    return false;
  }
  ++steps_done;
  newton_iterations += rep.newton_iterations;
  seconds_sum += dt;
  seconds_max = std::max(seconds_max, dt);
  return true;
}

void StepStats::add_to(nlohmann::json& j) const {
  j["steps_done"] = steps_done;
  j["step_seconds_mean"] = mean_seconds();
  j["step_seconds_max"] = seconds_max;
  j["newton_iterations"] = newton_iterations;
  j["diverged"] = diverged;
  if (diverged) j["message"] = message;
}

nlohmann::json mss_model_json(const mss::MssModel& model, const mesh::RegionMaterials& materials) {
  const auto& cyl = model.cylinder();
  const auto& o = model.options();
  const double g_annulus = materials.at(int(mesh::Region::annulus)).shear_modulus_mpa();
  const double g_nucleus = materials.at(int(mesh::Region::nucleus)).shear_modulus_mpa();
  return {{"springs",
           {{"edge", model.num_edge_springs()},
            {"radial_tets", model.num_radial_tets()},
            {"angle", model.num_angle_springs()},
            {"volume_terms", model.num_volume_terms()}}},
          {"total_mass_kg", model.total_mass_t() * 1e3},
          {"K_d_n_s_per_mm", model.damping_n_s_per_mm()},
          {"equivalent_cylinder",
           {{"D_u_mm", cyl.upper_diameter_mm},
            {"D_l_mm", cyl.lower_diameter_mm},
            {"D_m_mm", cyl.mean_diameter_mm},
            {"L_m_mm", cyl.length_mm},
            {"volume_mm3", cyl.volume_mm3},
            {"num_angle_springs", cyl.num_angle_springs},
            {"k_t_per_shear_modulus_mm3", cyl.k_t_per_shear_modulus},
            {"k_t_nmm_per_rad",
             {{"annulus", g_annulus * cyl.k_t_per_shear_modulus},
              {"nucleus", g_nucleus * cyl.k_t_per_shear_modulus}}}}},
          {"options", [&o] {
             nlohmann::json j = calibration::terms_json(o);
             j["damping_ratio"] = o.damping_ratio;
             return j;
           }()}};
}

}  // namespace spinesim::studies

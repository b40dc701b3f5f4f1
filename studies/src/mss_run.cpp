#include "spinesim/studies/mss_run.hpp"
#include "spinesim/mss/simulator.hpp"

#include "spinesim/calibration/tuned_disc.hpp"
#include "spinesim/common/timer.hpp"
#include "spinesim/mss/quantities.hpp"
#include "spinesim/studies/fem_reference.hpp"
#include "spinesim/studies/toolkit.hpp"

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <sstream>

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

mss::Boundary PlateLoad::boundary(double factor) const {
  mss::Boundary b;
  b.plate_center_mm = center;
  if (is_wrench) {
    b.plate_mode = mss::PlateMode::wrench;
    b.wrench = factor * value;
  } else {
    b.superior = mss::plate_pose(factor * value, center);
  }
  return b;
}

namespace {

/// Static equilibrium under the full load.
void solve_static_load(const mss::MssModel& model, MssRunResult& r, const StageHooks& hooks) {
  hooks.begin_stage("static equilibrium (Newton)");
  r.statics = mss::solve_static(model, r.request.load.boundary(1.0));
  hooks.end_stage(std::to_string(r.statics.iterations) + " iterations");
  r.seconds = r.statics.seconds;
  r.x_mm = r.statics.x_mm;
  r.plate_motion = r.statics.plate_motion;
  r.reaction_wrench = r.statics.reaction_wrench;
  r.failed = !r.statics.converged || !r.x_mm.allFinite();
  if (r.failed)
    r.failure = "static solve did not converge after " + std::to_string(r.statics.iterations) +
                " iterations: " + one_line(r.statics.message);
}

/// Steps in time: the load ramped over the first 10 % of the steps, then held.
void step_in_time(const mss::MssModel& model, MssRunResult& r, VtuSeries* frames,
                  const StageHooks& hooks) {
  const MssRunRequest& rq = r.request;
  mss::Simulator sim(model, rq.dynamics);
  mss::State s = sim.rest_state();
  r.ramp_steps = std::max(1, int(std::ceil(0.1 * rq.steps)));
  const int every = rq.frame_every > 0 ? rq.frame_every : std::max(1, rq.steps / 100);
  if (frames) frames->add(0.0, model, s.x_mm);

  hooks.begin_stage(std::to_string(rq.steps) + " steps of " + rq.integrator_name + " Euler, dt " +
                    std::to_string(rq.dynamics.dt_s) + " s");
  const Timer timer;
  for (int k = 1; k <= rq.steps; ++k) {
    if (!r.stats.step(sim, s, rq.load.boundary(std::min(1.0, double(k) / r.ramp_steps)))) break;
    if (frames && (k % every == 0 || k == rq.steps)) frames->add(s.time_s, model, s.x_mm);
  }
  r.seconds = timer.seconds();
  hooks.end_stage(std::to_string(r.stats.steps_done) + " steps");

  r.x_mm = s.x_mm;
  r.time_s = s.time_s;
  // The load factor of the last good step.
  const double applied = std::min(1.0, double(r.stats.steps_done) / r.ramp_steps);
  r.plate_motion =
      rq.load.is_wrench ? mss::Vector6d(s.plate_q) : mss::Vector6d(applied * rq.load.value);
  // About the moved plate centre, like StaticResult::reaction_wrench.
  r.reaction_wrench = mss::plate_reaction(model, r.x_mm, rq.load.center + r.plate_motion.head<3>());
  if (r.stats.diverged) {
    const int k = r.stats.steps_done + 1;
    const double dt = rq.dynamics.dt_s;
    std::ostringstream os;
    os << "diverged at step " << k << " of " << rq.steps << " (t = " << k * dt << " s, "
       << rq.integrator_name << " Euler, dt = " << dt << " s): " << r.stats.message;
    if (rq.dynamics.integrator != mss::Integrator::implicit_euler) {
      const double stable = sim.predicted_stable_dt_s(rq.dynamics.integrator);
      if (std::isfinite(stable)) os << "; predicted stable dt < " << stable << " s";
    }
    r.failed = true;
    r.failure = os.str();
  }
}

}  // namespace

MssRunResult run_mss_load(const mss::MssModel& model, const MssRunRequest& request,
                          VtuSeries* frames, const StageHooks& hooks) {
  MssRunResult r;
  r.request = request;
  if (request.dynamic)
    step_in_time(model, r, frames, hooks);
  else
    solve_static_load(model, r, hooks);
  r.volume_mm3 = model.volume_mm3(r.x_mm);
  r.rest_volume_mm3 = model.rest_volume_mm3();
  r.volume_change = mss::volume_change(model, r.x_mm);
  r.max_displacement_mm = mss::max_displacement_mm(model, r.x_mm);
  r.inverted_tets = model.inverted_tets(r.x_mm);
  return r;
}

nlohmann::json mss_run_json(const MssRunResult& r) {
  const MssRunRequest& rq = r.request;
  nlohmann::json j;
  if (rq.dynamic) {
    j["integrator"] = rq.integrator_name;
    j["dt_s"] = rq.dynamics.dt_s;
    j["steps"] = rq.steps;
    j["ramp_steps"] = r.ramp_steps;
    j["time_s"] = r.time_s;
    j["matrix_update"] =
        rq.dynamics.matrix_update == mss::MatrixUpdate::frozen ? "frozen" : "every_iteration";
    r.stats.add_to(j);
    j["timings"]["stepping_s"] = r.seconds;
  } else {
    j["converged"] = r.statics.converged;
    j["iterations"] = r.statics.iterations;
    j["residual_n"] = r.statics.residual_n;
    j["timings"]["solve_s"] = r.seconds;
  }
  j["reaction_wrench"] = to_json(Eigen::VectorXd(r.reaction_wrench));
  j["reaction_wrench_units"] =
      "Fx,Fy,Fz [N], Mx,My,Mz [N·mm] exerted by the disc on the plate, about the moved plate "
      "centre";
  j["plate_motion"] = to_json(Eigen::VectorXd(motion_rad_to_deg(r.plate_motion)));
  j["plate_motion_units"] = "tx,ty,tz [mm], rx,ry,rz [deg]";
  j["volume_mm3"] = r.volume_mm3;
  j["rest_volume_mm3"] = r.rest_volume_mm3;
  j["volume_change"] = r.volume_change;
  j["max_displacement_mm"] = r.max_displacement_mm;
  j["inverted_tets"] = r.inverted_tets;
  return j;
}

void print_mss_run(std::ostream& os, const mss::MssModel& model, const std::string& mesh_label,
                   const std::string& material, const std::string& constants,
                   const MssRunResult& r) {
  const mesh::TetMesh& m = model.mesh();
  const MssRunRequest& rq = r.request;
  os << std::setprecision(5) << "MSS on " << mesh_label << " (" << m.num_vertices() << " nodes, "
     << m.num_tets() << " tets), material " << material << ", " << constants << "\n"
     << "  springs       " << model.num_edge_springs() << " edge, " << model.num_radial_tets()
     << " radial tets, " << model.num_angle_springs() << " angle, " << model.num_volume_terms()
     << " volume\n"
     << "  plate centre  " << rq.load.center.transpose() << " mm\n";
  if (rq.dynamic)
    os << "  dynamic       " << r.stats.steps_done << " of " << rq.steps << " steps, dt "
       << rq.dynamics.dt_s << " s, mean step " << r.stats.mean_seconds() * 1e3 << " ms\n";
  else
    os << "  static        " << (r.statics.converged ? "converged" : "NOT converged") << " in "
       << r.statics.iterations << " Newton iterations\n";
  const auto qd = motion_rad_to_deg(r.plate_motion);
  os << "  plate motion  t = " << qd.head<3>().transpose()
     << " mm, r = " << qd.tail<3>().transpose() << " deg\n"
     << "  reaction      " << to_json(Eigen::VectorXd(r.reaction_wrench)).dump() << " (N, N·mm)\n"
     << "  volume        " << r.volume_mm3 << " mm^3, change " << 100.0 * r.volume_change << " %\n";
}

}  // namespace spinesim::studies

#include "spinesim/calibration/nonlinear_protocol.hpp"

#include "spinesim/common/constants.hpp"
#include "spinesim/common/timer.hpp"

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <sstream>
#include <stdexcept>

namespace spinesim::calibration {

namespace {

std::vector<fem::LoadCase> all_cases(const NonlinearCalibrationRequest& rq) {
  std::vector<fem::LoadCase> all = rq.train;
  all.insert(all.end(), rq.holdout.begin(), rq.holdout.end());
  return all;
}

/// One (case, level) row of the report: untuned (scales 1) beside tuned.
nlohmann::json case_row(const NonlinearCaseError& before, const NonlinearCaseError& after,
                        const NonlinearReferenceCase& ref) {
  nlohmann::json row = {{"name", after.name},
                        {"level", after.level},
                        {"untuned_error", before.displacement_error},
                        {"tuned_error", after.displacement_error},
                        {"untuned_reaction_error", before.reaction_error},
                        {"tuned_reaction_error", after.reaction_error},
                        {"fem_plate_rotation_deg", ref.plate_motion.tail<3>().norm() * kDegPerRad},
                        {"fem_plate_shift_mm", ref.plate_motion.head<3>().norm()},
                        {"converged", before.converged && after.converged}};
  // Why a solve failed (the untuned network's, else the tuned one's).
  if (!before.converged) row["message"] = "untuned: " + before.message;
  if (!after.converged) row["message"] = "tuned: " + after.message;
  return row;
}

nlohmann::json report(const NonlinearCalibrationOutcome& o, const NonlinearCalibrationRequest& rq,
                      const mss::MssModel& network) {
  nlohmann::json train = nlohmann::json::array(), holdout = nlohmann::json::array();
  for (std::size_t i = 0; i < o.fit.after.size(); ++i)
    (o.fit.after[i].trained ? train : holdout)
        .push_back(case_row(o.fit.before[i], o.fit.after[i], o.reference.cases[i]));
  const LeastSquaresFit& f = o.fit.fit;
  const bool fibres = network.options().fibre_springs;
  return {
      {"reference", "nonlinear FEM"},
      {"fem_order", rq.fem_order},
      {"load_levels", rq.load_levels},
      {"load_increments", rq.load_increments},
      {"terms", term_set_name(rq.terms)},
      {"fibre_elements", network.num_fibre_springs()},
      {"fibre_stretch", !fibres                              ? "none"
                        : network.options().isochoric_fibres ? "isochoric"
                                                             : "spring"},
      {"errors",
       "reaction |S (R - R*)| / |S R*| (S scales moments by the plate's RMS radius) and "
       "displacement ||u - u*|| / ||u*|| of the free vertices, the MSS's plate at the FEM's pose"},
      {"plate_rms_radius_mm", o.reference.plate_rms_radius_mm},
      {"train", train},
      {"holdout", holdout},
      {"objective", f.objective},
      {"active_bounds", f.active_bounds},
      {"scale_bounds", {rq.fit.lower_scale, rq.fit.upper_scale}},
      {"ipopt",
       {{"status", f.status},
        {"success", f.success},
        {"iterations", f.iterations},
        {"evaluations", f.model_evaluations},
        {"seconds", f.seconds}}},
      {"fem_seconds", o.reference.seconds},
      {"seconds", o.total_seconds}};
}

}  // namespace

void validate(const NonlinearCalibrationRequest& rq) {
  check_cases(rq.train, rq.holdout);
  if (rq.load_levels.empty()) throw std::invalid_argument("--nonlinear needs a load level");
  for (double l : rq.load_levels)
    if (!std::isfinite(l) || !(l > 0) || l > 2)
      throw std::invalid_argument("load levels must be in (0, 2] (factors on the standard loads)");
  if (rq.fem_order != 1 && rq.fem_order != 2)
    throw std::invalid_argument("the FEM order must be 1 or 2");
  if (rq.load_increments < 1) throw std::invalid_argument("load increments must be >= 1");
}

mss::MssOptions nonlinear_network(const mesh::RegionMaterials& materials,
                                  const NonlinearCalibrationRequest& rq) {
  mss::MssOptions o = term_set_options(rq.terms);
  o.fibre_springs = materials.has_fibres();
  o.isochoric_fibres = o.fibre_springs && rq.isochoric_fibres;
  return o;
}

NonlinearCalibrationOutcome calibrate_disc_nonlinear(const mesh::TetMesh& mesh,
                                                     const mesh::RegionMaterials& materials,
                                                     const NonlinearCalibrationRequest& rq,
                                                     const StatusLine& status) {
  validate(rq);
  mesh::require_endplate_labels(mesh);
  const Timer timer;
  const auto say = [&](const std::string& s) {
    if (status) status(s);
  };
  NonlinearCalibrationOutcome out;
  fem::NewtonOptions newton;
  newton.load_increments = rq.load_increments;
  const std::vector<fem::LoadCase> cases = all_cases(rq);
  const int total = int(cases.size() * rq.load_levels.size());
  say("nonlinear FEM reference (P" + std::to_string(rq.fem_order) + "): " + std::to_string(total) +
      " solves");
  out.reference = nonlinear_reference(
      mesh, materials, cases, rq.load_levels, rq.fem_order, newton, [&](int done, int n) {
        say("FEM solve " + std::to_string(done) + "/" + std::to_string(n) + " done");
      });
  const mss::MssModel network(mesh, materials, nonlinear_network(materials, rq));
  NonlinearFitRequest fit = rq.fit;
  fit.train.clear();
  for (const auto& c : rq.train) fit.train.push_back(c.name);
  say("fitting the network's scales (" + term_set_name(rq.terms) +
      (network.options().fibre_springs ? ", fibre elements" : "") + ")");
  out.fit = fit_mss_nonlinear(network, out.reference, fit, [&](int it, double objective, double) {
    std::ostringstream s;
    s << "Ipopt iteration " << it << ": objective " << std::setprecision(4) << objective;
    say(s.str());
  });
  out.success = out.fit.fit.success;

  TunedDisc& t = out.tuned;
  t.level = disc_level(mesh);
  t.material_name = materials.name;
  t.material = material_signature(materials);
  t.mesh = fingerprint(mesh);
  t.fem_order = rq.fem_order;
  t.options = network.options();
  for (std::size_t j = 0; j < out.fit.knobs.size(); ++j)
    t.scales[knob_name(out.fit.knobs[j])] = out.fit.fit.parameters(Eigen::Index(j));
  out.total_seconds = timer.seconds();
  t.report = report(out, rq, network);
  return out;
}

}  // namespace spinesim::calibration

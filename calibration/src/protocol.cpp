#include "spinesim/calibration/protocol.hpp"

#include "spinesim/common/constants.hpp"
#include "spinesim/common/timer.hpp"
#include "spinesim/fem/plate_stiffness.hpp"

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <sstream>
#include <stdexcept>

namespace spinesim::calibration {

namespace {

std::vector<std::string> names(const std::vector<fem::LoadCase>& cases) {
  std::vector<std::string> out;
  for (const auto& c : cases) out.push_back(c.name);
  return out;
}

nlohmann::json evaluation_json(const Evaluation& e) {
  return {{"J", e.value},
          {"displacement", e.displacement},
          {"reaction", e.reaction},
          {"stiffness", e.stiffness},
          {"regularisation", e.regularisation}};
}

const CaseError& case_error(const Evaluation& e, const std::string& name) {
  for (const auto& c : e.cases)
    if (c.name == name) return c;
  throw std::logic_error("calibration report: case " + name + " missing");
}

const CaseComparison* case_check(const MssFemComparison& c, const std::string& name) {
  for (const auto& r : c.cases)
    if (r.name == name) return &r;
  return nullptr;
}

Eigen::VectorXd diag(const fem::Matrix6d& k) { return fem::stiffness_per_degree(k).diagonal(); }

nlohmann::json to_json(const Eigen::VectorXd& v) {
  return std::vector<double>(v.data(), v.data() + v.size());
}

/// An Ipopt run in the report (either stage's result), plus `extra` fields.
template <class Result>
nlohmann::json ipopt_json(const Result& r, nlohmann::json extra) {
  extra.update(
      {{"status", r.status},
       {"success", r.success},
       {"iterations", r.iterations},
       {"evaluations", r.evaluations},
       {"seconds", r.seconds},
       {"seconds_per_evaluation", r.evaluations ? r.evaluation_seconds / r.evaluations : 0.0}});
  return extra;
}

/// The per-spring stage in the report: weights, Ipopt, J at both ends, where the multipliers went.
nlohmann::json per_spring_json(const PerSpringResult& r, const CalibrationRequest& rq,
                               Eigen::Index edges) {
  std::vector<double> q(r.log_multipliers.data(),
                        r.log_multipliers.data() + r.log_multipliers.size());
  std::sort(q.begin(), q.end());
  const double lo = std::log(rq.per_spring_ipopt.lower_scale),
               hi = std::log(rq.per_spring_ipopt.upper_scale);
  const auto count = [&q](auto pred) { return std::count_if(q.begin(), q.end(), pred); };
  const auto objective = [](const PerSpringEvaluation& e) {
    nlohmann::json j = evaluation_json(e.data);
    j["J"] = e.value;
    j["data"] = e.data.value;
    j["smoothness"] = e.smoothness;
    j["prior"] = e.prior;
    j.erase("regularisation");
    return j;
  };
  return {
      {"edge_springs", edges},
      {"weights",
       {{"smoothness", rq.per_spring_weights.smoothness}, {"prior", rq.weights.regularisation}}},
      {"multiplier_bounds", {rq.per_spring_ipopt.lower_scale, rq.per_spring_ipopt.upper_scale}},
      {"multipliers",
       {{"min", std::exp(q.front())},
        {"median", std::exp(q[q.size() / 2])},
        {"max", std::exp(q.back())},
        {"at_lower_bound", count([lo](double v) { return v <= lo + 1e-6; })},
        {"at_upper_bound", count([hi](double v) { return v >= hi - 1e-6; })}}},
      {"kept_region_fit", r.kept_start},
      {"objective", {{"start", objective(r.start)}, {"final", objective(r.final)}}},
      {"ipopt", ipopt_json(r, {{"hessian", "limited-memory BFGS"}})},
      {"transfer",
       "per-spring multipliers belong to this mesh; other meshes get the region-level scales"}};
}

}  // namespace

std::vector<fem::LoadCase> held_out_cases(const std::vector<fem::LoadCase>& train) {
  std::vector<fem::LoadCase> out;
  for (const auto& c : fem::standard_load_cases()) {
    bool used = false;
    for (const auto& t : train) used = used || t.name == c.name;
    if (!used) out.push_back(c);
  }
  return out;
}

void check_cases(const std::vector<fem::LoadCase>& train,
                 const std::vector<fem::LoadCase>& holdout) {
  if (train.empty())
    throw std::invalid_argument("calibration needs at least one training case (--train)");
  for (const auto& h : holdout)
    for (const auto& t : train)
      if (h.name == t.name)
        throw std::invalid_argument("case '" + h.name + "' is both trained on and held out");
}

namespace {

/// Refuses a request that cannot run (before any work).
void check_request(const mesh::TetMesh& m, const CalibrationRequest& rq) {
  check_cases(rq.train, rq.holdout);
  validate(rq.ipopt);
  if (rq.per_spring) {
    validate(rq.per_spring_ipopt);
    const auto& w = rq.per_spring_weights;
    if (!std::isfinite(w.smoothness) || w.smoothness < 0 || !std::isfinite(w.prior) || w.prior < 0)
      throw std::invalid_argument("per-spring weights (--smoothness) must be finite and >= 0");
  }
  mesh::require_endplate_labels(m);
  for (const auto& [label, other] : rq.transfer_meshes) {
    mesh::require_endplate_labels(other);
    const std::string a = disc_level(m), b = disc_level(other);
    if (!a.empty() && !b.empty() && a != b)
      throw std::invalid_argument("transfer mesh " + label + " is a " + b +
                                  " disc, the calibration mesh a " + a + " disc");
  }
}

/// Ipopt's per-iteration line for the status callback.
std::function<void(int, double, double)> ipopt_progress(const StatusLine& say,
                                                        const std::string& stage) {
  return [say, stage](int it, double J, double inf_du) {
    std::ostringstream s;
    s << stage << "Ipopt iteration " << it << ": J = " << std::setprecision(4) << J
      << ", dual infeasibility " << std::setprecision(2) << inf_du;
    say(s.str());
  };
}

/// The tuned file's identity and scales (and per-spring multipliers when that stage ran);
/// returns the region-level model options (what transfers to other meshes).
mss::MssOptions fill_tuned_file(CalibrationOutcome& out, const mesh::TetMesh& m,
                                const mesh::RegionMaterials& materials,
                                const CalibrationRequest& rq, const mss::MssOptions& options,
                                const LinearMss& lin, const mss::MssModel& model) {
  TunedDisc& t = out.tuned;
  t.level = disc_level(m);
  t.material_name = materials.name;
  t.material = material_signature(materials);
  t.mesh = fingerprint(m);
  t.fem_order = rq.fem_order;
  t.options = options;
  for (std::size_t j = 0; j < lin.knobs().size(); ++j)
    t.scales[knob_name(lin.knobs()[j])] = std::exp(out.result.log_scales(Eigen::Index(j)));
  const mss::MssOptions region_options = t.mss_options();  // before the multipliers: what transfers
  if (out.per_spring_ran) {
    const Eigen::VectorXd mu = out.per_spring.log_multipliers.array().exp();
    t.edge_multipliers.assign(mu.data(), mu.data() + mu.size());
    t.edge_order = edge_order_hash(model);
  }
  return region_options;
}

/// The nonlinear MSS-vs-FEM protocol on every case for the untuned, the tuned and (after the
/// per-spring stage) the region-only model, at the check load scale.
void run_nonlinear_checks(CalibrationOutcome& out, const fem::DiscFem& fem,
                          const mss::MssModel& thesis_model, const mesh::TetMesh& m,
                          const mesh::RegionMaterials& materials, const CalibrationRequest& rq,
                          const std::vector<fem::LoadCase>& all,
                          const mss::MssOptions& region_options, const StatusLine& say) {
  say("nonlinear check: untuned and tuned MSS vs FEM, " + std::to_string(all.size()) + " cases");
  const Timer t0;
  const auto compare = [&](const fem::DiscFem& f, const mss::MssModel& model) {
    return compare_mss_fem(f, model, all, materials.name, mss::StaticOptions(),
                           rq.check_load_scale);
  };
  out.untuned_check = compare(fem, thesis_model);
  out.tuned_check = compare(fem, mss::MssModel(m, materials, out.tuned.mss_options()));
  if (out.per_spring_ran) {
    say("nonlinear check: the region-only fit, " + std::to_string(all.size()) + " cases");
    out.region_check = compare(fem, mss::MssModel(m, materials, region_options));
  }
  out.check_seconds = t0.seconds();
}

/// The region scales on other meshes of the disc (they transfer; how well? Per-spring
/// multipliers belong to this mesh and are not carried over).
void run_transfer_checks(CalibrationOutcome& out, const mesh::RegionMaterials& materials,
                         const CalibrationRequest& rq, const std::vector<fem::LoadCase>& all,
                         const mss::MssOptions& region_options, const StatusLine& say) {
  for (const auto& [label, other] : rq.transfer_meshes) {
    say("transfer check on " + label + " (" + std::to_string(other.num_tets()) +
        " tets): FEM and MSS");
    const Timer t0;
    const fem::DiscFem other_fem(other, materials, rq.fem_order,
                                 fem::DiscFem::default_plate_center(other));
    TransferCheck tc;
    tc.label = label;
    tc.untuned = compare_mss_fem(other_fem,
                                 mss::MssModel(other, materials, term_set_options(TermSet::thesis)),
                                 all, materials.name, mss::StaticOptions(), rq.check_load_scale);
    tc.tuned = compare_mss_fem(other_fem, mss::MssModel(other, materials, region_options), all,
                               materials.name, mss::StaticOptions(), rq.check_load_scale);
    tc.seconds = t0.seconds();
    out.transfer.push_back(std::move(tc));
  }
}

/// One report row per case: linearised and nonlinear errors, untuned beside tuned (and the
/// region-only fit beside the per-spring one).
nlohmann::json case_rows(const CalibrationOutcome& out, const FemReference& ref,
                         const std::vector<fem::LoadCase>& cases) {
  nlohmann::json rows = nlohmann::json::array();
  const Evaluation& tuned_linear =
      out.per_spring_ran ? out.per_spring.final.data : out.result.final;
  for (const auto& lc : cases) {
    const auto& u = case_error(out.untuned_linear, lc.name);
    const auto& f = case_error(tuned_linear, lc.name);
    nlohmann::json r = {{"name", lc.name},
                        {"untuned_error_linear", u.displacement_error},
                        {"tuned_error_linear", f.displacement_error},
                        {"untuned_reaction_error_linear", u.reaction_error},
                        {"tuned_reaction_error_linear", f.reaction_error}};
    for (const auto& ref_case : ref.cases)
      if (ref_case.name == lc.name)
        r["fem_plate_rotation_deg"] = ref_case.plate_motion.tail<3>().norm() * kDegPerRad;
    if (out.per_spring_ran) {  // the region-only fit beside the per-spring one
      const auto& g = case_error(out.result.final, lc.name);
      r["region_error_linear"] = g.displacement_error;
      r["region_reaction_error_linear"] = g.reaction_error;
      const CaseComparison* rn = case_check(out.region_check, lc.name);
      r["region_error"] = rn ? rn->displacement_error : g.displacement_error;
      if (rn) r["region_reaction_error"] = rn->reaction_error;
    }
    const CaseComparison* un = case_check(out.untuned_check, lc.name);
    const CaseComparison* tn = case_check(out.tuned_check, lc.name);
    if (un && tn) {
      r["untuned_error"] = un->displacement_error;
      r["tuned_error"] = tn->displacement_error;
      r["untuned_reaction_error"] = un->reaction_error;
      r["tuned_reaction_error"] = tn->reaction_error;
      r["untuned_inverted_tets"] = un->inverted_tets;
      r["tuned_inverted_tets"] = tn->inverted_tets;
      r["converged"] = un->converged && tn->converged;
    } else {  // no nonlinear check: the linearised errors are all there is
      r["untuned_error"] = u.displacement_error;
      r["tuned_error"] = f.displacement_error;
    }
    rows.push_back(r);
  }
  return rows;
}

/// The transfer checks in the report (region-level scales only).
nlohmann::json transfer_json(const CalibrationOutcome& out, const CalibrationRequest& rq) {
  nlohmann::json rows = nlohmann::json::array();
  for (const TransferCheck& tc : out.transfer) {  // region-level scales only
    nlohmann::json cases = nlohmann::json::array();
    for (std::size_t i = 0; i < tc.tuned.cases.size(); ++i)
      cases.push_back({{"name", tc.tuned.cases[i].name},
                       {"untuned_error", tc.untuned.cases[i].displacement_error},
                       {"tuned_error", tc.tuned.cases[i].displacement_error}});
    const Eigen::VectorXd f = diag(tc.tuned.k6_fem), u = diag(tc.untuned.k6_mss),
                          k = diag(tc.tuned.k6_mss);
    rows.push_back({{"mesh", tc.label},
                    {"scales", "region-level"},
                    {"load_scale", rq.check_load_scale},
                    {"note", out.per_spring_ran
                                 ? "per-spring multipliers do not transfer to another mesh: the "
                                   "region-level scales are checked here"
                                 : "region-level scales transfer to other meshes of the disc"},
                    {"nodes", tc.tuned.nodes},
                    {"tets", tc.tuned.tets},
                    {"cases", cases},
                    {"stiffness_ratio_untuned", to_json(Eigen::VectorXd(u.cwiseQuotient(f)))},
                    {"stiffness_ratio_tuned", to_json(Eigen::VectorXd(k.cwiseQuotient(f)))},
                    {"seconds", tc.seconds}});
  }
  return rows;
}

/// The report stored in the tuned file (t.report): protocol, cases, K6 diagonals, objective,
/// weights, transfer, Ipopt and timings.
nlohmann::json calibration_report(const CalibrationOutcome& out, const CalibrationRequest& rq,
                                  const mesh::TetMesh& m, const LinearMss& lin,
                                  const FemReference& ref, Eigen::Index edge_springs) {
  const Eigen::VectorXd kf = diag(out.k6_fem), ku = diag(out.k6_untuned), kt = diag(out.k6_tuned),
                        kr = diag(out.k6_region);
  nlohmann::json knobs = nlohmann::json::array();
  for (const auto& k : lin.knobs()) knobs.push_back(knob_name(k));
  nlohmann::json report = {
      {"method",
       "Ipopt on the MSS linearised at rest (exact adjoint gradient, Gauss-Newton Hessian); errors "
       "`untuned_error`/`tuned_error`: nonlinear static MSS vs FEM at the case loads x check_load_scale, as "
       "`spinesim mss compare --load-scale`; `fem_plate_rotation_deg`: the FEM plate's rotation at the full case load; "
       "`*_linear`: the linearised MSS the optimiser fitted. With --per-spring, `tuned_*` is the per-spring model "
       "(region scales x one multiplier per main spring) and `region_*` the region-only fit it started from"},
      {"untuned", "thesis network (main + radial + torsion springs), Van Gelder constants, scales 1"},
      {"check_load_scale", rq.nonlinear_check ? nlohmann::json(rq.check_load_scale) : nlohmann::json(nullptr)},
      {"terms", term_set_name(rq.terms)},
      {"knobs", knobs},
      {"fem_order", rq.fem_order},
      {"tets", m.num_tets()},
      {"nodes", m.num_vertices()},
      {"train", case_rows(out, ref, rq.train)},
      {"holdout", case_rows(out, ref, rq.holdout)},
      {"stiffness_diagonal",
       {{"fem", to_json(kf)},
        {"untuned", to_json(ku)},
        {"tuned", to_json(kt)},
        {"ratio_untuned", to_json(Eigen::VectorXd(ku.cwiseQuotient(kf)))},
        {"ratio_tuned", to_json(Eigen::VectorXd(kt.cwiseQuotient(kf)))},
        {"region", to_json(kr)},
        {"ratio_region", to_json(Eigen::VectorXd(kr.cwiseQuotient(kf)))},
        {"units", "tx,ty,tz [N/mm], rx,ry,rz [N·mm/deg], global frame, linear (rest)"}}},
      {"objective",
       {{"untuned", evaluation_json(out.untuned_linear)},
        {"start", evaluation_json(out.result.start)},
        {"final", evaluation_json(out.result.final)}}},
      {"weights",
       {{"reaction", rq.weights.reaction},
        {"stiffness", rq.weights.stiffness},
        {"regularisation", rq.weights.regularisation}}},
      {"transfer", transfer_json(out, rq)},
      {"ipopt", ipopt_json(out.result, {{"scale_bounds", {rq.ipopt.lower_scale, rq.ipopt.upper_scale}}})},
      {"timings",
       {{"fem_s", out.fem_seconds},
        {"setup_s", out.setup_seconds},
        {"ipopt_s", out.result.seconds},
        {"per_spring_s", out.per_spring_ran ? out.per_spring.seconds : 0.0},
        {"nonlinear_check_s", out.check_seconds},
        {"transfer_s", [&] { double x = 0; for (const auto& tc : out.transfer) x += tc.seconds; return x; }()},
        {"total_s", out.total_seconds}}}};
  if (out.per_spring_ran) report["per_spring"] = per_spring_json(out.per_spring, rq, edge_springs);
  return report;
}

}  // namespace

TermSet parse_term_set(const std::string& name) {
  if (name == "thesis") return TermSet::thesis;
  if (name == "thesis+volume") return TermSet::thesis_volume;
  if (name == "all") return TermSet::all;
  throw std::invalid_argument("unknown --terms '" + name + "' (thesis, thesis+volume, all)");
}

std::string term_set_name(TermSet t) {
  switch (t) {
    case TermSet::thesis:
      return "thesis";
    case TermSet::thesis_volume:
      return "thesis+volume";
    case TermSet::all:
      return "all";
  }
  return "?";
}

mss::MssOptions term_set_options(TermSet t) {
  mss::MssOptions o;
  o.volume_term = t != TermSet::thesis;
  o.disc_volume_term = t == TermSet::all;
  return o;
}

CalibrationOutcome calibrate_disc(const mesh::TetMesh& m, const mesh::RegionMaterials& materials,
                                  const CalibrationRequest& rq, const StatusLine& status) {
  const Timer t_start;
  const StatusLine say = [&status](const std::string& s) {
    if (status) status(s);
  };
  check_request(m, rq);
  CalibrationOutcome out;
  std::vector<fem::LoadCase> all = rq.train;
  all.insert(all.end(), rq.holdout.begin(), rq.holdout.end());

  // 1. FEM reference on the same mesh.
  say("FEM P" + std::to_string(rq.fem_order) + " reference (" + std::to_string(m.num_tets()) +
      " tets)");
  Timer t0;
  const Eigen::Vector3d c = fem::DiscFem::default_plate_center(m);
  const fem::DiscFem fem(m, materials, rq.fem_order, c);
  const FemReference ref = make_reference(fem, m, all);
  out.k6_fem = ref.k6;
  out.fem_seconds = t0.seconds();

  // 2. Linearised models: the untuned thesis network (baseline) and the one to tune.
  say("linearising the mass-spring model at rest");
  t0.restart();
  const mss::MssModel thesis_model(m, materials, term_set_options(TermSet::thesis));
  LinearMss thesis_lin(thesis_model, available_knobs(thesis_model.options()), c);
  Objective thesis_obj(thesis_lin, ref, names(rq.train), rq.weights);
  out.untuned_linear =
      thesis_obj.evaluate(Eigen::VectorXd::Zero(Eigen::Index(thesis_lin.knobs().size())), false);
  out.k6_untuned = out.untuned_linear.k6;
  const mss::MssOptions options = term_set_options(rq.terms);
  const mss::MssModel model(m, materials, options);
  LinearMss lin(model, available_knobs(options), c);
  Objective obj(lin, ref, names(rq.train), rq.weights);
  out.setup_seconds = t0.seconds();

  // 3. Ipopt from Van Gelder (all scales 1).
  say("Ipopt: " + std::to_string(lin.knobs().size()) + " stiffness scales, " +
      std::to_string(rq.train.size()) + " training cases");
  out.result = calibrate(obj, Eigen::VectorXd::Zero(Eigen::Index(lin.knobs().size())), rq.ipopt,
                         ipopt_progress(say, ""));
  out.k6_region = out.k6_tuned = out.result.final.k6;
  out.success = out.result.success;

  // 3b. Per-spring multipliers on top of the fitted region scales.
  if (rq.per_spring && out.result.success) {
    say("per-spring stage: " + std::to_string(model.num_edge_springs()) +
        " edge springs, Ipopt limited-memory BFGS");
    PerSpringWeights w = rq.per_spring_weights;
    w.prior = rq.weights.regularisation;
    PerSpringObjective ps(obj, model, out.result.log_scales, w);
    out.per_spring =
        calibrate_per_spring(ps, rq.per_spring_ipopt, ipopt_progress(say, "per-spring "));
    out.per_spring_ran = true;
    out.k6_tuned = out.per_spring.final.data.k6;
    out.success = out.per_spring.success;
  }

  // 4. The tuned file, the nonlinear checks (as `mss compare`) and the transfer meshes.
  const mss::MssOptions region_options =
      fill_tuned_file(out, m, materials, rq, options, lin, model);
  if (rq.nonlinear_check && out.success)
    run_nonlinear_checks(out, fem, thesis_model, m, materials, rq, all, region_options, say);
  if (out.success) run_transfer_checks(out, materials, rq, all, region_options, say);
  out.total_seconds = t_start.seconds();

  // 5. Report.
  out.tuned.report = calibration_report(out, rq, m, lin, ref, model.num_edge_springs());
  return out;
}

}  // namespace spinesim::calibration

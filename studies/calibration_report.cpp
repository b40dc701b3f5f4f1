#include "calibration_report.hpp"

#include "cli_common.hpp"
#include "fem_report.hpp"

#include <chrono>
#include <iomanip>
#include <iostream>
#include <sstream>
#include <stdexcept>

namespace spinesim::cli {

namespace {

using clock_type = std::chrono::steady_clock;

std::vector<std::string> names(const std::vector<fem::LoadCase>& cases) {
  std::vector<std::string> out;
  for (const auto& c : cases) out.push_back(c.name);
  return out;
}

nlohmann::json evaluation_json(const calibration::Evaluation& e) {
  return {{"J", e.value},
          {"displacement", e.displacement},
          {"reaction", e.reaction},
          {"stiffness", e.stiffness},
          {"regularisation", e.regularisation}};
}

const calibration::CaseError& case_error(const calibration::Evaluation& e, const std::string& name) {
  for (const auto& c : e.cases)
    if (c.name == name) return c;
  throw std::logic_error("calibration report: case " + name + " missing");
}

const CaseComparison* case_check(const MssFemComparison& c, const std::string& name) {
  for (const auto& r : c.cases)
    if (r.name == name) return &r;
  return nullptr;
}

Eigen::VectorXd diag(const fem::Matrix6d& k) { return stiffness_per_degree(k).diagonal(); }

std::string pct(double e) {
  std::ostringstream s;
  s << std::fixed << std::setprecision(1) << 100.0 * e << " %";
  return s.str();
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
    case TermSet::thesis: return "thesis";
    case TermSet::thesis_volume: return "thesis+volume";
    case TermSet::all: return "all";
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
  const auto t_start = clock_type::now();
  const auto say = [&](const std::string& s) {
    if (status) status(s);
  };
  if (rq.train.empty()) throw std::invalid_argument("calibration needs at least one training case (--train)");
  for (const auto& h : rq.holdout)
    for (const auto& t : rq.train)
      if (h.name == t.name) throw std::invalid_argument("case '" + h.name + "' is both trained on and held out");
  calibration::validate(rq.ipopt);
  mesh::require_endplate_labels(m);
  for (const auto& [label, other] : rq.transfer_meshes) {
    mesh::require_endplate_labels(other);
    const std::string a = calibration::disc_level(m), b = calibration::disc_level(other);
    if (!a.empty() && !b.empty() && a != b)
      throw std::invalid_argument("transfer mesh " + label + " is a " + b + " disc, the calibration mesh a " + a + " disc");
  }

  CalibrationOutcome out;
  std::vector<fem::LoadCase> all = rq.train;
  all.insert(all.end(), rq.holdout.begin(), rq.holdout.end());

  // 1. FEM reference on the same mesh.
  say("FEM P" + std::to_string(rq.fem_order) + " reference (" + std::to_string(m.num_tets()) + " tets)");
  auto t0 = clock_type::now();
  const Eigen::Vector3d c = fem::DiscFem::default_plate_center(m);
  const fem::DiscFem fem(m, materials, rq.fem_order, c);
  const calibration::FemReference ref = calibration::make_reference(fem, m, all);
  out.k6_fem = ref.k6;
  out.fem_seconds = seconds_since(t0);

  // 2. Linearised models: the untuned thesis network (baseline) and the one to tune.
  say("linearising the mass-spring model at rest");
  t0 = clock_type::now();
  const mss::MssModel thesis_model(m, materials, term_set_options(TermSet::thesis));
  calibration::LinearMss thesis_lin(thesis_model, calibration::available_knobs(thesis_model.options()), c);
  calibration::Objective thesis_obj(thesis_lin, ref, names(rq.train), rq.weights);
  out.untuned_linear = thesis_obj.evaluate(Eigen::VectorXd::Zero(Eigen::Index(thesis_lin.knobs().size())), false);
  out.k6_untuned = out.untuned_linear.k6;

  const mss::MssOptions options = term_set_options(rq.terms);
  const mss::MssModel model(m, materials, options);
  calibration::LinearMss lin(model, calibration::available_knobs(options), c);
  calibration::Objective obj(lin, ref, names(rq.train), rq.weights);
  out.setup_seconds = seconds_since(t0);

  // 3. Ipopt from Van Gelder (all scales 1).
  say("Ipopt: " + std::to_string(lin.knobs().size()) + " stiffness scales, " + std::to_string(rq.train.size()) +
      " training cases");
  out.result = calibration::calibrate(obj, Eigen::VectorXd::Zero(Eigen::Index(lin.knobs().size())), rq.ipopt,
                                      [&](int it, double J, double inf_du) {
                                        std::ostringstream s;
                                        s << "Ipopt iteration " << it << ": J = " << std::setprecision(4) << J
                                          << ", dual infeasibility " << std::setprecision(2) << inf_du;
                                        say(s.str());
                                      });
  out.k6_tuned = out.result.final.k6;

  // 4. The tuned file's contents.
  calibration::TunedDisc& t = out.tuned;
  t.level = calibration::disc_level(m);
  t.material_name = materials.name;
  t.material = calibration::material_signature(materials);
  t.mesh = calibration::fingerprint(m);
  t.fem_order = rq.fem_order;
  t.options = options;
  for (std::size_t j = 0; j < lin.knobs().size(); ++j)
    t.scales[calibration::knob_name(lin.knobs()[j])] = std::exp(out.result.log_scales(Eigen::Index(j)));

  // 5. Nonlinear checks at the cases' loads (as `mss compare`).
  if (rq.nonlinear_check && out.result.success) {
    say("nonlinear check: untuned and tuned MSS vs FEM, " + std::to_string(all.size()) + " cases");
    t0 = clock_type::now();
    out.untuned_check = compare_mss_fem(fem, thesis_model, all, materials.name, mss::StaticOptions(), rq.check_load_scale);
    mss::MssModel tuned(m, materials, t.mss_options());
    out.tuned_check = compare_mss_fem(fem, tuned, all, materials.name, mss::StaticOptions(), rq.check_load_scale);
    out.check_seconds = seconds_since(t0);
  }
  // 6. The same scales on other meshes of the disc (region scales transfer; how well?).
  if (out.result.success)
    for (const auto& [label, other] : rq.transfer_meshes) {
      say("transfer check on " + label + " (" + std::to_string(other.num_tets()) + " tets): FEM and MSS");
      t0 = clock_type::now();
      const fem::DiscFem other_fem(other, materials, rq.fem_order, fem::DiscFem::default_plate_center(other));
      TransferCheck tc;
      tc.label = label;
      tc.untuned = compare_mss_fem(other_fem, mss::MssModel(other, materials, term_set_options(TermSet::thesis)), all,
                                   materials.name, mss::StaticOptions(), rq.check_load_scale);
      tc.tuned = compare_mss_fem(other_fem, mss::MssModel(other, materials, t.mss_options()), all, materials.name,
                                 mss::StaticOptions(), rq.check_load_scale);
      tc.seconds = seconds_since(t0);
      out.transfer.push_back(std::move(tc));
    }
  out.total_seconds = seconds_since(t_start);

  // 7. Report.
  auto case_rows = [&](const std::vector<fem::LoadCase>& cases) {
    nlohmann::json rows = nlohmann::json::array();
    for (const auto& lc : cases) {
      const auto& u = case_error(out.untuned_linear, lc.name);
      const auto& f = case_error(out.result.final, lc.name);
      nlohmann::json r = {{"name", lc.name},
                          {"untuned_error_linear", u.displacement_error},
                          {"tuned_error_linear", f.displacement_error},
                          {"untuned_reaction_error_linear", u.reaction_error},
                          {"tuned_reaction_error_linear", f.reaction_error}};
      for (const auto& ref_case : ref.cases)
        if (ref_case.name == lc.name)
          r["fem_plate_rotation_deg"] = ref_case.plate_motion.tail<3>().norm() * 180.0 / 3.14159265358979323846;
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
  };
  const Eigen::VectorXd kf = diag(out.k6_fem), ku = diag(out.k6_untuned), kt = diag(out.k6_tuned);
  nlohmann::json knobs = nlohmann::json::array();
  for (const auto& k : lin.knobs()) knobs.push_back(calibration::knob_name(k));
  t.report = {
      {"method",
       "Ipopt on the MSS linearised at rest (exact adjoint gradient, Gauss-Newton Hessian); errors "
       "`untuned_error`/`tuned_error`: nonlinear static MSS vs FEM at the case loads x check_load_scale, as "
       "`spinesim mss compare --load-scale`; `fem_plate_rotation_deg`: the FEM plate's rotation at the full case load; "
       "`*_linear`: the linearised MSS the optimiser fitted"},
      {"untuned", "thesis network (main + radial + torsion springs), Van Gelder constants, scales 1"},
      {"check_load_scale", rq.nonlinear_check ? nlohmann::json(rq.check_load_scale) : nlohmann::json(nullptr)},
      {"terms", term_set_name(rq.terms)},
      {"knobs", knobs},
      {"fem_order", rq.fem_order},
      {"tets", m.num_tets()},
      {"nodes", m.num_vertices()},
      {"train", case_rows(rq.train)},
      {"holdout", case_rows(rq.holdout)},
      {"stiffness_diagonal",
       {{"fem", to_json(kf)},
        {"untuned", to_json(ku)},
        {"tuned", to_json(kt)},
        {"ratio_untuned", to_json(Eigen::VectorXd(ku.cwiseQuotient(kf)))},
        {"ratio_tuned", to_json(Eigen::VectorXd(kt.cwiseQuotient(kf)))},
        {"units", "tx,ty,tz [N/mm], rx,ry,rz [N·mm/deg], global frame, linear (rest)"}}},
      {"objective",
       {{"untuned", evaluation_json(out.untuned_linear)},
        {"start", evaluation_json(out.result.start)},
        {"final", evaluation_json(out.result.final)}}},
      {"weights",
       {{"reaction", rq.weights.reaction},
        {"stiffness", rq.weights.stiffness},
        {"regularisation", rq.weights.regularisation}}},
      {"transfer",
       [&] {
         nlohmann::json rows = nlohmann::json::array();
         for (const TransferCheck& tc : out.transfer) {
           nlohmann::json cases = nlohmann::json::array();
           for (std::size_t i = 0; i < tc.tuned.cases.size(); ++i)
             cases.push_back({{"name", tc.tuned.cases[i].name},
                              {"untuned_error", tc.untuned.cases[i].displacement_error},
                              {"tuned_error", tc.tuned.cases[i].displacement_error}});
           const Eigen::VectorXd f = diag(tc.tuned.k6_fem), u = diag(tc.untuned.k6_mss), k = diag(tc.tuned.k6_mss);
           rows.push_back({{"mesh", tc.label},
                           {"nodes", tc.tuned.nodes},
                           {"tets", tc.tuned.tets},
                           {"cases", cases},
                           {"stiffness_ratio_untuned", to_json(Eigen::VectorXd(u.cwiseQuotient(f)))},
                           {"stiffness_ratio_tuned", to_json(Eigen::VectorXd(k.cwiseQuotient(f)))},
                           {"seconds", tc.seconds}});
         }
         return rows;
       }()},
      {"ipopt",
       {{"status", out.result.status},
        {"success", out.result.success},
        {"iterations", out.result.iterations},
        {"evaluations", out.result.evaluations},
        {"seconds", out.result.seconds},
        {"seconds_per_evaluation",
         out.result.evaluations ? out.result.evaluation_seconds / out.result.evaluations : 0.0},
        {"scale_bounds", {rq.ipopt.lower_scale, rq.ipopt.upper_scale}}}},
      {"timings",
       {{"fem_s", out.fem_seconds},
        {"setup_s", out.setup_seconds},
        {"ipopt_s", out.result.seconds},
        {"nonlinear_check_s", out.check_seconds},
        {"transfer_s", [&] { double x = 0; for (const auto& tc : out.transfer) x += tc.seconds; return x; }()},
        {"total_s", out.total_seconds}}}};
  return out;
}

mss::MssModel tuned_model(const calibration::TunedDisc& tuned, const mesh::TetMesh& mesh,
                          const mesh::RegionMaterials& materials, bool quiet) {
  const std::string note = calibration::check_applies(tuned, mesh, materials);
  if (!note.empty() && !quiet) std::cerr << "spinesim: note: " << note << "\n";
  return mss::MssModel(mesh, materials, tuned.mss_options());
}

void print_calibration(std::ostream& os, const CalibrationOutcome& o, const CalibrationRequest& rq) {
  const auto& rep = o.tuned.report;
  os << "Calibration of " << (o.tuned.level.empty() ? "disc" : o.tuned.level) << " (" << rep["nodes"] << " nodes, "
     << rep["tets"] << " tets), material " << o.tuned.material_name << ", terms " << term_set_name(rq.terms)
     << ", FEM P" << rq.fem_order << "\n"
     << "Ipopt: " << o.result.status << " after " << o.result.iterations << " iterations, " << o.result.evaluations
     << " evaluations, " << std::fixed << std::setprecision(2) << o.result.seconds << " s ("
     << std::setprecision(1) << 1e3 * rep["ipopt"]["seconds_per_evaluation"].get<double>()
     << " ms per objective + gradient + Hessian)\n\n";
  os << (rq.nonlinear_check ? "Relative nodal displacement error vs FEM (nonlinear MSS at the case loads x " +
                                 std::to_string(rq.check_load_scale).substr(0, 4) + "; linearised in brackets):\n\n"
                             : "Relative nodal displacement error vs FEM (linearised MSS only: --no-check):\n\n")
     << "  " << std::left << std::setw(18) << "case" << std::setw(10) << "set" << std::right << std::setw(24)
     << "untuned (Van Gelder)" << std::setw(24) << "tuned" << "\n";
  for (const char* set : {"train", "holdout"})
    for (const auto& r : rep[set]) {
      const auto cell = [&](const char* nl, const char* lin) {
        return pct(r[nl].get<double>()) + " (" + pct(r[lin].get<double>()) + ")";
      };
      os << "  " << std::left << std::setw(18) << r["name"].get<std::string>() << std::setw(10) << set << std::right
         << std::setw(24) << cell("untuned_error", "untuned_error_linear") << std::setw(24)
         << cell("tuned_error", "tuned_error_linear") << "\n";
    }
  static const char* dof[] = {"tx [N/mm]", "ty [N/mm]", "tz [N/mm]", "rx [N·mm/deg]", "ry [N·mm/deg]", "rz [N·mm/deg]"};
  const auto& kd = rep["stiffness_diagonal"];
  os << "\n6x6 plate stiffness diagonal (linear), MSS / FEM:\n\n  " << std::left << std::setw(16) << "DOF" << std::right
     << std::setw(12) << "FEM" << std::setw(12) << "untuned" << std::setw(12) << "tuned" << "\n";
  for (int i = 0; i < 6; ++i) {
    os << "  " << std::left << std::setw(16) << dof[i] << std::right << std::defaultfloat << std::setprecision(4)
       << std::setw(12) << kd["fem"][std::size_t(i)].get<double>() << std::fixed << std::setprecision(3)
       << std::setw(12) << kd["ratio_untuned"][std::size_t(i)].get<double>() << std::setw(12)
       << kd["ratio_tuned"][std::size_t(i)].get<double>() << "\n";
  }
  for (const auto& tr : rep["transfer"]) {
    os << "\nSame scales on another mesh: " << tr["mesh"].get<std::string>() << " (" << tr["tets"] << " tets), vs the FEM there:\n\n"
       << "  " << std::left << std::setw(18) << "case" << std::right << std::setw(24) << "untuned" << std::setw(24) << "tuned"
       << "\n";
    for (const auto& c : tr["cases"])
      os << "  " << std::left << std::setw(18) << c["name"].get<std::string>() << std::right << std::setw(24)
         << pct(c["untuned_error"].get<double>()) << std::setw(24) << pct(c["tuned_error"].get<double>()) << "\n";
    os << "  6x6 diagonal MSS/FEM, tuned:";
    for (const auto& r : tr["stiffness_ratio_tuned"]) os << " " << std::fixed << std::setprecision(3) << r.get<double>();
    os << std::defaultfloat << "\n";
  }
  os << "\nTuned scales (x Van Gelder constants):";
  for (const auto& [name, s] : o.tuned.scales) os << "  " << name << " " << std::setprecision(3) << s;
  os << std::defaultfloat << "\n";
}

}  // namespace spinesim::cli

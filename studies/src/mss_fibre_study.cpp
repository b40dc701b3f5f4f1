#include "spinesim/studies/mss_fibre_study.hpp"

#include "spinesim/calibration/protocol.hpp"
#include "spinesim/common/constants.hpp"
#include "spinesim/common/timer.hpp"
#include "spinesim/mss/model.hpp"
#include "spinesim/studies/toolkit.hpp"

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <sstream>
#include <stdexcept>

namespace spinesim::studies {

namespace {

mss::MssOptions network(calibration::TermSet terms, bool fibres, bool isochoric) {
  mss::MssOptions o = calibration::term_set_options(terms);
  o.fibre_springs = fibres;
  o.isochoric_fibres = fibres && isochoric;
  return o;
}

nlohmann::json fit_json(const calibration::NonlinearFitResult& f) {
  nlohmann::json scales = nlohmann::json::object();
  for (std::size_t j = 0; j < f.knobs.size(); ++j)
    scales[calibration::knob_name(f.knobs[j])] = f.fit.parameters(Eigen::Index(j));
  nlohmann::json cases = nlohmann::json::array();
  for (std::size_t i = 0; i < f.after.size(); ++i) {
    const calibration::NonlinearCaseError &a = f.after[i], &b = f.before[i];
    cases.push_back({{"case", a.name},
                     {"level", a.level},
                     {"set", a.trained ? "train" : "held-out"},
                     {"reaction_error_untuned", b.reaction_error},
                     {"displacement_error_untuned", b.displacement_error},
                     {"reaction_error", a.reaction_error},
                     {"displacement_error", a.displacement_error},
                     {"reaction_wrench", to_json(a.reaction_mss)},
                     {"converged", a.converged}});
  }
  return {{"success", f.fit.success},
          {"status", f.fit.status},
          {"iterations", f.fit.iterations},
          {"model_evaluations", f.fit.model_evaluations},
          {"seconds", f.fit.seconds},
          {"objective", f.fit.objective},
          {"scales", scales},
          {"active_bounds", f.fit.active_bounds},
          {"cases", cases}};
}

/// The curves of the pure-moment cases: the FEM at `curve_levels`, each fitted network at the
/// FEM's poses (the fits' scales on copies of the networks).
std::vector<MomentCurve> moment_curves(const mesh::RegionMaterials& materials,
                                       const mss::MssModel& region, const mss::MssModel& fibre,
                                       const MssFibreStudyResult& r, const MssFibreStudyOptions& o,
                                       const fem::NewtonOptions& newton) {
  std::vector<fem::LoadCase> moments;
  for (const fem::LoadCase& c : o.cases)
    if (c.wrench_local.head<3>().isZero() && !c.wrench_local.tail<3>().isZero())
      moments.push_back(c);
  std::vector<MomentCurve> curves;
  if (moments.empty()) return curves;
  const calibration::NonlinearReference ref = calibration::nonlinear_reference(
      region.mesh(), materials, moments, o.curve_levels, o.fem_order, newton);
  mss::MssModel tuned_region = region, tuned_fibre = fibre;
  tuned_region.set_scales(r.region.scales);
  tuned_fibre.set_scales(r.fibre.scales);
  const auto region_at = calibration::nonlinear_errors(tuned_region, ref);
  const auto fibre_at = calibration::nonlinear_errors(tuned_fibre, ref);
  for (std::size_t i = 0; i < ref.cases.size(); ++i) {
    const calibration::NonlinearReferenceCase& c = ref.cases[i];
    if (curves.empty() || curves.back().name != c.name) {
      curves.push_back({c.name,
                        std::find(o.train.begin(), o.train.end(), c.name) != o.train.end(),
                        {},
                        {},
                        {},
                        {}});
    }
    const Eigen::Vector3d e = c.wrench.tail<3>().normalized();
    const auto moment_nm = [&](const calibration::Vector6d& reaction) {
      return -reaction.tail<3>().dot(e) / 1000.0;
    };
    MomentCurve& curve = curves.back();
    curve.rotation_deg.push_back(c.plate_motion.tail<3>().dot(e) * kDegPerRad);
    curve.fem_moment_nm.push_back(moment_nm(c.reaction));
    curve.region_moment_nm.push_back(moment_nm(region_at[i].reaction_mss));
    curve.fibre_moment_nm.push_back(moment_nm(fibre_at[i].reaction_mss));
  }
  return curves;
}

/// The targets in N m/deg named as a curve's case.
std::vector<DiscValidationRow> corridors(const std::vector<MomentCurve>& curves,
                                         const nlohmann::json& targets) {
  std::vector<DiscValidationRow> rows;
  if (targets.is_null()) return rows;
  for (const auto& t : targets.at("targets")) {
    DiscValidationRow row = disc_target_row(t);
    const bool drawn = std::any_of(curves.begin(), curves.end(),
                                   [&](const MomentCurve& c) { return c.name == row.quantity; });
    if (drawn && row.units == "N m/deg") rows.push_back(std::move(row));
  }
  return rows;
}

nlohmann::json curves_json(const std::vector<MomentCurve>& curves) {
  nlohmann::json out = nlohmann::json::array();
  for (const MomentCurve& c : curves)
    out.push_back({{"case", c.name},
                   {"set", c.trained ? "train" : "held-out"},
                   {"rotation_deg", c.rotation_deg},
                   {"fem_moment_nm", c.fem_moment_nm},
                   {"region_moment_nm", c.region_moment_nm},
                   {"fibre_moment_nm", c.fibre_moment_nm}});
  return out;
}

nlohmann::json corridors_json(const std::vector<DiscValidationRow>& rows) {
  nlohmann::json out = nlohmann::json::array();
  for (const DiscValidationRow& t : rows) {
    out.push_back(disc_target_json(t));
    out.back()["preparation"] = t.preparation;
  }
  return out;
}

}  // namespace

void validate(const MssFibreStudyOptions& o, const mesh::RegionMaterials& materials) {
  if (!materials.has_fibres())
    throw std::invalid_argument("study mss-fibres: material '" + materials.name +
                                "' has no fibres (use fibre-reinforced or a preset with fibres)");
  if (o.levels.empty()) throw std::invalid_argument("study mss-fibres: no load level");
  for (const auto* levels : {&o.levels, &o.curve_levels})
    for (double l : *levels)
      if (!std::isfinite(l) || !(l > 0) || l > 2)
        throw std::invalid_argument("study mss-fibres: load levels must be in (0, 2]");
  if (o.fem_order != 1 && o.fem_order != 2)
    throw std::invalid_argument("study mss-fibres: --fem-order must be 1 or 2");
  if (o.threads < 1 || o.load_increments < 1)
    throw std::invalid_argument("study mss-fibres: threads and increments must be >= 1");
  if (o.train.empty()) throw std::invalid_argument("study mss-fibres: no training case");
  for (const std::string& t : o.train)
    if (std::none_of(o.cases.begin(), o.cases.end(),
                     [&](const fem::LoadCase& c) { return c.name == t; }))
      throw std::invalid_argument("study mss-fibres: training case '" + t +
                                  "' is not among the cases");
  if (o.cases.size() <= o.train.size())
    throw std::invalid_argument("study mss-fibres: every case is trained; none is held out");
}

MssFibreStudyResult run_mss_fibre_study(const mesh::TetMesh& mesh,
                                        const mesh::RegionMaterials& materials,
                                        const MssFibreStudyOptions& o,
                                        const std::string& mesh_label,
                                        const std::function<void(const std::string&)>& status) {
  validate(o, materials);
  const Timer timer;
  auto say = [&](const std::string& s) {
    if (status) status(s);
  };
  MssFibreStudyResult r;
  r.mesh_label = mesh_label;
  r.material = materials.name;
  r.terms = calibration::term_set_name(o.terms);
  r.nodes = mesh.num_vertices();
  r.tets = mesh.num_tets();
  fem::NewtonOptions newton;
  newton.load_increments = o.load_increments;
  say("nonlinear FEM reference: " + std::to_string(o.cases.size() * o.levels.size()) +
      " solves (P" + std::to_string(o.fem_order) + ")");
  r.reference = calibration::nonlinear_reference(
      mesh, materials, o.cases, o.levels, o.fem_order, newton, [&](int done, int total) {
        say("FEM solve " + std::to_string(done) + "/" + std::to_string(total) + " done");
      });
  calibration::NonlinearFitRequest request;
  request.train = o.train;
  request.fit.threads = o.threads;
  const auto progress = [&](int it, double objective, double) {
    std::ostringstream s;
    s << "  Ipopt iteration " << it << ", objective " << objective;
    say(s.str());
  };
  say("fitting the region-scale network (" + calibration::term_set_name(o.terms) + ")");
  const mss::MssModel region(mesh, materials, network(o.terms, false, false));
  r.region = calibration::fit_mss_nonlinear(region, r.reference, request, progress);
  say("fitting the network with fibre springs");
  const mss::MssModel fibre(mesh, materials, network(o.terms, true, o.isochoric_fibres));
  r.fibre_springs = fibre.num_fibre_springs();
  r.fibre_stretch = o.isochoric_fibres ? "isochoric" : "spring";
  r.fibre = calibration::fit_mss_nonlinear(fibre, r.reference, request, progress);
  if (!o.curve_levels.empty()) {
    say("moment-rotation curves");
    r.curves = moment_curves(materials, region, fibre, r, o, newton);
    r.corridors = corridors(r.curves, o.targets);
  }
  r.seconds = timer.seconds();
  return r;
}

void print_mss_fibre_study(std::ostream& out, const MssFibreStudyResult& r) {
  out << "# Mass-spring disc against the nonlinear FEM disc\n\n"
      << r.mesh_label << ", " << r.nodes << " nodes, " << r.tets << " tets; material " << r.material
      << "; FEM P" << r.reference.fem_order << "; network terms " << r.terms << "; "
      << r.fibre_springs << " fibre springs (" << r.fibre_stretch << " stretch)\n\n"
      << "Errors of the MSS with its plate at the FEM's pose: reaction |S dR|/|S R*| and "
         "displacement of the free vertices ||du||/||u*||.\n\n"
      << "| case | load | set | FEM shift (mm) | FEM rotation (deg) | region MSS reaction | "
         "region MSS displ. | fibre MSS reaction | fibre MSS displ. |\n"
         "|---|---:|---|---:|---:|---:|---:|---:|---:|\n";
  for (std::size_t i = 0; i < r.fibre.after.size(); ++i) {
    const auto &g = r.region.after[i], &f = r.fibre.after[i];
    const auto& c = r.reference.cases[i];
    out << "| " << f.name << " | " << f.level << "× | " << (f.trained ? "train" : "held out")
        << " | " << fixed(c.plate_motion.head<3>().norm(), 3) << " | "
        << fixed(c.plate_motion.tail<3>().norm() * kDegPerRad, 2) << " | "
        << percent(g.reaction_error) << " | " << percent(g.displacement_error) << " | "
        << percent(f.reaction_error) << " | " << percent(f.displacement_error) << " |\n";
  }
  for (const auto* fit : {&r.region, &r.fibre}) {
    out << "\n"
        << (fit == &r.region ? "Region network" : "Fibre network") << ": "
        << (fit->fit.success ? "converged" : "NOT converged") << " (" << fit->fit.status << "), "
        << fit->fit.iterations << " Ipopt iterations, " << fit->fit.model_evaluations
        << " evaluations, " << std::fixed << std::setprecision(0) << fit->fit.seconds
        << " s; scales:";
    out << std::setprecision(3) << std::defaultfloat;
    for (std::size_t j = 0; j < fit->knobs.size(); ++j)
      out << " " << calibration::knob_name(fit->knobs[j]) << " "
          << fit->fit.parameters(Eigen::Index(j));
    if (!fit->fit.active_bounds.empty()) {
      out << "; at bounds:";
      for (std::size_t b = 0; b < fit->fit.active_bounds.size(); ++b)
        out << (b == 0 ? " " : ", ") << fit->fit.active_bounds[b];
    }
    out << ".\n";
  }
  if (!r.curves.empty()) {
    out << "\nMoment-rotation at the FEM's poses (moment and rotation along the applied "
           "moment):\n\n"
        << "| case | set | rotation (deg) | FEM (N m) | region MSS (N m) | fibre MSS (N m) |\n"
           "|---|---|---:|---:|---:|---:|\n";
    for (const MomentCurve& c : r.curves)
      for (std::size_t k = 0; k < c.rotation_deg.size(); ++k)
        out << "| " << c.name << " | " << (c.trained ? "train" : "held out") << " | "
            << fixed(c.rotation_deg[k], 2) << " | " << fixed(c.fem_moment_nm[k], 2) << " | "
            << fixed(c.region_moment_nm[k], 2) << " | " << fixed(c.fibre_moment_nm[k], 2) << " |\n";
  }
  out << "\nFEM reference " << std::fixed << std::setprecision(0) << r.reference.seconds
      << " s; whole study " << r.seconds << " s\n";
}

nlohmann::json mss_fibre_study_json(const MssFibreStudyResult& r) {
  nlohmann::json reference = nlohmann::json::array();
  for (const auto& c : r.reference.cases)
    reference.push_back({{"case", c.name},
                         {"level", c.level},
                         {"wrench", to_json(c.wrench)},
                         {"plate_motion", to_json(c.plate_motion)},
                         {"reaction_wrench", to_json(c.reaction)},
                         {"newton_iterations", c.newton_iterations},
                         {"seconds", c.seconds}});
  return {{"mesh", r.mesh_label},
          {"nodes", r.nodes},
          {"tets", r.tets},
          {"material", r.material},
          {"fem_order", r.reference.fem_order},
          {"terms", r.terms},
          {"plate_rms_radius_mm", r.reference.plate_rms_radius_mm},
          {"fibre_springs", r.fibre_springs},
          {"fibre_stretch", r.fibre_stretch},
          {"reference", reference},
          {"region", fit_json(r.region)},
          {"fibre", fit_json(r.fibre)},
          {"curves", curves_json(r.curves)},
          {"corridors", corridors_json(r.corridors)},
          {"seconds", r.seconds}};
}

}  // namespace spinesim::studies

#include "spinesim/studies/mss_fibre_study.hpp"

#include "spinesim/calibration/protocol.hpp"
#include "spinesim/common/timer.hpp"
#include "spinesim/mss/model.hpp"

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <sstream>
#include <stdexcept>

namespace spinesim::studies {

namespace {

mss::MssOptions network(bool fibres) {
  mss::MssOptions o = calibration::term_set_options(calibration::TermSet::thesis_volume);
  o.fibre_springs = fibres;
  return o;
}

std::string percent(double v) {
  std::ostringstream s;
  s << std::fixed << std::setprecision(1) << 100.0 * v << " %";
  return v == v ? s.str() : std::string("n/a");
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

}  // namespace

void validate(const MssFibreStudyOptions& o, const mesh::RegionMaterials& materials) {
  if (!materials.has_fibres())
    throw std::invalid_argument("study mss-fibres: material '" + materials.name +
                                "' has no fibres (use fibre-reinforced or a preset with fibres)");
  if (o.levels.empty()) throw std::invalid_argument("study mss-fibres: no load level");
  for (double l : o.levels)
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
  say("fitting the region-scale network (thesis springs + volume term)");
  const mss::MssModel region(mesh, materials, network(false));
  r.region = calibration::fit_mss_nonlinear(region, r.reference, request, progress);
  say("fitting the network with fibre springs");
  const mss::MssModel fibre(mesh, materials, network(true));
  r.fibre_springs = fibre.num_fibre_springs();
  r.fibre = calibration::fit_mss_nonlinear(fibre, r.reference, request, progress);
  r.seconds = timer.seconds();
  return r;
}

void print_mss_fibre_study(std::ostream& out, const MssFibreStudyResult& r) {
  out << "# Mass-spring disc against the nonlinear FEM disc\n\n"
      << r.mesh_label << ", " << r.nodes << " nodes, " << r.tets << " tets; material " << r.material
      << "; FEM P" << r.reference.fem_order << "; " << r.fibre_springs << " fibre springs\n\n"
      << "Errors of the MSS with its plate at the FEM's pose: reaction |S dR|/|S R*| and "
         "displacement of the free vertices ||du||/||u*||.\n\n"
      << "| case | load | set | FEM rotation/shift | region MSS reaction | region MSS displ. | "
         "fibre MSS reaction | fibre MSS displ. |\n|---|---:|---|---:|---:|---:|---:|---:|\n";
  for (std::size_t i = 0; i < r.fibre.after.size(); ++i) {
    const auto &g = r.region.after[i], &f = r.fibre.after[i];
    const auto& c = r.reference.cases[i];
    const double rot = c.plate_motion.tail<3>().norm() * 180.0 / M_PI;
    std::ostringstream motion;
    motion << std::fixed << std::setprecision(2)
           << (rot > 0.05 ? rot : c.plate_motion.head<3>().norm()) << (rot > 0.05 ? " deg" : " mm");
    out << "| " << f.name << " | " << f.level << " x | " << (f.trained ? "train" : "held out")
        << " | " << motion.str() << " | " << percent(g.reaction_error) << " | "
        << percent(g.displacement_error) << " | " << percent(f.reaction_error) << " | "
        << percent(f.displacement_error) << " |\n";
  }
  for (const auto* fit : {&r.region, &r.fibre}) {
    out << "\n"
        << (fit == &r.region ? "Region network" : "Fibre network") << ": "
        << (fit->fit.success ? "converged" : "NOT converged (" + fit->fit.status + ")") << ", "
        << fit->fit.iterations << " Ipopt iterations, " << fit->fit.model_evaluations
        << " evaluations, " << std::fixed << std::setprecision(0) << fit->fit.seconds
        << " s; scales:";
    out << std::setprecision(3) << std::defaultfloat;
    for (std::size_t j = 0; j < fit->knobs.size(); ++j)
      out << " " << calibration::knob_name(fit->knobs[j]) << " "
          << fit->fit.parameters(Eigen::Index(j));
    if (!fit->fit.active_bounds.empty()) {
      out << "; at bounds:";
      for (const auto& b : fit->fit.active_bounds) out << " " << b << ";";
    }
    out << "\n";
  }
  out << "\nFEM reference " << std::fixed << std::setprecision(0) << r.reference.seconds
      << " s; whole study " << r.seconds << " s\n";
}

nlohmann::json mss_fibre_study_json(const MssFibreStudyResult& r) {
  nlohmann::json reference = nlohmann::json::array();
  for (const auto& c : r.reference.cases)
    reference.push_back(
        {{"case", c.name},
         {"level", c.level},
         {"plate_motion", std::vector<double>(c.plate_motion.data(), c.plate_motion.data() + 6)},
         {"newton_iterations", c.newton_iterations},
         {"seconds", c.seconds}});
  return {{"mesh", r.mesh_label},
          {"nodes", r.nodes},
          {"tets", r.tets},
          {"material", r.material},
          {"fem_order", r.reference.fem_order},
          {"fibre_springs", r.fibre_springs},
          {"reference", reference},
          {"region", fit_json(r.region)},
          {"fibre", fit_json(r.fibre)},
          {"seconds", r.seconds}};
}

}  // namespace spinesim::studies

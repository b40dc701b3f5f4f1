#include "spinesim/studies/calibration_summary.hpp"

#include "spinesim/studies/toolkit.hpp"

#include <cmath>
#include <iomanip>
#include <iostream>

namespace spinesim::studies {
namespace {

std::string pct(double e) { return percent(e); }

}  // namespace

mss::MssModel tuned_model(const calibration::TunedDisc& tuned, const mesh::TetMesh& mesh,
                          const mesh::RegionMaterials& materials, bool quiet) {
  const std::string note = calibration::check_applies(tuned, mesh, materials);
  if (!note.empty() && !quiet) std::cerr << "spinesim: note: " << note << "\n";
  return calibration::build_tuned_model(tuned, mesh, materials);
}

void print_calibration(std::ostream& os, const CalibrationOutcome& o,
                       const CalibrationRequest& rq) {
  const auto& rep = o.tuned.report;
  const bool ps = o.per_spring_ran;
  os << "Calibration of " << (o.tuned.level.empty() ? "disc" : o.tuned.level) << " ("
     << rep["nodes"] << " nodes, " << rep["tets"] << " tets), material " << o.tuned.material_name
     << ", terms " << term_set_name(rq.terms) << ", FEM P" << rq.fem_order
     << (ps ? ", region scales then per-spring multipliers" : "") << "\n"
     << "Ipopt" << (ps ? " (region scales)" : "") << ": " << o.result.status << " after "
     << o.result.iterations << " iterations, " << o.result.evaluations << " evaluations, "
     << std::fixed << std::setprecision(2) << o.result.seconds << " s (" << std::setprecision(1)
     << 1e3 * rep["ipopt"]["seconds_per_evaluation"].get<double>()
     << " ms per objective + gradient + Hessian)\n";
  if (ps) {
    const auto& p = rep["per_spring"];
    os << "Ipopt (per-spring, " << p["edge_springs"] << " multipliers in [" << std::defaultfloat
       << std::setprecision(6) << rq.per_spring_ipopt.lower_scale << ", "
       << rq.per_spring_ipopt.upper_scale << "], smoothness weight "
       << rq.per_spring_weights.smoothness << ", limited-memory BFGS): " << o.per_spring.status
       << " after " << o.per_spring.iterations << " iterations, " << o.per_spring.evaluations
       << " evaluations, " << std::fixed << std::setprecision(2) << o.per_spring.seconds << " s; J "
       << std::setprecision(3) << std::scientific << o.per_spring.start.value << " -> "
       << o.per_spring.final.value << std::fixed
       << (o.per_spring.kept_start ? " (Ipopt ended higher: the region fit is kept)" : "")
       << "; multipliers " << std::setprecision(2) << p["multipliers"]["min"].get<double>()
       << " .. " << p["multipliers"]["max"].get<double>() << ", median "
       << p["multipliers"]["median"].get<double>() << "\n";
  }
  os << "\n"
     << (rq.nonlinear_check
             ? "Relative nodal displacement error vs FEM (nonlinear MSS at the case loads x " +
                   std::to_string(rq.check_load_scale).substr(0, 4) +
                   "; linearised in brackets):\n\n"
             : "Relative nodal displacement error vs FEM (linearised MSS only: --no-check):\n\n");
  std::vector<std::string> head{"case", "set", "untuned (Van Gelder)"};
  if (ps) head.push_back("region scales");
  head.push_back(ps ? "per-spring" : "tuned");
  TextTable cases(head, 2);
  for (const char* set : {"train", "holdout"})
    for (const auto& r : rep[set]) {
      const auto cell = [&](const char* nl, const char* lin) {
        return pct(r[nl].get<double>()) + " (" + pct(r[lin].get<double>()) + ")";
      };
      std::vector<std::string> row{r["name"].get<std::string>(), set,
                                   cell("untuned_error", "untuned_error_linear")};
      if (ps) row.push_back(cell("region_error", "region_error_linear"));
      row.push_back(cell("tuned_error", "tuned_error_linear"));
      cases.add(row);
    }
  cases.print(os, false);
  static const char* dof[] = {"tx [N/mm]",     "ty [N/mm]",     "tz [N/mm]",
                              "rx [N·mm/deg]", "ry [N·mm/deg]", "rz [N·mm/deg]"};
  const auto& kd = rep["stiffness_diagonal"];
  os << "\n6x6 plate stiffness diagonal (linear), MSS / FEM:\n\n";
  std::vector<std::string> khead{"DOF", "FEM", "untuned"};
  if (ps) khead.push_back("region");
  khead.push_back(ps ? "per-spring" : "tuned");
  TextTable k6(khead);
  for (std::size_t i = 0; i < 6; ++i) {
    std::vector<std::string> row{dof[i], significant(kd["fem"][i].get<double>(), 4),
                                 fixed(kd["ratio_untuned"][i].get<double>(), 3)};
    if (ps) row.push_back(fixed(kd["ratio_region"][i].get<double>(), 3));
    row.push_back(fixed(kd["ratio_tuned"][i].get<double>(), 3));
    k6.add(row);
  }
  k6.print(os, false);
  for (const auto& tr : rep["transfer"]) {
    os << "\n"
       << (ps ? "Region-level scales" : "Same scales")
       << " on another mesh: " << tr["mesh"].get<std::string>() << " (" << tr["tets"]
       << " tets), vs the FEM there"
       << (ps ? " (per-spring multipliers do not transfer to another mesh)" : "") << ":\n\n";
    TextTable t({"case", "untuned", ps ? "region scales" : "tuned"});
    for (const auto& c : tr["cases"])
      t.add({c["name"].get<std::string>(), pct(c["untuned_error"].get<double>()),
             pct(c["tuned_error"].get<double>())});
    t.print(os, false);
    os << "  6x6 diagonal MSS/FEM, tuned:";
    for (const auto& r : tr["stiffness_ratio_tuned"]) os << " " << fixed(r.get<double>(), 3);
    os << "\n";
  }
  os << "\nTuned " << (ps ? "region " : "") << "scales (x Van Gelder constants):";
  for (const auto& [name, s] : o.tuned.scales)
    os << "  " << name << " " << std::setprecision(3) << s;
  os << std::defaultfloat << "\n";
  if (ps)
    os << "Per-spring multipliers: " << o.tuned.edge_multipliers.size()
       << " (this mesh only: `mss --params` refuses the file on any other mesh)\n";
}

void print_nonlinear_calibration(std::ostream& os,
                                 const calibration::NonlinearCalibrationOutcome& o) {
  const auto& rep = o.tuned.report;
  const auto& f = o.fit.fit;
  os << "Calibration of " << (o.tuned.level.empty() ? "disc" : o.tuned.level) << " against the "
     << "nonlinear FEM (P" << o.tuned.fem_order << "), material " << o.tuned.material_name
     << ", terms " << rep["terms"].get<std::string>() << ", " << rep["fibre_elements"]
     << " fibre elements (" << rep["fibre_stretch"].get<std::string>() << " stretch)\n"
     << "Ipopt: " << f.status << " after " << f.iterations << " iterations, " << f.model_evaluations
     << " network evaluations, " << fixed(f.seconds, 1) << " s; FEM reference "
     << fixed(o.reference.seconds, 1) << " s\n\n"
     << "Errors against the FEM, the network's plate at the FEM's pose (untuned = scales 1):\n\n";
  TextTable cases({"case", "load", "set", "FEM rotation (deg)", "displacement (untuned > tuned)",
                   "reaction (untuned > tuned)"});
  for (const char* set : {"train", "holdout"})
    for (const auto& row : rep[set])
      cases.add(
          {row["name"].get<std::string>(), fixed(row["level"].get<double>(), 2) + "x",
           set == std::string("train") ? "train" : "held out",
           fixed(row["fem_plate_rotation_deg"].get<double>(), 2),
           pct(row["untuned_error"].get<double>()) + " > " + pct(row["tuned_error"].get<double>()),
           pct(row["untuned_reaction_error"].get<double>()) + " > " +
               pct(row["tuned_reaction_error"].get<double>())});
  cases.print(os, false);
  os << "\nScales:";
  for (const auto& [name, scale] : o.tuned.scales) os << " " << name << " " << fixed(scale, 3);
  os << "\n";
  if (!f.active_bounds.empty()) {
    os << "At a bound:";
    for (const auto& b : f.active_bounds) os << " " << b;
    os << "\n";
  }
}

void print_all_levels(std::ostream& os, const AllLevelsResult& r, const std::string& terms,
                      double check_load_scale) {
  const bool nonlinear = r.set.settings.value("reference", "") == "nonlinear FEM";
  const auto pair = [](double u, double t) {
    return fixed(100 * u, 0) + ">" + fixed(100 * t, 1) + "%";
  };
  const auto or_dash = [](double v) { return std::isnan(v) ? std::string("-") : percent(v); };
  TextTable table({"level", "tets", "train max (untuned>tuned)", "holdout max (untuned>tuned)",
                   nonlinear ? "reaction max (train / holdout)" : "K6 diag ratio (tuned, min-max)",
                   "Ipopt its", "time (s)"});
  for (const auto& l : r.levels) {
    if (!l.success) {
      table.add({l.level, std::to_string(l.tets), "failed: " + l.status, "-", "-",
                 std::to_string(l.iterations), fixed(l.seconds, 1)});
      continue;
    }
    table.add({l.level, std::to_string(l.tets), pair(l.train_untuned, l.train_tuned),
               std::isnan(l.holdout_untuned) ? std::string("-")
                                             : pair(l.holdout_untuned, l.holdout_tuned),
               nonlinear
                   ? or_dash(l.train_reaction_tuned) + " / " + or_dash(l.holdout_reaction_tuned)
                   : fixed(l.k6_ratio_min, 3) + "-" + fixed(l.k6_ratio_max, 3),
               std::to_string(l.iterations), fixed(l.seconds, 1)});
  }
  const bool all = r.set.levels.size() == r.levels.size();
  os << "Calibration of " << (all ? "all " : "") << r.levels.size() << " levels"
     << (all ? "" : " (" + std::to_string(r.set.levels.size()) + " succeeded)") << ", material "
     << r.set.material_name << ", terms " << terms;
  if (nonlinear)
    os << ", against the nonlinear FEM at load levels " << r.set.settings.at("load_levels").dump()
       << " x the standard loads (errors: relative nodal displacement and reaction over every "
          "level, the MSS's plate at the FEM's pose)\n\n";
  else
    os << " (errors: relative nodal displacement, nonlinear check at loads x " << check_load_scale
       << ")\n\n";
  table.print(os, false);
}

}  // namespace spinesim::studies

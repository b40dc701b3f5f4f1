#include "spinesim/studies/disc_identification.hpp"

#include "spinesim/common/parallel.hpp"
#include "spinesim/common/timer.hpp"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace spinesim::studies {
namespace {

constexpr int kAnnulus = int(mesh::Region::annulus), kNucleus = int(mesh::Region::nucleus);
const double kNaN = std::numeric_limits<double>::quiet_NaN();

/// The fit's rows of a targets file, in file order, with everything the tables print.
std::vector<IdentifiedRow> rows_of(const nlohmann::json& targets) {
  std::vector<IdentifiedRow> rows;
  for (const auto& t : targets.value("targets", nlohmann::json::array())) {
    IdentifiedRow row;
    static_cast<DiscValidationRow&>(row) = disc_target_row(t);
    if (!(row.low > 0 && row.low < row.high))
      throw std::invalid_argument("disc identification: target '" + row.quantity +
                                  "' needs a window 0 < low < high");
    rows.push_back(row);
  }
  return rows;
}

/// The rows' quantity names; throws std::invalid_argument for a quantity the disc does not give
/// or units other than the disc's.
std::vector<std::string> check_quantities(const std::vector<IdentifiedRow>& rows) {
  std::vector<std::string> names;
  for (const IdentifiedRow& row : rows) {
    bool known = false;
    for (const auto& [name, component] : nonlinear_disc_cases()) known |= row.quantity == name;
    if (!known && row.quantity != "nucleus-pressure-ratio")
      throw std::invalid_argument("disc identification: the disc gives no '" + row.quantity + "'");
    const std::string units = row.quantity == "compression"              ? "kN/mm"
                              : row.quantity == "nucleus-pressure-ratio" ? "1"
                                                                         : "N m/deg";
    if (!row.units.empty() && row.units != units)
      throw std::invalid_argument("disc identification: target '" + row.quantity + "' in '" +
                                  row.units + "', expected '" + units + "'");
    names.push_back(row.quantity);
  }
  return names;
}

std::vector<calibration::WindowTarget> windows(const std::vector<IdentifiedRow>& rows) {
  std::vector<calibration::WindowTarget> w;
  for (const IdentifiedRow& r : rows) w.push_back({r.quantity, r.low, r.high});
  return w;
}

/// f at every point, `threads` at a time, in order.
std::vector<Eigen::VectorXd> map_points(
    const std::function<Eigen::VectorXd(const Eigen::VectorXd&)>& f,
    const std::vector<Eigen::VectorXd>& points, int threads) {
  std::vector<Eigen::VectorXd> out(points.size());
  parallel_for(points.size(), threads, [&](std::size_t k) { out[k] = f(points[k]); });
  return out;
}

/// The disc's quantities at p, in the rows' order, NaN where a case did not converge.
struct DiscModel {
  const mesh::TetMesh* mesh;
  const mesh::RegionMaterials* base;
  std::vector<std::string> quantities;
  NonlinearDiscOptions options;
  std::atomic<int>* evaluations;
  std::atomic<long>* microseconds;

  Eigen::VectorXd operator()(const Eigen::VectorXd& p) const {
    const Timer t;
    const NonlinearDiscQuantities q =
        nonlinear_disc_quantities(*mesh, disc_material_at(*base, p, base->name), options);
    Eigen::VectorXd out(Eigen::Index(quantities.size()));
    for (std::size_t i = 0; i < quantities.size(); ++i) {
      const auto it = q.values.find(quantities[i]);
      out(Eigen::Index(i)) = it == q.values.end() ? kNaN : it->second;
    }
    ++*evaluations;
    *microseconds += long(t.seconds() * 1e6);
    return out;
  }
};

std::vector<calibration::FitParameter> fit_parameters(const std::vector<DiscParameter>& ps,
                                                      const Eigen::VectorXd& start) {
  std::vector<calibration::FitParameter> out;
  for (std::size_t j = 0; j < ps.size(); ++j) {
    calibration::FitParameter f = ps[j].fit;
    f.start = std::clamp(start(Eigen::Index(j)), f.lower, f.upper);
    out.push_back(f);
  }
  return out;
}

}  // namespace

void validate(const DiscIdentificationOptions& o) {
  for (int order : {o.coarse_order, o.fine_order})
    if (order != 1 && order != 2)
      throw std::invalid_argument("disc identification: orders must be 1 or 2");
  if (o.load_increments < 1 || o.load_increments > 1000 || o.max_mapping_rounds < 1 ||
      o.max_mapping_rounds > 20 || !(o.mapping_tolerance > 0) || o.threads < 1)
    throw std::invalid_argument(
        "disc identification: increments 1-1000, mapping rounds 1-20, a tolerance > 0 and "
        "threads >= 1 expected");
}

std::vector<DiscParameter> disc_parameters(const mesh::RegionMaterials& base) {
  if (!base.by_region.count(kAnnulus) || !base.by_region.count(kNucleus) ||
      !base.fibres.count(kAnnulus))
    throw std::invalid_argument("disc identification: material '" + base.name +
                                "' needs an annulus with fibres and a nucleus");
  const mesh::FibreReinforcement& f = base.fibres.at(kAnnulus);
  return {
      {{"annulus-E", "MPa", base.at(kAnnulus).youngs_modulus_mpa, 1.0, 4.2},
       "lower: annulus ground substance C10 0.133, C01 0.0333 MPa (BMC Musculoskelet Disord "
       "2024;25:639, Table 1), E = 6(C10 + C01) = 1.0 MPa; upper: E 4.2 MPa (BioMed Res Int "
       "2013:705185, Table 1, the preset's)"},
      {{"fibre-scale", "", 1.0, 0.5, 2.0},
       "ours, an assumption: a factor 2 either way on the single-lamella moduli of Skaggs et al. "
       "1994 (" +
           significant(f.modulus_inner_mpa, 3) + "-" + significant(f.modulus_outer_mpa, 3) +
           " MPa), not a published range"},
      {{"fibre-k2", "", f.toe_k2, 1.0, 100.0},
       "ours, an assumption: the toe exponent of the exponential fibre law from nearly quadratic "
       "(1) to a toe that ends within a few per cent strain (100)"},
      {{"nucleus-E", "MPa", base.at(kNucleus).youngs_modulus_mpa, 0.72, 1.26},
       "lower: nucleus neo-Hookean C10 0.12 MPa (BMC Musculoskelet Disord 2015, doi "
       "10.1186/s12891-015-0686-z, Table 1, grade 0), E = 6 C10; upper: Mooney-Rivlin C10 0.12, "
       "C01 0.09 MPa (BMC "
       "Musculoskelet Disord 2024;25:639, Table 1), E = 6(C10 + C01)"}};
}

mesh::RegionMaterials disc_material_at(const mesh::RegionMaterials& base, const Eigen::VectorXd& p,
                                       const std::string& name) {
  mesh::RegionMaterials m = base;
  m.name = name;
  m.by_region.at(kAnnulus).youngs_modulus_mpa = p(0);
  mesh::FibreReinforcement& f = m.fibres.at(kAnnulus);
  f.modulus_inner_mpa *= p(1);
  f.modulus_outer_mpa *= p(1);
  f.toe_k2 = p(2);
  m.by_region.at(kNucleus).youngs_modulus_mpa = p(3);
  return m;
}

namespace {

/// The fits' shared state: the two discs as models, the rows and the parameters.
struct Identification {
  DiscModel coarse, fine;
  std::vector<IdentifiedRow> rows;
  std::vector<DiscParameter> parameters;
  const DiscIdentificationOptions& options;
  const StageHooks& hooks;

  /// The coarse model times the fine/coarse ratios.
  calibration::QuantityModel corrected(const Eigen::VectorXd& ratio) const {
    const DiscModel c = coarse;
    return [c, ratio](const Eigen::VectorXd& p) -> Eigen::VectorXd {
      return c(p).cwiseProduct(ratio);
    };
  }

  calibration::WindowFitOptions fit_options() const {
    calibration::WindowFitOptions o;
    o.ipopt = options.ipopt;
    o.threads = options.threads;
    return o;
  }

  static std::string summary(const calibration::WindowFit& f) {
    return std::to_string(f.iterations) + " Ipopt iterations, " + f.status;
  }

  calibration::WindowFit fit(const Eigen::VectorXd& ratio, const Eigen::VectorXd& start,
                             const std::string& what) const {
    hooks.begin_stage(what);
    calibration::WindowFit f = calibration::fit_to_windows(
        corrected(ratio), fit_parameters(parameters, start), windows(rows),
        std::vector<bool>(rows.size(), true), fit_options());
    hooks.end_stage(summary(f));
    return f;
  }
};

/// Fits on the corrected coarse disc until the fine/coarse ratios settle; returns the last
/// fit's full record and leaves the ratios in `ratio`.
calibration::WindowFit map_and_fit(const Identification& id, Eigen::VectorXd& p,
                                   Eigen::VectorXd& ratio, DiscIdentificationResult& r) {
  calibration::WindowFit f;
  for (int round = 1; round <= id.options.max_mapping_rounds; ++round) {
    f = id.fit(ratio, p, "fit " + std::to_string(round) + " (coarse disc, corrected)");
    p = f.parameters;
    id.hooks.begin_stage("fine disc at fit " + std::to_string(round));
    MappingRound m;
    m.parameters = p;
    m.coarse = f.quantities.cwiseQuotient(ratio);
    m.fine = id.fine(p);
    m.ratio = m.fine.cwiseQuotient(m.coarse);
    m.ipopt_iterations = f.iterations;
    m.ipopt_status = f.status;
    const double moved = (m.ratio.cwiseQuotient(ratio).array() - 1.0).abs().maxCoeff();
    id.hooks.end_stage("ratios moved " + significant(100 * moved, 2) + " %");
    r.rounds.push_back(m);
    if (!m.ratio.allFinite()) {
      r.status = "the fine disc did not converge at fit " + std::to_string(round);
      return f;
    }
    ratio = m.ratio;
    if (!f.success) {
      r.status = "Ipopt: " + f.status;
      return f;
    }
    if (moved < id.options.mapping_tolerance) {
      r.success = true;
      r.status = "converged in " + std::to_string(round) + (round == 1 ? " round" : " rounds");
      return f;
    }
  }
  r.status = "the fine/coarse ratios had not settled after " +
             std::to_string(id.options.max_mapping_rounds) + " rounds";
  return f;
}

/// Each row's prediction by the fit to the others, evaluated on the fine disc.
void leave_one_out(const Identification& id, const Eigen::VectorXd& p, const Eigen::VectorXd& ratio,
                   DiscIdentificationResult& r) {
  const std::vector<calibration::WindowFit> fits = calibration::leave_one_out(
      id.corrected(ratio), fit_parameters(id.parameters, p), windows(id.rows),
      std::vector<bool>(id.rows.size(), true), id.fit_options(),
      [&](int i) { id.hooks.begin_stage("fit without " + id.rows[std::size_t(i)].quantity); },
      [&](int, const calibration::WindowFit& f) { id.hooks.end_stage(id.summary(f)); });
  std::vector<std::size_t> rows;
  for (std::size_t i = 0; i < fits.size(); ++i)
    if (fits[i].parameters.size())
      rows.push_back(i), r.loo_parameters.push_back(fits[i].parameters);
  if (rows.empty()) return;  // one target: nothing to predict it from
  id.hooks.begin_stage("fine disc at the " + std::to_string(rows.size()) + " leave-one-out fits");
  const std::vector<Eigen::VectorXd> q = map_points(id.fine, r.loo_parameters, id.options.threads);
  for (std::size_t k = 0; k < rows.size(); ++k)
    r.fit_rows[rows[k]].loo_prediction = q[k](Eigen::Index(rows[k]));
  id.hooks.end_stage();
}

}  // namespace

DiscIdentificationResult identify_disc_material(
    const mesh::TetMesh& coarse, const mesh::TetMesh& fine, const mesh::RegionMaterials& base,
    const nlohmann::json& targets, const nlohmann::json& held_out,
    const DiscIdentificationOptions& options, const std::string& coarse_label,
    const std::string& fine_label, const StageHooks& hooks) {
  validate(options);
  const Timer timer;
  DiscIdentificationResult r;
  r.material_name = base.name;
  r.coarse_label = coarse_label;
  r.fine_label = fine_label;
  r.parameters = disc_parameters(base);
  std::atomic<int> coarse_n{0}, fine_n{0};
  std::atomic<long> coarse_us{0}, fine_us{0};
  std::vector<IdentifiedRow> rows = rows_of(targets);
  if (rows.empty()) throw std::invalid_argument("disc identification: no target (empty data set)");
  const std::vector<IdentifiedRow> held = rows_of(held_out);
  check_quantities(held);
  std::vector<std::string> names = check_quantities(rows);
  NonlinearDiscOptions co, fo;
  co.order = options.coarse_order, fo.order = options.fine_order;
  co.load_increments = fo.load_increments = options.load_increments;
  const Identification id{{&coarse, &base, names, co, &coarse_n, &coarse_us},
                          {&fine, &base, names, fo, &fine_n, &fine_us},
                          rows,
                          r.parameters,
                          options,
                          hooks};

  // The preset on both discs: the first fine/coarse ratios.
  Eigen::VectorXd p(Eigen::Index(r.parameters.size()));
  for (std::size_t j = 0; j < r.parameters.size(); ++j)
    p(Eigen::Index(j)) = r.parameters[j].fit.start;
  hooks.begin_stage("the preset on the coarse and the fine disc");
  Eigen::VectorXd preset_coarse, preset_fine;
  parallel_for(2, options.threads, [&](std::size_t k) {
    if (k == 0)
      preset_coarse = id.coarse(p);
    else
      preset_fine = id.fine(p);
  });
  hooks.end_stage();
  Eigen::VectorXd ratio = preset_fine.cwiseQuotient(preset_coarse);
  if (!ratio.allFinite())
    throw std::runtime_error("disc identification: the preset's disc does not converge");

  const calibration::WindowFit f = map_and_fit(id, p, ratio, r);
  r.identified = p;
  r.active_bounds = f.active_bounds;
  r.fit_rows = rows;
  const Eigen::VectorXd& q = r.rounds.back().fine;
  for (std::size_t i = 0; i < rows.size(); ++i) {
    r.fit_rows[i].preset = preset_fine(Eigen::Index(i));
    r.fit_rows[i].ours = q(Eigen::Index(i));
  }
  if (r.success && options.leave_one_out) leave_one_out(id, p, ratio, r);

  // The held-out rows: the identified disc's value of the same quantity.
  for (IdentifiedRow row : held) {
    for (std::size_t i = 0; i < rows.size(); ++i)
      if (rows[i].quantity == row.quantity)
        row.preset = preset_fine(Eigen::Index(i)), row.ours = q(Eigen::Index(i));
    r.held_out_rows.push_back(row);
  }
  r.coarse_evaluations = coarse_n;
  r.fine_evaluations = fine_n;
  r.coarse_seconds_each = coarse_n ? 1e-6 * double(coarse_us) / coarse_n : 0;
  r.fine_seconds_each = fine_n ? 1e-6 * double(fine_us) / fine_n : 0;
  r.seconds = timer.seconds();
  return r;
}

nlohmann::json identified_material_json(const DiscIdentificationResult& r,
                                        const mesh::RegionMaterials& base) {
  // Six significant digits: exp(ln p) leaves rounding in the last places (100.00000000000004).
  Eigen::VectorXd p = r.identified;
  for (Eigen::Index j = 0; j < p.size(); ++j) p(j) = std::stod(significant(p(j), 6));
  const mesh::RegionMaterials m = disc_material_at(base, p, "disc-identified");
  const mesh::IsotropicMaterial& a = m.at(kAnnulus);
  const mesh::IsotropicMaterial& n = m.at(kNucleus);
  const mesh::FibreReinforcement& f = m.fibres.at(kAnnulus);
  std::string bounds;
  for (const DiscParameter& d : r.parameters) bounds += d.fit.name + ": " + d.source + ". ";
  return {
      {"name", "disc-identified"},
      {"source",
       "The nonlinear disc's annulus matrix E, fibre moduli, fibre toe exponent k2 and nucleus E "
       "identified by `spinesim study disc-identify` from the in-vitro disc tests of "
       "data/validation/disc_in_vitro.json (L4-L5, " +
           r.fine_label + "), starting from the '" + r.material_name +
           "' preset, whose other values (Poisson ratios, densities, fibre angles) it keeps. "
           "Bounds: " +
           bounds + "Status: " + r.status + "."},
      {"annulus",
       {{"E_mpa", a.youngs_modulus_mpa},
        {"nu", a.poisson_ratio},
        {"density_kg_m3", a.density_kg_m3},
        {"source", "identified; Poisson ratio and density as the starting preset"},
        {"fibres",
         {{"E_inner_mpa", f.modulus_inner_mpa},
          {"E_outer_mpa", f.modulus_outer_mpa},
          {"angle_inner_deg", f.angle_inner_deg},
          {"angle_outer_deg", f.angle_outer_deg},
          {"k2", f.toe_k2},
          {"source", "moduli and k2 identified; the starting preset's fibres: " + f.source}}}}},
      {"nucleus",
       {{"E_mpa", n.youngs_modulus_mpa},
        {"nu", n.poisson_ratio},
        {"density_kg_m3", n.density_kg_m3},
        {"source", "identified; Poisson ratio and density as the starting preset"}}}};
}

namespace {

/// A number, or null for NaN (JSON has no NaN).
nlohmann::json json_number(double v) { return std::isfinite(v) ? nlohmann::json(v) : nullptr; }

nlohmann::json vector_json(const Eigen::VectorXd& v) {
  nlohmann::json a = nlohmann::json::array();
  for (Eigen::Index i = 0; i < v.size(); ++i) a.push_back(json_number(v(i)));
  return a;
}

nlohmann::json rows_json(const std::vector<IdentifiedRow>& rows) {
  nlohmann::json out = nlohmann::json::array();
  for (const IdentifiedRow& row : rows)
    out.push_back({{"quantity", row.quantity},
                   {"units", row.units},
                   {"low", row.low},
                   {"high", row.high},
                   {"preset", json_number(row.preset)},
                   {"identified", json_number(row.ours)},
                   {"leave_one_out", json_number(row.loo_prediction)},
                   {"match", row.match()},
                   {"reported", row.reported},
                   {"preparation", row.preparation},
                   {"source", row.source}});
  return out;
}

}  // namespace

nlohmann::json disc_identification_json(const DiscIdentificationResult& r) {
  nlohmann::json params = nlohmann::json::array();
  for (std::size_t j = 0; j < r.parameters.size(); ++j) {
    const calibration::FitParameter& f = r.parameters[j].fit;
    nlohmann::json loo = nlohmann::json::array();
    for (const Eigen::VectorXd& p : r.loo_parameters) loo.push_back(p(Eigen::Index(j)));
    params.push_back({{"name", f.name},
                      {"units", f.units},
                      {"start", f.start},
                      {"lower", f.lower},
                      {"upper", f.upper},
                      {"identified", r.identified(Eigen::Index(j))},
                      {"leave_one_out", loo},
                      {"bounds_source", r.parameters[j].source}});
  }
  nlohmann::json rounds = nlohmann::json::array();
  for (const MappingRound& m : r.rounds)
    rounds.push_back({{"parameters", vector_json(m.parameters)},
                      {"coarse", vector_json(m.coarse)},
                      {"fine", vector_json(m.fine)},
                      {"fine_over_coarse", vector_json(m.ratio)},
                      {"ipopt_iterations", m.ipopt_iterations},
                      {"ipopt_status", m.ipopt_status}});
  return {{"material", r.material_name},
          {"coarse_disc", r.coarse_label},
          {"fine_disc", r.fine_label},
          {"success", r.success},
          {"status", r.status},
          {"parameters", params},
          {"active_bounds", r.active_bounds},
          {"targets", rows_json(r.fit_rows)},
          {"held_out", rows_json(r.held_out_rows)},
          {"mapping_rounds", rounds},
          {"cost",
           {{"seconds", r.seconds},
            {"coarse_evaluations", r.coarse_evaluations},
            {"coarse_seconds_each", r.coarse_seconds_each},
            {"fine_evaluations", r.fine_evaluations},
            {"fine_seconds_each", r.fine_seconds_each}}}};
}

void print_disc_identification(std::ostream& os, const DiscIdentificationResult& r, bool markdown) {
  os << "Disc material identified from in-vitro tests: start '" << r.material_name << "'\n"
     << "  fitted on " << r.coarse_label << ", corrected to and reported on " << r.fine_label
     << "\n  " << (r.success ? "" : "NOT FINISHED: ") << r.status << "\n\n";
  TextTable params({"parameter", "units", "start", "lower", "upper", "identified", "bound"}, 2);
  for (std::size_t j = 0; j < r.parameters.size(); ++j) {
    const calibration::FitParameter& f = r.parameters[j].fit;
    std::string active;
    for (const std::string& a : r.active_bounds)
      if (a.rfind(f.name + " at ", 0) == 0) active = a.substr(f.name.size() + 4, 5);
    params.add({f.name, f.units, significant(f.start, 3), significant(f.lower, 3),
                significant(f.upper, 3), significant(r.identified(Eigen::Index(j)), 3),
                active.empty() ? "-" : active + " (active)"});
  }
  params.print(os, markdown);
  os << "\n";
  TextTable fit({"quantity", "units", "preset", "identified", "window", "verdict", "leave-one-out",
                 "verdict", "tested as"},
                2);
  const auto verdict = [](double v, const IdentifiedRow& row) {
    return !std::isfinite(v) ? std::string("n/a")
                             : (v >= row.low && v <= row.high ? "MATCH" : "MISS");
  };
  for (const IdentifiedRow& row : r.fit_rows)
    fit.add({row.quantity, row.units, significant(row.preset, 3), significant(row.ours, 3),
             significant(row.low, 3) + " - " + significant(row.high, 3), verdict(row.ours, row),
             significant(row.loo_prediction, 3), verdict(row.loo_prediction, row),
             row.preparation});
  fit.print(os, markdown);
  if (!r.held_out_rows.empty()) {
    os << "\n  Held out (other laboratories; predicted, not fitted):\n";
    TextTable held({"quantity", "units", "identified", "window", "verdict", "source"}, 2);
    for (const IdentifiedRow& row : r.held_out_rows)
      held.add({row.quantity, row.units, significant(row.ours, 3),
                significant(row.low, 3) + " - " + significant(row.high, 3), verdict(row.ours, row),
                row.source});
    held.print(os, markdown);
  }
  os << "\n  Cost: " << significant(r.seconds, 3) << " s; " << r.coarse_evaluations
     << " coarse disc solves (" << significant(r.coarse_seconds_each, 3) << " s each), "
     << r.fine_evaluations << " fine (" << significant(r.fine_seconds_each, 3) << " s each), "
     << r.rounds.size() << " mapping rounds\n";
}

}  // namespace spinesim::studies

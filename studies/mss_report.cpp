#include "mss_report.hpp"

#include "cli_common.hpp"
#include "fem_report.hpp"

#include "spinesim/calibration/tuned_disc.hpp"
#include "spinesim/mss/elements.hpp"

#include <Eigen/SparseCholesky>

#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <sstream>
#include <stdexcept>

namespace spinesim::cli {
namespace fs = std::filesystem;

namespace {

using RowMatrixX3 = Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor>;
using Row6 = Eigen::Matrix<double, 1, 6>;

bool is_superior(const mesh::TetMesh& m, Eigen::Index i) { return m.surface(i) == int(mesh::Surface::superior_endplate); }
bool is_inferior(const mesh::TetMesh& m, Eigen::Index i) { return m.surface(i) == int(mesh::Surface::inferior_endplate); }

/// Row `a` of the rigid-plate map of node X: u = t + theta x (X - c) = [I, -[X - c]x] (t, theta).
Row6 plate_map_row(const Eigen::Vector3d& X, const Eigen::Vector3d& c, int a) {
  const Eigen::Vector3d r = X - c;
  Eigen::Matrix3d skew;
  skew << 0, -r.z(), r.y(), r.z(), 0, -r.x(), -r.y(), r.x(), 0;
  Row6 row = Row6::Zero();
  row(a) = 1.0;
  row.tail<3>() = -skew.row(a);
  return row;
}

/// RMS over the superior-plate nodes of the rigid displacement t + theta x (X_i - c).
double plate_rms(const mesh::TetMesh& m, const Eigen::Vector3d& c, const fem::Vector6d& q) {
  double sum = 0;
  Eigen::Index n = 0;
  for (Eigen::Index i = 0; i < m.num_vertices(); ++i)
    if (is_superior(m, i)) {
      const Eigen::Vector3d r = m.V.row(i).transpose() - c;
      sum += (q.head<3>() + q.tail<3>().cross(r)).squaredNorm();
      ++n;
    }
  return n ? std::sqrt(sum / double(n)) : 0.0;
}

double plate_rms_radius(const mesh::TetMesh& m, const Eigen::Vector3d& c) {
  double sum = 0;
  Eigen::Index n = 0;
  for (Eigen::Index i = 0; i < m.num_vertices(); ++i)
    if (is_superior(m, i)) {
      sum += (m.V.row(i).transpose() - c).squaredNorm();
      ++n;
    }
  return n ? std::sqrt(sum / double(n)) : 1.0;
}

/// `s` right-aligned (or left) in `width` columns, counting UTF-8 code points (· is one column).
std::string pad(const std::string& s, int width, bool left = false) {
  int cols = 0;
  for (unsigned char ch : s) cols += (ch & 0xC0) != 0x80;
  const std::string fill(std::size_t(std::max(0, width - cols)), ' ');
  return left ? s + fill : fill + s;
}

double safe_ratio(double num, double den) { return den > 0 ? num / den : (num > 0 ? INFINITY : 0.0); }

}  // namespace

// --- model options ---------------------------------------------------------------------------

void add_model_flags(CLI::App* cmd, ModelFlags& f) {
  cmd->add_flag("--no-radial", f.no_radial, "Without the radial springs (thesis 5.3-5.5)");
  cmd->add_flag("--no-torsion", f.no_torsion, "Without the torsional angle springs (thesis 5.6-5.8)");
  cmd->add_flag("--volume-term", f.volume_term, "Add the per-tetrahedron volume penalty (beyond the thesis)");
  cmd->add_flag("--disc-volume-term", f.disc_volume_term, "Add the whole-disc volume penalty (beyond the thesis)");
  cmd->add_option("--volume-factor", f.volume_factor, "c_v of the per-tetrahedron term, k_v = c_v K / V0_t")
      ->capture_default_str();
  cmd->add_option("--disc-volume-factor", f.disc_volume_factor, "c_g of the whole-disc term, k_g = c_g K / V0")
      ->capture_default_str();
  f.damping_option = cmd->add_option("--damping", f.damping_n_s_per_mm,
                                     "Ambient damping K_d per node, N·s/mm (default: critical for the first axial mode)");
}

mss::MssOptions model_options(const ModelFlags& f) {
  mss::MssOptions o;
  o.radial_springs = !f.no_radial;
  o.torsion_springs = !f.no_torsion;
  o.volume_term = f.volume_term;
  o.disc_volume_term = f.disc_volume_term;
  if (!std::isfinite(f.volume_factor) || f.volume_factor <= 0 || !std::isfinite(f.disc_volume_factor) ||
      f.disc_volume_factor <= 0)
    throw std::invalid_argument("--volume-factor and --disc-volume-factor must be finite numbers > 0");
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

mss::Integrator parse_integrator(const std::string& name) {
  if (name == "implicit") return mss::Integrator::implicit_euler;
  if (name == "symplectic") return mss::Integrator::symplectic_euler;
  if (name == "explicit") return mss::Integrator::explicit_euler;
  throw std::invalid_argument("unknown --integrator '" + name + "' (implicit, symplectic, explicit)");
}

// --- stepping ---------------------------------------------------------------------------------

bool StepStats::step(mss::Simulator& sim, mss::State& s, const mss::Boundary& bc) {
  const auto t0 = std::chrono::steady_clock::now();
  const mss::StepReport rep = sim.step(s, bc);
  const double dt = seconds_since(t0);
  if (!rep.ok) {
    diverged = true;
    message = rep.message;
    std::replace(message.begin(), message.end(), '\n', ' ');
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

// --- results of one MSS state ----------------------------------------------------------------

Eigen::MatrixX3d mss_displacement(const mss::MssModel& model, const Eigen::VectorXd& x_mm) {
  const Eigen::Index n = model.num_nodes();
  const Eigen::VectorXd u = x_mm - model.rest_positions_mm();
  return Eigen::Map<const RowMatrixX3>(u.data(), n, 3);
}

MssFields mss_fields(const mss::MssModel& model, const Eigen::VectorXd& x_mm) {
  const mesh::TetMesh& m = model.mesh();
  const Eigen::VectorXd& X = model.rest_positions_mm();
  Eigen::MatrixXd dv(m.num_tets(), 1);
  for (Eigen::Index t = 0; t < m.num_tets(); ++t) {
    mss::TetPoints x, x0;
    for (int k = 0; k < 4; ++k) {
      x.col(k) = x_mm.segment<3>(3 * m.T(t, k));
      x0.col(k) = X.segment<3>(3 * m.T(t, k));
    }
    const double v0 = mss::tet_signed_volume(x0);
    dv(t, 0) = (mss::tet_signed_volume(x) - v0) / v0;
  }
  MssFields f;
  f.point.push_back({"displacement", mss_displacement(model, x_mm)});
  f.cell.push_back({"volume_change", dv});
  return f;
}

double volume_change(const mss::MssModel& model, const Eigen::VectorXd& x_mm) {
  const double v0 = model.rest_volume_mm3();
  return (model.volume_mm3(x_mm) - v0) / v0;
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
             {{"annulus", g_annulus * cyl.k_t_per_shear_modulus}, {"nucleus", g_nucleus * cyl.k_t_per_shear_modulus}}}}},
          {"options", [&o] {
             nlohmann::json j = calibration::terms_json(o);
             j["damping_ratio"] = o.damping_ratio;
             return j;
           }()}};
}

fem::Matrix6d mss_plate_stiffness(const mss::MssModel& model, const Eigen::Vector3d& center_mm) {
  const mesh::TetMesh& m = model.mesh();
  const Eigen::VectorXd& X = model.rest_positions_mm();
  Eigen::SparseMatrix<double> H;
  model.hessian(X, mss::HessianMode::exact, H);

  // 1. Classify the DOF: free (numbered), plate (rigid map rows), fixed (dropped).
  const Eigen::Index ndof = model.num_dofs();
  std::vector<Eigen::Index> free_index(std::size_t(ndof), -1);
  Eigen::Matrix<double, Eigen::Dynamic, 6> map(ndof, 6);
  map.setZero();
  Eigen::Index nf = 0;
  for (Eigen::Index i = 0; i < m.num_vertices(); ++i)
    for (int a = 0; a < 3; ++a) {
      if (is_superior(m, i))
        map.row(3 * i + a) = plate_map_row(X.segment<3>(3 * i), center_mm, a);
      else if (!is_inferior(m, i))
        free_index[std::size_t(3 * i + a)] = nf++;
    }

  // 2. Blocks K_ff, B = K_fp T and T'K_pp T from the Hessian's entries.
  std::vector<Eigen::Triplet<double>> kff;
  Eigen::MatrixXd b = Eigen::MatrixXd::Zero(nf, 6);
  fem::Matrix6d kpp = fem::Matrix6d::Zero();
  for (Eigen::Index col = 0; col < H.outerSize(); ++col) {
    const bool col_plate = is_superior(m, col / 3);
    const Eigen::Index fc = free_index[std::size_t(col)];
    for (Eigen::SparseMatrix<double>::InnerIterator it(H, col); it; ++it) {
      const Eigen::Index row = it.row();
      const Eigen::Index fr = free_index[std::size_t(row)];
      const bool row_plate = is_superior(m, row / 3);
      if (fr >= 0 && fc >= 0)
        kff.emplace_back(fr, fc, it.value());
      else if (fr >= 0 && col_plate)
        b.row(fr) += it.value() * map.row(col);
      else if (row_plate && col_plate)
        kpp += map.row(row).transpose() * it.value() * map.row(col);
    }
  }
  Eigen::SparseMatrix<double> k(nf, nf);
  k.setFromTriplets(kff.begin(), kff.end());

  // 3. The whole-disc volume term's dense rank-one part k_g u u^T (model.hpp), split like the
  //    blocks: free part u_f, plate part T'u_p.
  Eigen::VectorXd u;
  const double kg = model.disc_volume_rank_one(X, u);
  Eigen::VectorXd u_f = Eigen::VectorXd::Zero(nf);
  fem::Vector6d u_p = fem::Vector6d::Zero();
  if (kg != 0.0)
    for (Eigen::Index dof = 0; dof < ndof; ++dof) {
      if (free_index[std::size_t(dof)] >= 0) u_f(free_index[std::size_t(dof)]) = u(dof);
      else if (is_superior(m, dof / 3)) u_p += u(dof) * map.row(dof).transpose();
    }
  b += kg * u_f * u_p.transpose();
  kpp += kg * u_p * u_p.transpose();

  // 4. Condense: K_ff + k_g u_f u_f' inverted by Sherman–Morrison on the sparse factor.
  Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> ldlt(k);
  if (ldlt.info() != Eigen::Success)
    throw std::runtime_error("MSS plate stiffness: the free-node stiffness does not factorise");
  Eigen::MatrixXd z = ldlt.solve(b);
  if (kg != 0.0) {
    const Eigen::VectorXd a_u = ldlt.solve(u_f);
    z -= a_u * (kg * (u_f.transpose() * z)) / (1.0 + kg * u_f.dot(a_u));
  }
  fem::Matrix6d k6 = kpp - b.transpose() * z;
  k6 = 0.5 * (k6 + k6.transpose()).eval();
  if (!k6.allFinite()) throw std::runtime_error("MSS plate stiffness: non-finite result");
  return k6;
}

// --- MSS vs FEM --------------------------------------------------------------------------------

MssFemComparison compare_mss_fem(const fem::DiscFem& fem, const mss::MssModel& model,
                                 const std::vector<fem::LoadCase>& cases, const std::string& material_name,
                                 const mss::StaticOptions& options, double load_scale) {
  if (!std::isfinite(load_scale) || load_scale <= 0)
    throw std::invalid_argument("the load scale must be a finite number > 0");
  using clock = std::chrono::steady_clock;
  const mesh::TetMesh& m = model.mesh();
  const Eigen::Vector3d c = fem.plate_center();
  MssFemComparison out;
  out.material = material_name;
  out.load_scale = load_scale;
  out.fem_order = fem.order();
  out.nodes = m.num_vertices();
  out.tets = m.num_tets();
  out.plate_rms_radius_mm = plate_rms_radius(m, c);
  const double rho = out.plate_rms_radius_mm;

  for (const fem::LoadCase& lc : cases) {
    CaseComparison r;
    r.name = lc.name;
    r.wrench = load_scale * fem::global_wrench(lc, m.frame);

    auto t0 = clock::now();
    const fem::PlateSolution f = fem.solve_wrench(r.wrench);
    out.fem_seconds += seconds_since(t0);
    r.plate_motion_fem = f.plate_motion;
    r.reaction_fem = f.reaction_wrench;
    r.max_displacement_fem_mm = f.displacement_mm.rowwise().norm().maxCoeff();

    // (a) wrench-loaded.
    t0 = clock::now();
    mss::Boundary bw;
    bw.plate_mode = mss::PlateMode::wrench;
    bw.wrench = r.wrench;
    bw.plate_center_mm = c;
    const mss::StaticResult sw = mss::solve_static(model, bw, options);
    const Eigen::MatrixX3d u = mss_displacement(model, sw.x_mm);
    r.plate_motion_mss = sw.plate_motion;
    r.displacement_error = safe_ratio((u - f.displacement_mm).norm(), f.displacement_mm.norm());
    r.plate_motion_error =
        safe_ratio(plate_rms(m, c, r.plate_motion_mss - r.plate_motion_fem), plate_rms(m, c, r.plate_motion_fem));
    r.max_displacement_mss_mm = u.rowwise().norm().maxCoeff();
    r.inverted_tets = model.inverted_tets(sw.x_mm);

    // (b) motion-loaded with the FEM's plate motion.
    mss::Boundary bm;
    bm.superior = mss::plate_pose(f.plate_motion, c);
    bm.plate_center_mm = c;
    const mss::StaticResult sm = mss::solve_static(model, bm, options);
    out.mss_seconds += seconds_since(t0);
    r.reaction_mss = sm.reaction_wrench;
    const auto scaled = [rho](const fem::Vector6d& w) {
      fem::Vector6d s = w;
      s.tail<3>() /= rho;
      return s;
    };
    const fem::Vector6d d = scaled(r.reaction_mss - r.reaction_fem);
    const double size = scaled(r.reaction_fem).norm();
    r.reaction_error = safe_ratio(d.norm(), size);
    r.reaction_force_error = safe_ratio(d.head<3>().norm(), size);
    r.reaction_moment_error = safe_ratio(d.tail<3>().norm(), size);

    r.converged = sw.converged && sm.converged;
    r.iterations = sw.iterations + sm.iterations;
    if (!sw.converged) r.message = "wrench solve: " + sw.message;
    if (!sm.converged) r.message += (r.message.empty() ? "" : "; ") + std::string("motion solve: ") + sm.message;
    out.cases.push_back(r);
  }

  const auto t0 = clock::now();
  out.k6_fem = fem.stiffness_6x6();
  out.k6_mss = mss_plate_stiffness(model, c);
  out.stiffness_seconds = seconds_since(t0);
  return out;
}

nlohmann::json comparison_json(const MssFemComparison& c) {
  nlohmann::json cases = nlohmann::json::array();
  double sum_u = 0, sum_r = 0;
  for (const CaseComparison& r : c.cases) {
    nlohmann::json j = {{"name", r.name},
                        {"wrench", to_json(Eigen::VectorXd(r.wrench))},
                        {"displacement_error", r.displacement_error},
                        {"plate_motion_error", r.plate_motion_error},
                        {"inverted_tets", r.inverted_tets},
                        {"plate_motion_fem", to_json(Eigen::VectorXd(motion_rad_to_deg(r.plate_motion_fem)))},
                        {"plate_motion_mss", to_json(Eigen::VectorXd(motion_rad_to_deg(r.plate_motion_mss)))},
                        {"reaction_error", r.reaction_error},
                        {"reaction_force_error", r.reaction_force_error},
                        {"reaction_moment_error", r.reaction_moment_error},
                        {"reaction_wrench_fem", to_json(Eigen::VectorXd(r.reaction_fem))},
                        {"reaction_wrench_mss", to_json(Eigen::VectorXd(r.reaction_mss))},
                        {"max_displacement_fem_mm", r.max_displacement_fem_mm},
                        {"max_displacement_mss_mm", r.max_displacement_mss_mm},
                        {"converged", r.converged},
                        {"newton_iterations", r.iterations}};
    if (!r.message.empty()) j["message"] = r.message;
    cases.push_back(j);
    sum_u += r.displacement_error;
    sum_r += r.reaction_error;
  }
  const double n = c.cases.empty() ? 1.0 : double(c.cases.size());
  const fem::Vector6d kf = stiffness_per_degree(c.k6_fem).diagonal();
  const fem::Vector6d km = stiffness_per_degree(c.k6_mss).diagonal();
  return {{"material", c.material},
          {"fem_order", c.fem_order},
          {"nodes", c.nodes},
          {"tets", c.tets},
          {"mss_constants", c.constants},
          {"load_scale", c.load_scale},
          {"plate_rms_radius_mm", c.plate_rms_radius_mm},
          {"units",
           {{"wrench", "Fx,Fy,Fz [N], Mx,My,Mz [N·mm], global frame"},
            {"plate_motion", "tx,ty,tz [mm], rx,ry,rz [deg]"},
            {"errors", "relative (dimensionless); see `spinesim mss compare --help`"}}},
          {"cases", cases},
          {"mean_displacement_error", sum_u / n},
          {"mean_reaction_error", sum_r / n},
          {"stiffness_diagonal",
           {{"fem", to_json(Eigen::VectorXd(kf))},
            {"mss", to_json(Eigen::VectorXd(km))},
            {"ratio_mss_over_fem", to_json(Eigen::VectorXd(km.cwiseQuotient(kf)))},
            {"units", "tx,ty,tz [N/mm], rx,ry,rz [N·mm/deg]"}}},
          {"timings", {{"fem_solves_s", c.fem_seconds}, {"mss_static_s", c.mss_seconds}, {"stiffness_s", c.stiffness_seconds}}}};
}

void print_comparison(std::ostream& os, const MssFemComparison& c, bool markdown) {
  const auto flags = os.flags();
  const auto prec = os.precision();
  os << std::setprecision(3) << std::fixed;
  const auto pct = [](double e) {
    std::ostringstream s;
    s << std::fixed << std::setprecision(1) << 100.0 * e << " %";
    return s.str();
  };
  static const char* head[] = {"case", "displacement error", "plate-motion error", "reaction error",
                               "force part", "moment part", "max |u| FEM (mm)", "max |u| MSS (mm)"};
  if (markdown) {
    os << "|";
    for (const char* h : head) {
      os << " ";
      for (const char* ch = h; *ch; ++ch) os << (*ch == '|' ? "\\|" : std::string(1, *ch));  // | would end the cell
      os << " |";
    }
    os << "\n|---|---|---|---|---|---|---|---|\n";
  } else {
    os << pad(head[0], 16, true);
    for (int i = 1; i < 8; ++i) os << pad(head[i], 20);
    os << "\n";
  }
  for (const CaseComparison& r : c.cases) {
    const std::string cells[] = {r.name + (r.converged ? "" : " (not converged)") +
                                     (r.inverted_tets > 0 ? " (" + std::to_string(r.inverted_tets) + " tets inverted)" : ""),
                                 pct(r.displacement_error),
                                 pct(r.plate_motion_error),
                                 pct(r.reaction_error),
                                 pct(r.reaction_force_error),
                                 pct(r.reaction_moment_error),
                                 [&] { std::ostringstream s; s << std::fixed << std::setprecision(3) << r.max_displacement_fem_mm; return s.str(); }(),
                                 [&] { std::ostringstream s; s << std::fixed << std::setprecision(3) << r.max_displacement_mss_mm; return s.str(); }()};
    if (markdown) {
      os << "|";
      for (const auto& cell : cells) os << " " << cell << " |";
      os << "\n";
    } else {
      os << pad(cells[0], 16, true);
      for (int i = 1; i < 8; ++i) os << pad(cells[i], 20);
      os << "\n";
    }
  }
  const fem::Vector6d kf = stiffness_per_degree(c.k6_fem).diagonal();
  const fem::Vector6d km = stiffness_per_degree(c.k6_mss).diagonal();
  static const char* dof[] = {"tx [N/mm]", "ty [N/mm]", "tz [N/mm]", "rx [N·mm/deg]", "ry [N·mm/deg]", "rz [N·mm/deg]"};
  os << "\n" << (markdown ? "" : "  ") << "6x6 plate stiffness diagonal (global frame), MSS (rest, condensed) vs FEM P"
     << c.fem_order << ":\n\n";
  if (markdown)
    os << "| DOF | FEM | MSS | MSS / FEM |\n|---|---|---|---|\n";
  else
    os << "  " << pad("DOF", 16, true) << pad("FEM", 14) << pad("MSS", 14) << pad("MSS/FEM", 10) << "\n";
  for (int i = 0; i < 6; ++i) {
    std::ostringstream f, s;
    f << std::defaultfloat << std::setprecision(4) << kf(i);
    s << std::defaultfloat << std::setprecision(4) << km(i);
    if (markdown)
      os << "| " << dof[i] << " | " << f.str() << " | " << s.str() << " | " << km(i) / kf(i) << " |\n";
    else
      os << "  " << pad(dof[i], 16, true) << pad(f.str(), 14) << pad(s.str(), 14) << std::setw(10) << km(i) / kf(i)
         << "\n";
  }
  os.flags(flags);
  os.precision(prec);
}

std::string comparison_csv(const MssFemComparison& c) {
  std::ostringstream os;
  os << std::setprecision(17);
  os << "case,displacement_error,plate_motion_error,reaction_error,reaction_force_error,reaction_moment_error,"
        "converged";
  for (const char* who : {"fem", "mss"})
    for (const char* comp : {"Fx_N", "Fy_N", "Fz_N", "Mx_Nmm", "My_Nmm", "Mz_Nmm"}) os << ",reaction_" << who << "_" << comp;
  os << "\n";
  for (const CaseComparison& r : c.cases) {
    os << r.name << "," << r.displacement_error << "," << r.plate_motion_error << "," << r.reaction_error << ","
       << r.reaction_force_error << "," << r.reaction_moment_error << "," << (r.converged ? 1 : 0);
    for (int i = 0; i < 6; ++i) os << "," << r.reaction_fem(i);
    for (int i = 0; i < 6; ++i) os << "," << r.reaction_mss(i);
    os << "\n";
  }
  return os.str();
}

// --- files -----------------------------------------------------------------------------------

void write_text_file(const std::string& path, const std::string& text) {
  std::string tmpl = path + ".tmp-XXXXXX";
  std::vector<char> name(tmpl.begin(), tmpl.end());
  name.push_back('\0');
  const int fd = ::mkstemp(name.data());
  if (fd < 0) throw std::runtime_error(path + ": cannot create a file there (" + std::strerror(errno) + ")");
  ::fchmod(fd, 0644);
  ::close(fd);
  const std::string tmp(name.data());
  {
    std::ofstream os(tmp, std::ios::binary | std::ios::trunc);
    os << text;
    os.flush();
    if (!os) {
      std::remove(tmp.c_str());
      throw std::runtime_error(path + ": write failed (disk full?)");
    }
  }
  if (std::rename(tmp.c_str(), path.c_str()) != 0) {
    std::remove(tmp.c_str());
    throw std::runtime_error(path + ": cannot replace the file (" + std::strerror(errno) + ")");
  }
}

void require_output_folder(const std::string& path, const std::string& option) {
  fs::path dir = fs::path(path).parent_path();
  if (dir.empty()) dir = ".";
  if (!fs::is_directory(dir))
    throw std::invalid_argument(option + " " + path + ": folder " + dir.string() + " does not exist");
}

VtuSeries::VtuSeries(const std::string& pvd_path) : pvd_path_(pvd_path) {
  const fs::path p(pvd_path);
  if (p.extension() != ".pvd") throw std::invalid_argument("time series " + pvd_path + ": the name must end in .pvd");
  require_output_folder(pvd_path, "time series");
  stem_ = p.stem().string();
  folder_ = (p.parent_path() / stem_).string();
  fs::create_directories(folder_);
}

void VtuSeries::add(double time_s, const mss::MssModel& model, const Eigen::VectorXd& x_mm) {
  char name[64];
  std::snprintf(name, sizeof name, "_%06zu.vtu", entries_.size());
  const std::string rel = stem_ + "/" + stem_ + name;
  const MssFields f = mss_fields(model, x_mm);
  mesh::write_vtu((fs::path(folder_) / (stem_ + name)).string(), model.mesh(), f.point, f.cell);
  entries_.push_back({time_s, rel});
}

void VtuSeries::finish() { mesh::write_pvd(pvd_path_, entries_); }

void VtuSeries::discard() {
  for (const std::string& f : frame_paths()) fs::remove(f);
  entries_.clear();
  std::error_code ec;
  fs::remove(folder_, ec);  // only if empty
}

std::vector<std::string> VtuSeries::frame_paths() const {
  std::vector<std::string> out;
  const fs::path base = fs::path(pvd_path_).parent_path();
  for (const auto& e : entries_) out.push_back((base / e.file).string());
  return out;
}

}  // namespace spinesim::cli

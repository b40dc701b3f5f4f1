#include "spinesim/calibration/nonlinear_fit.hpp"

#include "spinesim/common/timer.hpp"
#include "spinesim/fem/nonlinear_disc.hpp"
#include "spinesim/mesh/rigid_plate.hpp"
#include "spinesim/mss/boundary.hpp"
#include "spinesim/mss/quantities.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <stdexcept>

namespace spinesim::calibration {

namespace {

/// S = diag(1, 1, 1, 1/ρ, 1/ρ, 1/ρ): moments in N·mm over the plate's RMS radius add to N.
Vector6d scaled(const Vector6d& w, double rho) {
  Vector6d s = w;
  s.tail<3>() /= rho;
  return s;
}

/// Rows of the vertices off both endplates.
std::vector<Eigen::Index> free_vertices(const mesh::TetMesh& m) {
  std::vector<Eigen::Index> out;
  for (Eigen::Index i = 0; i < m.num_vertices(); ++i)
    if (m.surface(i) != 1 && m.surface(i) != 2) out.push_back(i);
  return out;
}

/// Residual block of one case (6 reaction entries, then 3 per free vertex), unweighted.
Eigen::VectorXd case_residual(const mss::MssModel& model, const NonlinearReference& ref,
                              const NonlinearReferenceCase& c, const mss::StaticResult& s,
                              const std::vector<Eigen::Index>& free) {
  const double rho = ref.plate_rms_radius_mm;
  Eigen::VectorXd r(6 + 3 * Eigen::Index(free.size()));
  if (!s.converged) return r.setConstant(std::numeric_limits<double>::quiet_NaN());
  const Vector6d ref_w = scaled(c.reaction, rho);
  r.head<6>() = (scaled(s.reaction_wrench, rho) - ref_w) / ref_w.norm();
  const Eigen::MatrixX3d u = mss::displacement(model, s.x_mm);
  double norm2 = 0;
  for (Eigen::Index i : free) norm2 += c.vertex_displacement_mm.row(i).squaredNorm();
  const double norm = std::sqrt(norm2);
  for (std::size_t k = 0; k < free.size(); ++k) {
    const Eigen::Index i = free[k];
    r.segment<3>(6 + 3 * Eigen::Index(k)) =
        (u.row(i) - c.vertex_displacement_mm.row(i)).transpose() / norm;
  }
  return r;
}

bool named(const std::vector<std::string>& names, const std::string& n) {
  return std::find(names.begin(), names.end(), n) != names.end();
}

void check_request(const mss::MssModel& model, const NonlinearReference& ref,
                   const NonlinearFitRequest& q) {
  if (q.train.empty()) throw std::invalid_argument("nonlinear fit: no training case");
  for (const std::string& name : q.train) {
    const bool known = std::any_of(ref.cases.begin(), ref.cases.end(),
                                   [&](const NonlinearReferenceCase& c) { return c.name == name; });
    if (!known)
      throw std::invalid_argument("nonlinear fit: training case '" + name +
                                  "' is not in the reference");
  }
  for (const NonlinearReferenceCase& c : ref.cases)
    if (c.vertex_displacement_mm.rows() != model.num_nodes())
      throw std::invalid_argument("nonlinear fit: the reference was made on another mesh");
  if (!std::isfinite(q.displacement_weight) || q.displacement_weight < 0)
    throw std::invalid_argument("nonlinear fit: the displacement weight must be finite and >= 0");
  if (!(q.lower_scale > 0) || !(q.lower_scale < 1) || !(q.upper_scale > 1) ||
      !std::isfinite(q.upper_scale))
    throw std::invalid_argument("nonlinear fit: scale bounds 0 < lower < 1 < upper expected");
}

}  // namespace

NonlinearReference nonlinear_reference(const mesh::TetMesh& mesh,
                                       const mesh::RegionMaterials& materials,
                                       const std::vector<fem::LoadCase>& cases,
                                       const std::vector<double>& levels, int fem_order,
                                       const fem::NewtonOptions& newton,
                                       const std::function<void(int, int)>& done) {
  if (cases.empty() || levels.empty())
    throw std::invalid_argument("nonlinear reference: no load case or no level");
  for (double l : levels)
    if (!std::isfinite(l) || !(l > 0))
      throw std::invalid_argument("nonlinear reference: load levels must be finite and > 0");
  const Timer timer;
  NonlinearReference ref;
  ref.fem_order = fem_order;
  ref.plate_center_mm = mss::default_plate_center(mesh);
  ref.plate_rms_radius_mm = mesh::plate_rms_radius(mesh, ref.plate_center_mm);
  const fem::NonlinearDisc disc(
      mesh, fem::disc_element_materials(mesh, materials, fem::material_fibre_k2(materials)),
      fem_order, ref.plate_center_mm);
  const int total = int(cases.size() * levels.size());
  for (const fem::LoadCase& lc : cases)
    for (double level : levels) {
      NonlinearReferenceCase c;
      c.name = lc.name;
      c.level = level;
      c.wrench = level * fem::global_wrench(lc, mesh.frame);
      fem::PlateLoad load;
      load.value = c.wrench;
      const Timer t;
      const fem::NonlinearPlateSolution s = disc.solve(load, newton);
      if (!s.body.converged) {
        std::ostringstream m;
        m << "nonlinear reference: " << lc.name << " at " << level
          << " x the standard load did not converge (" << s.body.failure << ")";
        throw std::runtime_error(m.str());
      }
      c.plate_motion = s.plate_motion;
      c.reaction = s.reaction_wrench;
      c.vertex_displacement_mm = s.body.displacement_mm.topRows(mesh.num_vertices());
      c.newton_iterations = s.body.newton_iterations;
      c.seconds = t.seconds();
      ref.cases.push_back(std::move(c));
      if (done) done(int(ref.cases.size()), total);
    }
  ref.seconds = timer.seconds();
  return ref;
}

mss::StaticResult mss_at_reference_pose(const mss::MssModel& model, const NonlinearReference& ref,
                                        const NonlinearReferenceCase& c,
                                        const mss::StaticOptions& o, PoseStart how) {
  mss::Boundary bc;
  bc.plate_mode = mss::PlateMode::pose;
  bc.plate_center_mm = ref.plate_center_mm;
  mss::StaticResult direct;
  if (how != PoseStart::pose_steps) {
    bc.superior = mss::plate_pose(c.plate_motion, ref.plate_center_mm);
    Eigen::VectorXd start = model.rest_positions_mm();
    for (Eigen::Index i = 0; i < model.num_nodes(); ++i)
      start.segment<3>(3 * i) += c.vertex_displacement_mm.row(i).transpose();
    direct = mss::solve_static(model, bc, o, start);
    // An untuned thoracic network under the full flexion moment (13 degrees) is too far from
    // the FEM's field for Newton: then the pose is reached in steps.
    if (direct.converged || how == PoseStart::fem_field) return direct;
  }
  mss::StaticResult s;
  s.x_mm = model.rest_positions_mm();
  for (int k = 1; k <= kPoseSteps; ++k) {
    bc.superior = mss::plate_pose(c.plate_motion * (double(k) / kPoseSteps), ref.plate_center_mm);
    s = mss::solve_static(model, bc, o, s.x_mm);
    if (!s.converged) {
      s.message = (direct.message.empty() ? "" : "from the FEM's field: " + direct.message + "; ") +
                  "in " + std::to_string(kPoseSteps) + " pose steps, step " + std::to_string(k) +
                  ": " + s.message;
      return s;
    }
  }
  return s;
}

std::vector<NonlinearCaseError> nonlinear_errors(const mss::MssModel& model,
                                                 const NonlinearReference& ref,
                                                 const std::vector<std::string>& train,
                                                 const mss::StaticOptions& options) {
  const std::vector<Eigen::Index> free = free_vertices(model.mesh());
  std::vector<NonlinearCaseError> out;
  for (const NonlinearReferenceCase& c : ref.cases) {
    NonlinearCaseError e;
    e.name = c.name;
    e.level = c.level;
    e.trained = named(train, c.name);
    const mss::StaticResult s = mss_at_reference_pose(model, ref, c, options);
    e.converged = s.converged;
    e.iterations = s.iterations;
    e.message = s.message;
    e.reaction_mss = s.reaction_wrench;
    const Eigen::VectorXd r = case_residual(model, ref, c, s, free);
    e.reaction_error = r.head<6>().norm();
    e.displacement_error = r.tail(r.size() - 6).norm();
    out.push_back(std::move(e));
  }
  return out;
}

NonlinearFitResult fit_mss_nonlinear(const mss::MssModel& model, const NonlinearReference& ref,
                                     const NonlinearFitRequest& request, const Progress& progress) {
  check_request(model, ref, request);
  NonlinearFitResult out;
  out.knobs = available_knobs(model.options());
  const auto start_scales = model.options().scales;
  std::vector<FitParameter> parameters;
  for (const Knob& k : out.knobs) {
    const double s = start_scales[std::size_t(k.term)].by_region[std::size_t(k.region)];
    parameters.push_back({knob_name(k), "", std::clamp(s, request.lower_scale, request.upper_scale),
                          request.lower_scale, request.upper_scale});
  }
  std::vector<const NonlinearReferenceCase*> training;
  for (const NonlinearReferenceCase& c : ref.cases)
    if (named(request.train, c.name)) training.push_back(&c);
  const std::vector<Eigen::Index> free = free_vertices(model.mesh());
  const double weight_u = std::sqrt(request.displacement_weight);
  const double per_case = 1.0 / std::sqrt(double(training.size()));
  auto with_scales = [&](const Eigen::VectorXd& p) {
    mss::MssModel m = model;
    auto scales = start_scales;
    for (std::size_t j = 0; j < out.knobs.size(); ++j)
      scales[std::size_t(out.knobs[j].term)].by_region[std::size_t(out.knobs[j].region)] =
          p(Eigen::Index(j));
    m.set_scales(scales);
    return m;
  };
  const ResidualModel residuals = [&](const Eigen::VectorXd& p) -> Eigen::VectorXd {
    const mss::MssModel m = with_scales(p);
    const Eigen::Index block = 6 + 3 * Eigen::Index(free.size());
    Eigen::VectorXd r(block * Eigen::Index(training.size()));
    for (std::size_t k = 0; k < training.size(); ++k) {
      const NonlinearReferenceCase& c = *training[k];
      Eigen::VectorXd rc =
          case_residual(m, ref, c, mss_at_reference_pose(m, ref, c, request.solver), free);
      rc.tail(rc.size() - 6) *= weight_u;
      r.segment(Eigen::Index(k) * block, block) = per_case * rc;
    }
    return r;
  };
  out.before = nonlinear_errors(model, ref, request.train, request.solver);
  out.fit = fit_least_squares(residuals, parameters, request.fit, progress);
  const mss::MssModel fitted = with_scales(out.fit.parameters);
  out.scales = fitted.options().scales;
  out.after = nonlinear_errors(fitted, ref, request.train, request.solver);
  return out;
}

}  // namespace spinesim::calibration

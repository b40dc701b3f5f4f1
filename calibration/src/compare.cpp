#include "spinesim/calibration/compare.hpp"

#include "spinesim/common/timer.hpp"
#include "spinesim/mesh/rigid_plate.hpp"
#include "spinesim/mss/boundary.hpp"
#include "spinesim/mss/plate_stiffness.hpp"
#include "spinesim/mss/quantities.hpp"

#include <cmath>
#include <stdexcept>

namespace spinesim::calibration {

namespace {
double safe_ratio(double num, double den) {
  return den > 0 ? num / den : (num > 0 ? INFINITY : 0.0);
}
}  // namespace

MssFemComparison compare_mss_fem(const fem::DiscFem& fem, const mss::MssModel& model,
                                 const std::vector<fem::LoadCase>& cases,
                                 const std::string& material_name,
                                 const mss::StaticOptions& options, double load_scale) {
  if (!std::isfinite(load_scale) || load_scale <= 0)
    throw std::invalid_argument("the load scale must be a finite number > 0");
  const mesh::TetMesh& m = model.mesh();
  const Eigen::Vector3d c = fem.plate_center();
  MssFemComparison out;
  out.material = material_name;
  out.load_scale = load_scale;
  out.fem_order = fem.order();
  out.nodes = m.num_vertices();
  out.tets = m.num_tets();
  out.plate_rms_radius_mm = mesh::plate_rms_radius(m, c);
  const double rho = out.plate_rms_radius_mm;

  for (const fem::LoadCase& lc : cases) {
    CaseComparison r;
    r.name = lc.name;
    r.wrench = load_scale * fem::global_wrench(lc, m.frame);

    Timer t0;
    const fem::PlateSolution f = fem.solve_wrench(r.wrench);
    out.fem_seconds += t0.seconds();
    r.plate_motion_fem = f.plate_motion;
    r.reaction_fem = f.reaction_wrench;
    r.max_displacement_fem_mm = f.displacement_mm.rowwise().norm().maxCoeff();

    // (a) wrench-loaded.
    t0.restart();
    mss::Boundary bw;
    bw.plate_mode = mss::PlateMode::wrench;
    bw.wrench = r.wrench;
    bw.plate_center_mm = c;
    const mss::StaticResult sw = mss::solve_static(model, bw, options);
    const Eigen::MatrixX3d u = mss::displacement(model, sw.x_mm);
    r.plate_motion_mss = sw.plate_motion;
    r.displacement_error = safe_ratio((u - f.displacement_mm).norm(), f.displacement_mm.norm());
    r.plate_motion_error =
        safe_ratio(mesh::plate_rms_displacement(m, c, r.plate_motion_mss - r.plate_motion_fem),
                   mesh::plate_rms_displacement(m, c, r.plate_motion_fem));
    r.max_displacement_mss_mm = u.rowwise().norm().maxCoeff();
    r.inverted_tets = model.inverted_tets(sw.x_mm);

    // (b) motion-loaded with the FEM's plate motion.
    mss::Boundary bm;
    bm.superior = mss::plate_pose(f.plate_motion, c);
    bm.plate_center_mm = c;
    const mss::StaticResult sm = mss::solve_static(model, bm, options);
    out.mss_seconds += t0.seconds();
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
    if (!sm.converged)
      r.message += (r.message.empty() ? "" : "; ") + std::string("motion solve: ") + sm.message;
    out.cases.push_back(r);
  }

  Timer t0;
  out.k6_fem = fem.stiffness_6x6();
  out.k6_mss = mss::plate_stiffness(model, c);
  out.stiffness_seconds = t0.seconds();
  return out;
}

}  // namespace spinesim::calibration

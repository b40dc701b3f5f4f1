#include "spinesim/fem/nonlinear_disc.hpp"

#include "spinesim/common/rotation.hpp"
#include "spinesim/fem/fe_space.hpp"
#include "spinesim/fem/fibres.hpp"

#include "plate_newton.hpp"

#include <Eigen/Geometry>

#include <stdexcept>
#include <utility>

namespace spinesim::fem {

double material_fibre_k2(const mesh::RegionMaterials& materials) {
  return materials.has_fibres() ? materials.fibres.begin()->second.toe_k2 : 10.0;
}

std::vector<FibreHyperelastic> disc_element_materials(const mesh::TetMesh& mesh,
                                                      const mesh::RegionMaterials& materials,
                                                      double fibre_k2) {
  const ElementFibres fibres = fibre_field(mesh, materials);
  std::vector<FibreHyperelastic> out;
  out.reserve(std::size_t(mesh.num_tets()));
  for (Eigen::Index t = 0; t < mesh.num_tets(); ++t) {
    const mesh::IsotropicMaterial& m = materials.at(mesh.region(t));
    FibreHyperelastic h = neo_hookean_from_linear(m.youngs_modulus_mpa, m.poisson_ratio);
    if (!fibres.empty() && fibres.stiffness_mpa(t) > 0) {
      const double k1 = fibres.stiffness_mpa(t) / 4.0;
      h.fibres.push_back({fibres.direction_1.row(t).transpose().normalized(), k1, fibre_k2});
      h.fibres.push_back({fibres.direction_2.row(t).transpose().normalized(), k1, fibre_k2});
    }
    out.push_back(std::move(h));
  }
  return out;
}

namespace {

HyperelasticBody make_body(const mesh::TetMesh& mesh, std::vector<FibreHyperelastic> materials,
                           int order, VolumetricForm form) {
  mesh::require_endplate_labels(mesh);
  return HyperelasticBody(make_fe_space(mesh, order), std::move(materials), form);
}

}  // namespace

NonlinearDisc::NonlinearDisc(const mesh::TetMesh& mesh,
                             std::vector<FibreHyperelastic> element_materials, int order,
                             const Eigen::Vector3d& plate_center_mm,
                             std::optional<VolumetricForm> form)
    : body_(make_body(mesh, std::move(element_materials), order,
                      form.value_or(order == 1 ? VolumetricForm::nodal_average
                                               : VolumetricForm::mean_dilatation))),
      center_(plate_center_mm) {
  labels_ = node_surface_labels(body_.space(), mesh);
  region_ = mesh.region;
  if (!center_.allFinite()) throw std::invalid_argument("plate centre: not finite");
}

NonlinearPlateSolution NonlinearDisc::solve_motion(const Eigen::Matrix<double, 6, 1>& motion,
                                                   const NewtonOptions& options) const {
  if (!motion.allFinite()) throw std::invalid_argument("plate motion: not finite");
  const Eigen::Vector3d t = motion.head<3>(), theta = motion.tail<3>();
  const Eigen::Matrix3d R_minus_I = rotation_exp_minus_identity(theta);
  const FeSpace& s = body_.space();
  std::vector<PrescribedDisplacement> bc;
  for (Eigen::Index i = 0; i < s.num_nodes(); ++i) {
    const int label = labels_(i);
    if (label != int(mesh::Surface::inferior_endplate) &&
        label != int(mesh::Surface::superior_endplate))
      continue;
    Eigen::Vector3d u = Eigen::Vector3d::Zero();
    if (label == int(mesh::Surface::superior_endplate)) {
      const Eigen::Vector3d arm = s.X.row(i).transpose() - center_;
      u = t + R_minus_I * arm;
    }
    for (int d = 0; d < 3; ++d) bc.push_back({i, d, u(d)});
  }
  NonlinearPlateSolution out;
  out.plate_motion = motion;
  out.body = body_.solve(bc, options);
  out.reaction_wrench = plate_reaction(out.body, motion.head<3>());
  out.nucleus_pressure_mpa = nucleus_pressure(out.body);
  return out;
}

Eigen::Matrix<double, 6, 1> NonlinearDisc::plate_reaction(const HyperelasticSolution& body,
                                                          const Eigen::Vector3d& t) const {
  // The disc pushes on the plate with −f at each plate node (f its internal force there).
  const FeSpace& s = body_.space();
  Eigen::Vector3d F = Eigen::Vector3d::Zero(), M = Eigen::Vector3d::Zero();
  const Eigen::Vector3d moved_center = center_ + t;
  for (Eigen::Index i = 0; i < s.num_nodes(); ++i) {
    if (labels_(i) != int(mesh::Surface::superior_endplate)) continue;
    const Eigen::Vector3d f = -body.reaction_n.row(i).transpose();
    const Eigen::Vector3d x = s.X.row(i).transpose() + body.displacement_mm.row(i).transpose();
    F += f;
    M += (x - moved_center).cross(f);
  }
  Eigen::Matrix<double, 6, 1> w;
  w << F, M;
  return w;
}

NonlinearPlateSolution NonlinearDisc::solve(const PlateLoad& load,
                                            const NewtonOptions& options) const {
  detail::PlateProblem pr;
  pr.center = center_;
  pr.motion_given = load.motion_given;
  pr.value = load.value;
  for (Eigen::Index i = 0; i < labels_.size(); ++i) {
    if (labels_(i) == int(mesh::Surface::inferior_endplate)) pr.fixed_nodes.push_back(i);
    if (labels_(i) == int(mesh::Surface::superior_endplate)) pr.plate_nodes.push_back(i);
  }
  detail::PlateNewtonResult r = detail::solve_plate_problem(body_, pr, options);
  NonlinearPlateSolution out;
  out.body = std::move(r.body);
  out.plate_motion = r.plate;
  out.reaction_wrench = plate_reaction(out.body, r.plate.head<3>());
  out.nucleus_pressure_mpa = nucleus_pressure(out.body);
  for (const auto& [fraction, plate] : r.path) out.path.push_back({fraction, plate});
  return out;
}

double NonlinearDisc::nucleus_pressure(const HyperelasticSolution& body) const {
  const FeSpace& s = body_.space();
  Eigen::VectorXd u(3 * s.num_nodes());
  for (Eigen::Index i = 0; i < s.num_nodes(); ++i)
    u.segment<3>(3 * i) = body.displacement_mm.row(i).transpose();
  const Eigen::VectorXd p = body_.element_pressures_mpa(u);
  double sum = 0, volume = 0;
  for (Eigen::Index t = 0; t < s.elements.rows(); ++t) {
    if (region_.size() != s.elements.rows() || region_(t) != int(mesh::Region::nucleus)) continue;
    TetVertices X;
    for (int a = 0; a < 4; ++a) X.row(a) = s.X.row(s.elements(t, a));
    double v = 0;
    barycentric_gradients(X, v);
    sum += v * p(t), volume += v;
  }
  return volume > 0 ? sum / volume : std::numeric_limits<double>::quiet_NaN();
}

}  // namespace spinesim::fem

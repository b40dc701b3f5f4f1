#include "spinesim/studies/mesh_disc.hpp"

#include "spinesim/common/atomic_file.hpp"
#include "spinesim/common/timer.hpp"
#include "spinesim/mesh/disc_geometry.hpp"
#include "spinesim/mesh/vertebra_disc.hpp"
#include "spinesim/spine/kinematics.hpp"
#include "spinesim/studies/mesh_report.hpp"
#include "spinesim/studies/spine_solve.hpp"
#include "spinesim/studies/toolkit.hpp"

#include <stdexcept>

namespace spinesim::studies {
namespace {

void check(const MeshDiscRequest& r) {
  const bool from_vertebrae = !r.inferior.empty() || !r.superior.empty();
  if (from_vertebrae == !r.level.empty())
    throw std::invalid_argument("give either --level or both --inferior and --superior");
  if (from_vertebrae && (r.inferior.empty() || r.superior.empty()))
    throw std::invalid_argument("a disc between vertebrae needs both --inferior and --superior");
  if (r.structured) mesh::validate(r.structured_options);
  if (r.scoliosis.cobb_deg != 0 && r.level.empty())
    throw std::invalid_argument("--scoliosis is for a parametric --level");
  if ((r.subject.height_m != 0 || r.subject.body_mass_kg != 0 ||
       r.subject.sex != spine::Sex::Male) &&
      r.level.empty())
    throw std::invalid_argument(
        "a body (--height, --mass, --sex, --subject) is for a parametric --level");
  if (!r.out.empty()) require_output_folder(r.out, "--out");  // a device, FIFO or link: refused
  if (r.out.empty() && !r.medit.empty())
    throw std::invalid_argument("--medit is a copy of --out: give --out too");
  if (!r.medit.empty()) require_output_folder(r.medit, "--medit");
}

nlohmann::json options_json(const MeshDiscRequest& r) {
  if (r.structured)
    return {{"mesher", "structured"},
            {"sectors", r.structured_options.sectors},
            {"rings", r.structured_options.rings},
            {"layers", r.structured_options.layers},
            {"match_area", r.structured_options.match_area}};
  const mesh::MeshOptions& o = r.cgal;
  return {{"mesher", "cgal"},
          {"cell_size_mm", o.cell_size_mm},
          {"facet_distance_mm", o.facet_distance_mm},
          {"facet_size_mm", o.facet_size_mm},
          {"radius_edge_ratio", o.radius_edge_ratio},
          {"odt", o.odt},
          {"lloyd", o.lloyd},
          {"perturb", o.perturb},
          {"exude", o.exude},
          {"seed", o.seed}};
}

/// The disc between two vertebra surfaces; returns the exact volume (the gap's quadrature).
double mesh_between_vertebrae(const MeshDiscRequest& r, const StageHooks& hooks,
                              MeshDiscResult& out) {
  hooks.begin_stage("reading vertebra surfaces");
  const auto inferior = mesh::read_surface(r.inferior, r.surface_mm_per_unit, r.up);
  const auto superior = mesh::read_surface(r.superior, r.surface_mm_per_unit, r.up);
  hooks.end_stage(std::to_string(inferior.F.rows()) + " + " + std::to_string(superior.F.rows()) +
                  " triangles");
  hooks.begin_stage("meshing the disc between the facing endplates");
  const Timer t;
  mesh::VertebraDiscInfo info;
  out.mesh = mesh::mesh_disc_between_vertebrae(inferior, superior, r.cgal,
                                               mesh::VertebraDiscOptions(), &info);
  out.mesh_seconds = t.seconds();
  hooks.end_stage(std::to_string(out.mesh.num_tets()) + " tets");
  if (info.filled_columns > 0)
    out.warning = "the endplates have holes: " + std::to_string(info.filled_columns) +
                  " columns (" + fixed(info.filled_area_mm2, 2) +
                  " mm^2) of the disc's footprint got endplate heights interpolated from around "
                  "them";
  out.disc = {{"inferior", r.inferior},
              {"superior", r.superior},
              {"disc",
               {{"filled_columns", info.filled_columns},
                {"filled_area_mm2", info.filled_area_mm2},
                {"footprint_area_mm2", info.footprint_area_mm2},
                {"center_height_mm", info.center_height_mm},
                {"min_height_mm", info.min_height_mm},
                {"max_height_mm", info.max_height_mm},
                {"width_mm", info.width_mm},
                {"depth_mm", info.depth_mm}}}};
  return info.volume_mm3;
}

/// The model of the request's body and curve, without loads (its scale and rest posture).
spine::SpineModel unloaded_model(const MeshDiscRequest& r, const std::string& data_dir) {
  spine::ModelOptions o;
  o.gravity = o.muscles = o.iap = false;
  o.scoliosis = r.scoliosis;
  o.subject = r.subject;
  return spine::load_spine_model(data_dir, o);
}

/// The disc of `level` carried between its vertebrae in the curve's rest posture. The mesh comes
/// in the spine placement; a local one is then expressed in the lower vertebra's frame.
nlohmann::json carry_in_scoliosis(const MeshDiscRequest& r, const std::string& data_dir,
                                  mesh::TetMesh& m) {
  const spine::SpineModel model = unloaded_model(r, data_dir);
  const double s = model.scale.length;
  const std::size_t k =
      std::size_t(spine::joint_index(mesh::disc_dimensions(r.level, data_dir).level));
  const std::vector<spine::Pose> P = spine::vertebra_poses(model, model.rest_posture);
  auto motion = [](const spine::Pose& p) { return mesh::RigidMotion{p.R, p.t}; };
  const mesh::RigidMotion upper = motion(P[k]),
                          lower = k + 1 < P.size() ? motion(P[k + 1]) : mesh::RigidMotion();
  mesh::DiscFrame frame = mesh::disc_level_frame(r.level, data_dir);
  frame.origin_mm *= s;  // the body's disc, scaled about the origin as its spine is
  mesh::carry_between(m, frame, s * mesh::disc_dimensions(r.level, data_dir).height_mm, lower,
                      upper);
  if (r.placement == mesh::DiscPlacement::local)
    for (Eigen::Index i = 0; i < m.V.rows(); ++i) {
      const Eigen::Vector3d x = lower.R.transpose() * (m.V.row(i).transpose() - lower.t);
      m.V.row(i) = (frame.axes.transpose() * (x - frame.origin_mm)).transpose();
    }
  const Eigen::Vector3d rest = model.joints[k].rest_rad * 180 / M_PI;
  return {{"type", r.scoliosis.type},
          {"cobb_deg", r.scoliosis.cobb_deg},
          {"apex", r.scoliosis.apex},
          {"joint_rest_rotation_deg", {rest.x(), rest.y(), rest.z()}},
          {"frontal_wedge_deg", rest.z()}};
}

/// A parametric level, CGAL or structured; returns the exact volume of the parametric disc.
double mesh_straight_level(const MeshDiscRequest& r, const std::string& data_dir,
                           const StageHooks& hooks, MeshDiscResult& out) {
  const auto dims = mesh::disc_dimensions(r.level, data_dir);
  const double s = unloaded_model(r, data_dir).scale.length;
  // The reference disc is meshed with sizes 1/s as large and scaled by s: the body's disc with
  // the asked sizes.
  mesh::MeshOptions cgal = r.cgal;
  for (double* size : {&cgal.cell_size_mm, &cgal.facet_distance_mm, &cgal.facet_size_mm,
                       &cgal.edge_size_mm})
    *size /= s;
  const Timer t;
  if (r.structured) {
    const mesh::StructuredDiscOptions& so = r.structured_options;
    hooks.begin_stage("meshing " + dims.level + " (structured, " + std::to_string(so.sectors) +
                      " sectors, " + std::to_string(so.rings) + " rings, " +
                      std::to_string(so.layers) + " layers)");
    out.mesh = mesh::mesh_structured_level(
        dims.level, so, data_dir,
        r.scoliosis.cobb_deg != 0 ? mesh::DiscPlacement::spine : r.placement);
  } else {
    hooks.begin_stage("meshing " + dims.level + " (cell size " +
                      std::to_string(r.cgal.cell_size_mm).substr(0, 4) + " mm)");
    out.mesh =
        mesh::mesh_disc_level(dims.level, cgal, data_dir,
                              r.scoliosis.cobb_deg != 0 ? mesh::DiscPlacement::spine : r.placement);
  }
  out.mesh.V *= s;
  out.mesh_seconds = t.seconds();
  hooks.end_stage(std::to_string(out.mesh.num_tets()) + " tets");
  out.disc = {{"level", dims.level},
              {"placement", r.placement == mesh::DiscPlacement::spine ? "spine" : "local"},
              {"length_scale", s},
              {"subject", subject_json(spine::resolve_subject(data_dir, r.subject))}};
  return s * s * s * mesh::parametric_disc_volume(dims);
}

/// A parametric level, CGAL or structured; returns the exact volume of the parametric disc (−1
/// when a scoliotic curve wedges it).
double mesh_level(const MeshDiscRequest& r, const std::string& data_dir, const StageHooks& hooks,
                  MeshDiscResult& out) {
  const double volume = mesh_straight_level(r, data_dir, hooks, out);
  if (r.scoliosis.cobb_deg == 0) return volume;
  out.disc["scoliosis"] = carry_in_scoliosis(r, data_dir, out.mesh);
  return -1;
}

}  // namespace

int mesh_disc_stages(const MeshDiscRequest& r) {
  return (r.level.empty() ? 2 : 1) + int(!r.out.empty());
}

MeshDiscResult run_mesh_disc(const MeshDiscRequest& request, const std::string& data_dir,
                             const StageHooks& hooks) {
  check(request);
  MeshDiscResult r;
  r.request = request;
  const double exact_volume = request.level.empty() ? mesh_between_vertebrae(request, hooks, r)
                                                    : mesh_level(request, data_dir, hooks, r);
  r.quality = mesh::quality_report(r.mesh, exact_volume);
  if (request.out.empty()) return r;  // the mesh alone (the Python module)
  hooks.begin_stage("writing " + request.out);
  OutputSet outputs("mesh disc");  // the VTU and the Medit copy: both or neither
  mesh::write_vtu(outputs.stage(request.out), r.mesh);
  if (!request.medit.empty()) mesh::write_medit(outputs.stage(request.medit), r.mesh);
  outputs.commit();
  hooks.end_stage();
  return r;
}

nlohmann::json mesh_disc_json(const MeshDiscResult& r) {
  nlohmann::json j = r.disc;
  j.update(quality_json(r.quality));
  j["mesh_seconds"] = r.mesh_seconds;
  j["out"] = path_or_null(r.request.out);
  if (!r.request.medit.empty()) j["medit"] = r.request.medit;
  j["options"] = options_json(r.request);
  return j;
}

}  // namespace spinesim::studies

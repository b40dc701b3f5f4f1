// spinesim mesh disc — tetrahedral disc meshes with CGAL Mesh_3, or structured (sweep) meshes
// of a few hundred tets for the 1 kHz mass-spring spine.
//
//   spinesim mesh disc --level L4-L5 [--cell-size 2] [--placement spine|local] --out disc.vtu
//   spinesim mesh disc --level T7-T8 --structured [--sectors 12 --rings 3 --layers 2] --out disc.vtu
//   spinesim mesh disc --inferior L5.obj --superior L4.obj --units m --up z --out disc.vtu
//
// Writes a VTU (cell data `region`, point data `surface`) and optionally Medit .mesh, and
// prints the quality report (tet count, dihedral angles, radius-edge ratio, volume vs exact).
#include "cli_common.hpp"

#include "spinesim/common/atomic_file.hpp"

#include "spinesim/studies/disc_level.hpp"
#include "spinesim/studies/mesh_report.hpp"

#include "spinesim/mesh/disc_geometry.hpp"
#include "spinesim/mesh/io.hpp"
#include "spinesim/mesh/mesher.hpp"
#include "spinesim/mesh/quality.hpp"
#include "spinesim/mesh/structured_disc.hpp"
#include "spinesim/mesh/vertebra_disc.hpp"

#include <iostream>
#include <map>
#include <memory>
#include <string>
#include <vector>

namespace spinesim::cli {
namespace {

struct MeshArgs {
  std::string level, inferior, superior, units = "mm", up = "y", placement = "spine";
  std::string out = "disc.vtu", medit;
  mesh::MeshOptions opt;
  bool no_perturb = false, no_exude = false, json = false, quiet = false;
  bool structured = false;
  mesh::StructuredDiscOptions structured_opt;
  double max_elements = mesh::MeshOptions().max_elements;
  std::vector<std::string> cgal_flags_given, structured_flags_given;  ///< filled after parsing
};

std::string joined(const std::vector<std::string>& names) {
  std::string s;
  for (const auto& n : names) s += (s.empty() ? "" : ", ") + n;
  return s;
}

// The structured mesher has its own resolution options; the Mesh_3 criteria do not apply.
void check_mesher_flags(const MeshArgs& a) {
  if (a.structured) {
    if (!a.cgal_flags_given.empty())
      throw std::invalid_argument("--structured does not take the CGAL options (" +
                                  joined(a.cgal_flags_given) +
                                  "); use --sectors, --rings, --layers");
    if (!a.inferior.empty() || !a.superior.empty())
      throw std::invalid_argument(
          "--structured meshes a parametric level: give --level, not --inferior/--superior");
    mesh::StructuredDiscOptions so = a.structured_opt;
    so.max_elements = a.max_elements;
    mesh::validate(so);
  } else if (!a.structured_flags_given.empty()) {
    throw std::invalid_argument(joined(a.structured_flags_given) + " only apply with --structured");
  }
}

/// The Mesh_3 options the flags select, within the mesher's own bounds (mesh_labeled_body),
/// checked before any work; NaN fails every test.
mesh::MeshOptions cgal_options(const MeshArgs& a) {
  mesh::MeshOptions opt = a.opt;
  opt.perturb = !a.no_perturb;
  opt.exude = !a.no_exude;
  if (!(opt.cell_size_mm > 0) || !std::isfinite(opt.cell_size_mm) || !(opt.facet_distance_mm > 0) ||
      !std::isfinite(opt.facet_distance_mm))
    throw std::invalid_argument("--cell-size and --facet-distance must be finite numbers > 0 mm");
  if (!(opt.facet_size_mm >= 0) || !std::isfinite(opt.facet_size_mm))
    throw std::invalid_argument("--facet-size must be 0 (the cell size) or a finite number > 0 mm");
  if (!(opt.radius_edge_ratio >= 2.0) || !std::isfinite(opt.radius_edge_ratio))
    throw std::invalid_argument("--radius-edge must be a finite number >= 2 (CGAL's bound)");
  if (!(opt.facet_angle_deg > 0 && opt.facet_angle_deg <= 30))
    throw std::invalid_argument("--facet-angle must lie in (0, 30] degrees (CGAL's bound)");
  if (!(a.max_elements >= 1)) throw std::invalid_argument("--max-elements must be >= 1");
  opt.max_elements = a.max_elements;
  return opt;
}

/// The options a mesh was made with, for the JSON report.
nlohmann::json options_json(const MeshArgs& a, const mesh::MeshOptions& opt) {
  if (a.structured)
    return {{"mesher", "structured"},
            {"sectors", a.structured_opt.sectors},
            {"rings", a.structured_opt.rings},
            {"layers", a.structured_opt.layers},
            {"match_area", a.structured_opt.match_area}};
  else
    return {{"mesher", "cgal"},
            {"cell_size_mm", opt.cell_size_mm},
            {"facet_distance_mm", opt.facet_distance_mm},
            {"facet_size_mm", opt.facet_size_mm},
            {"radius_edge_ratio", opt.radius_edge_ratio},
            {"odt", opt.odt},
            {"lloyd", opt.lloyd},
            {"perturb", opt.perturb},
            {"exude", opt.exude},
            {"seed", opt.seed}};
}

void run_mesh_disc(const MeshArgs& a) {
  check_mesher_flags(a);
  require_output_folder(a.out, "--out");  // a device, FIFO or link is refused before meshing
  if (!a.medit.empty()) require_output_folder(a.medit, "--medit");
  const mesh::MeshOptions opt = cgal_options(a);
  const bool from_vertebrae = !a.inferior.empty() || !a.superior.empty();
  if (from_vertebrae == !a.level.empty())
    throw std::invalid_argument("give either --level or both --inferior and --superior");
  if (from_vertebrae && (a.inferior.empty() || a.superior.empty()))
    throw std::invalid_argument("a disc between vertebrae needs both --inferior and --superior");

  Progress progress(from_vertebrae ? 3 : 2, a.quiet || a.json);
  mesh::TetMesh m;
  double exact_volume = -1;
  double mesh_s = 0;
  nlohmann::json j;
  if (from_vertebrae) {
    progress.begin("reading vertebra surfaces");
    const double scale = units_to_mm(a.units);
    const auto axis = up_axis(a.up);
    const auto inferior = mesh::read_surface(a.inferior, scale, axis);
    const auto superior = mesh::read_surface(a.superior, scale, axis);
    progress.end(std::to_string(inferior.F.rows()) + " + " + std::to_string(superior.F.rows()) +
                 " triangles");
    progress.begin("meshing the disc between the facing endplates");
    mesh::VertebraDiscInfo info;
    m = mesh::mesh_disc_between_vertebrae(inferior, superior, opt, mesh::VertebraDiscOptions(),
                                          &info);
    mesh_s = progress.end(std::to_string(m.num_tets()) + " tets");
    exact_volume = info.volume_mm3;  // quadrature of the endplate gap over the footprint
    j["inferior"] = a.inferior;
    j["superior"] = a.superior;
    if (info.filled_columns > 0)
      std::cerr << "spinesim: warning: the endplates have holes: " << info.filled_columns
                << " columns (" << fixed(info.filled_area_mm2, 2)
                << " mm^2) of the disc's footprint got endplate heights interpolated from around "
                   "them\n";
    j["disc"] = {{"filled_columns", info.filled_columns},
                 {"filled_area_mm2", info.filled_area_mm2},
                 {"footprint_area_mm2", info.footprint_area_mm2},
                 {"center_height_mm", info.center_height_mm},
                 {"min_height_mm", info.min_height_mm},
                 {"max_height_mm", info.max_height_mm},
                 {"width_mm", info.width_mm},
                 {"depth_mm", info.depth_mm}};
  } else {
    const auto dims = mesh::disc_dimensions(a.level, data_dir());
    if (a.placement != "spine" && a.placement != "local")
      throw std::invalid_argument("--placement must be 'spine' or 'local'");
    const DiscPlacement placement =
        a.placement == "spine" ? DiscPlacement::spine : DiscPlacement::local;
    if (a.structured) {
      mesh::StructuredDiscOptions so = a.structured_opt;
      so.max_elements = a.max_elements;
      progress.begin("meshing " + dims.level + " (structured, " + std::to_string(so.sectors) +
                     " sectors, " + std::to_string(so.rings) + " rings, " +
                     std::to_string(so.layers) + " layers)");
      m = mesh_structured_level(dims.level, so, placement);
    } else {
      progress.begin("meshing " + dims.level + " (cell size " +
                     std::to_string(opt.cell_size_mm).substr(0, 4) + " mm)");
      m = mesh_disc_level(dims.level, opt, placement);
    }
    mesh_s = progress.end(std::to_string(m.num_tets()) + " tets");
    exact_volume = mesh::parametric_disc_volume(dims);
    j["level"] = dims.level;
    j["placement"] = a.placement;
  }
  const auto q = mesh::quality_report(m, exact_volume);

  progress.begin("writing " + a.out);
  OutputSet outputs("mesh disc");  // the VTU and the MEDIT copy: both or neither
  mesh::write_vtu(outputs.stage(a.out), m);
  if (!a.medit.empty()) mesh::write_medit(outputs.stage(a.medit), m);
  outputs.commit();
  progress.end();

  j.update(quality_json(q));
  j["mesh_seconds"] = mesh_s;
  j["out"] = a.out;
  if (!a.medit.empty()) j["medit"] = a.medit;
  j["options"] = options_json(a, opt);
  if (a.json)
    print_json(j);
  else
    print_quality(std::cout, q, m.source);
}

}  // namespace

void register_mesh(CLI::App& app) {
  auto* mesh_cmd = app.add_subcommand(
      "mesh", "Make disc meshes (CGAL Mesh_3 or structured sweep) and vertebra surfaces");
  mesh_cmd->require_subcommand(1);
  auto a = std::make_shared<MeshArgs>();
  auto* disc = mesh_cmd->add_subcommand(
      "disc",
      "Mesh a disc: a parametric level (--level) or the disc between two vertebra surfaces");
  disc->add_option("--level", a->level,
                   "Disc level T1-T2 ... L5-S1 (parametric kidney-shaped disc)");
  disc->add_option("--inferior", a->inferior,
                   "Inferior vertebra or endplate surface (STL/OBJ/PLY/OFF)");
  disc->add_option("--superior", a->superior,
                   "Superior vertebra or endplate surface (STL/OBJ/PLY/OFF)");
  disc->add_option("--units", a->units, "Length unit of the surface files: mm, cm or m")
      ->capture_default_str();
  disc->add_option("--up", a->up, "Superior axis of the surface files: x, y, z, -x, -y, -z")
      ->capture_default_str();
  disc->add_option(
          "--placement", a->placement,
          "Parametric disc placement: 'spine' (between the vertebrae of thesis tables F.1/F.2) "
          "or 'local' (upright at the origin)")
      ->capture_default_str();
  const std::vector<CLI::Option*> cgal = {
      disc->add_option("--cell-size", a->opt.cell_size_mm, "Upper bound on tet circumradius, mm")
          ->capture_default_str(),
      disc->add_option("--facet-distance", a->opt.facet_distance_mm,
                       "Boundary approximation bound, mm")
          ->capture_default_str(),
      disc->add_option("--facet-size", a->opt.facet_size_mm,
                       "Boundary facet size, mm (0: = cell size)")
          ->capture_default_str(),
      disc->add_option("--facet-angle", a->opt.facet_angle_deg,
                       "Minimum boundary facet angle, degrees")
          ->capture_default_str(),
      disc->add_option("--radius-edge", a->opt.radius_edge_ratio, "Cell radius-edge ratio bound")
          ->capture_default_str(),
      disc->add_flag("--odt", a->opt.odt, "Run the ODT smoother"),
      disc->add_flag("--lloyd", a->opt.lloyd, "Run the Lloyd smoother"),
      disc->add_flag("--no-perturb", a->no_perturb, "Skip the sliver perturber"),
      disc->add_flag("--no-exude", a->no_exude, "Skip the sliver exuder"),
      disc->add_option("--seed", a->opt.seed, "Random seed (same seed, same mesh)")
          ->capture_default_str()};
  disc->add_option("--max-elements", a->max_elements,
                   "Refuse, before meshing, a mesh expected to exceed this many elements")
      ->capture_default_str();
  disc->add_flag(
      "--structured", a->structured,
      "Structured sweep mesh of a parametric level (a few hundred tets; no CGAL criteria)");
  const std::vector<CLI::Option*> structured = {
      disc->add_option("--sectors", a->structured_opt.sectors,
                       "Structured: samples around the outline (>= 6)")
          ->capture_default_str(),
      disc->add_option("--rings", a->structured_opt.rings,
                       "Structured: point rings, rim and nucleus boundary included (>= 2)")
          ->capture_default_str(),
      disc->add_option("--layers", a->structured_opt.layers,
                       "Structured: tet layers through the height (>= 1)")
          ->capture_default_str(),
      disc->add_flag(
          "--match-area", a->structured_opt.match_area,
          "Structured: stretch each section to the outline's exact area (exact volume)")};
  disc->add_option("--out", a->out, "Output VTU file")->capture_default_str();
  disc->add_option("--medit", a->medit, "Also write a Medit .mesh file");
  add_output_flags(disc, a->json, a->quiet);
  disc->callback([a, cgal, structured] {
    a->cgal_flags_given.clear();
    a->structured_flags_given.clear();
    for (const CLI::Option* o : cgal)
      if (o->count() > 0) a->cgal_flags_given.push_back(o->get_name());
    for (const CLI::Option* o : structured)
      if (o->count() > 0) a->structured_flags_given.push_back(o->get_name());
    run_mesh_disc(*a);
  });
  register_mesh_vertebrae(*mesh_cmd);
}

}  // namespace spinesim::cli

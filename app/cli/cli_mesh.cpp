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

#include "spinesim/studies/peer_disc.hpp"

#include "spinesim/studies/mesh_disc.hpp"
#include "spinesim/studies/mesh_report.hpp"

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
  ScoliosisFlags scoliosis;  ///< a level of a scoliotic spine: the disc wedged as the curve has it
  SubjectFlags subject;      ///< a level of another body's spine: the disc scaled with it
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

void run_mesh_disc(const MeshArgs& a) {
  // 1. Flags into the request (studies/mesh_disc.hpp), every one checked before any work.
  check_mesher_flags(a);
  MeshDiscRequest rq;
  rq.level = a.level;
  rq.inferior = a.inferior;
  rq.superior = a.superior;
  if (!a.inferior.empty() || !a.superior.empty()) {
    rq.surface_mm_per_unit = units_to_mm(a.units);
    rq.up = up_axis(a.up);
  }
  if (a.placement != "spine" && a.placement != "local")
    throw std::invalid_argument("--placement must be 'spine' or 'local'");
  rq.placement = a.placement == "spine" ? mesh::DiscPlacement::spine : mesh::DiscPlacement::local;
  rq.structured = a.structured;
  rq.structured_options = a.structured_opt;
  rq.structured_options.max_elements = a.max_elements;
  rq.cgal = cgal_options(a);
  if (a.out.empty()) throw std::invalid_argument("--out: give the output VTU");
  rq.out = a.out;
  rq.medit = a.medit;
  rq.scoliosis = scoliosis_of(a.scoliosis);
  rq.subject = subject_of(a.subject);

  // 2. The driver, then the report.
  Progress progress(mesh_disc_stages(rq), a.quiet || a.json);
  const MeshDiscResult r = run_mesh_disc(rq, data_dir(), progress.hooks());
  if (!r.warning.empty()) std::cerr << "spinesim: warning: " << r.warning << "\n";
  if (a.json)
    print_json(mesh_disc_json(r));
  else
    print_quality(std::cout, r.quality, r.mesh.source);
}

struct ImportArgs {
  studies::PeerDiscRequest request;
  bool json = false, quiet = false;
};

void run_mesh_import(const ImportArgs& a) {
  if (a.request.out.empty()) throw std::invalid_argument("--out: give the output VTU");
  const studies::PeerDiscResult r = studies::import_peer_disc(a.request, data_dir());
  const nlohmann::json j = studies::peer_disc_json(r, a.request);
  if (a.json) {
    print_json(j);
    return;
  }
  std::cout << r.mesh.source << ": " << r.hexahedra << " hexahedra -> " << r.mesh.num_tets()
            << " tets (annulus " << r.quality.annulus_tets << ", nucleus "
            << r.quality.nucleus_tets << "), " << r.mesh.num_vertices() << " nodes\n"
            << "  endplate nodes: inferior " << r.quality.inferior_nodes << ", superior "
            << r.quality.superior_nodes << "; wall " << r.quality.wall_nodes << "\n"
            << "  dihedral angle  min " << fixed(r.quality.min_dihedral_deg, 2) << " deg, max "
            << fixed(r.quality.max_dihedral_deg, 2) << " deg\n"
            << "  volume          " << fixed(r.quality.volume_mm3, 1) << " mm^3\n"
            << "  fibres          the peer's at " << fixed(r.peer_inclination_deg, 1)
            << " deg to the transverse plane, ours (fibre-reinforced) at "
            << fixed(r.our_inclination_deg, 1) << " deg; " << fixed(r.mean_pair_angle_deg, 1)
            << " deg apart on average\n"
            << "  fibre paths     "
            << (a.request.fibre_paths ? "the peer's (fibre materials follow them)"
                                      : "none (fibre materials follow the annulus geometry)")
            << "\n"
            << "wrote " << a.request.out << "\n";
}

}  // namespace

void register_mesh_import(CLI::App& mesh_cmd) {
  auto a = std::make_shared<ImportArgs>();
  auto* cmd = mesh_cmd.add_subcommand(
      "import", "A peer model's meshed disc as a spinesim disc (the ArtiSynth lumbosacral "
                "spine's hexahedral discs, split into tets)");
  cmd->add_option("--artisynth", a->request.folder,
                  "The model's fe-discs folder (LXX_AN_R1…R4 and LXX_NP .node/.elem files)")
      ->required();
  cmd->add_option("--level", a->request.level, "L1-L2, L2-L3, L3-L4, L4-L5 or L5-S1")->required();
  cmd->add_option("--out", a->request.out, "Output VTU file")->required();
  cmd->add_flag("!--no-fibre-paths", a->request.fibre_paths,
                "Leave the peer's fibres out of the mesh: a fibre material then lays its own "
                "along the annulus geometry");
  add_output_flags(cmd, a->json, a->quiet);
  cmd->footer(
      "Metres and the model's z-up frame become mm and ours; each hexahedron becomes six tets "
      "cut along\n"
      "its faces' lowest-numbered diagonals (conforming); rings are annulus, the nucleus "
      "nucleus; upper and\n"
      "lower faces the endplates. The peer's fibre polylines become the mesh's fibre paths "
      "(cell data\n"
      "fibre_path_direction_1/2), which fem, mss and calibrate lay a fibre material's fibres "
      "along.\n"
      "Then: spinesim fem --mesh OUT --material fibre-reinforced --case flexion; spinesim mss "
      "compare --mesh OUT;\n"
      "spinesim calibrate --mesh OUT");
  cmd->callback([a] { run_mesh_import(*a); });
}

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
  add_scoliosis_options(disc, a->scoliosis);
  add_subject_options(disc, a->subject);
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
  register_mesh_import(*mesh_cmd);
}

}  // namespace spinesim::cli

// spinesim mesh vertebrae — the parametric vertebra surfaces of the haptic scene.
//
//   spinesim mesh vertebrae [--level T1|…|L5|S1|all] [--triangles N] --out DIR
//
// Writes DIR/<name>.obj (mm, the spinesim frame, reference posture) and prints one line per
// body: triangles, vertices, enclosed volume and area, and whether the surface is closed.
#include "cli_common.hpp"

#include "spinesim/studies/vertebra_surfaces.hpp"

#include <iostream>
#include <memory>

namespace spinesim::cli {
namespace {

struct VertebraeArgs {
  std::string level = "all", out;
  int triangles = VertebraSurfacesRequest().triangles;
  bool json = false, quiet = false;
};

void run_mesh_vertebrae(const VertebraeArgs& a) {
  VertebraSurfacesRequest request;
  if (a.level != "all") request.bodies = split_list(a.level);
  request.triangles = a.triangles;
  request.out_dir = a.out;
  const int count = request.bodies.empty() ? 18 : int(request.bodies.size());
  ProgressBar bar(count, a.quiet || a.json, "vertebrae");
  const auto result =
      make_vertebra_surfaces(request, data_dir(), [&bar](int done, int) { bar.update(done); });
  if (a.json) {
    print_json(vertebra_surfaces_json(result));
    return;
  }
  std::cout << vertebra_surfaces_table(result) << "  " << fixed(result.seconds, 1) << " s\n";
}

}  // namespace

void register_mesh_vertebrae(CLI::App& mesh_cmd) {
  auto a = std::make_shared<VertebraeArgs>();
  auto* cmd = mesh_cmd.add_subcommand(
      "vertebrae",
      "Mesh the parametric vertebrae T1-L5 and the sacrum (closed OBJ surfaces, mm, reference "
      "posture)");
  cmd->add_option("--level", a->level,
                  "Bodies to mesh: all, or a comma-separated list of T1..L5 and S1 (the sacrum)")
      ->capture_default_str();
  cmd->add_option("--triangles", a->triangles, "Triangles per body (about; 100 to 2,000,000)")
      ->capture_default_str();
  cmd->add_option("--out", a->out, "Output folder (one <name>.obj per body)")->required();
  add_output_flags(cmd, a->json, a->quiet);
  cmd->callback([a] { run_mesh_vertebrae(*a); });
}

}  // namespace spinesim::cli

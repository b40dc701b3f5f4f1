#include "spinesim/studies/vertebra_surfaces.hpp"

#include "spinesim/common/timer.hpp"
#include "spinesim/studies/toolkit.hpp"

#include <filesystem>
#include <sstream>
#include <stdexcept>

namespace spinesim::studies {

VertebraSurfacesResult make_vertebra_surfaces(const VertebraSurfacesRequest& request,
                                              const std::string& data_dir,
                                              const std::function<void(int, int)>& progress) {
  const std::vector<std::string> bodies =
      request.bodies.empty() ? mesh::scene_body_names() : request.bodies;
  // Everything that can be refused is refused before the first body is meshed.
  std::vector<mesh::ParametricVertebra> solids;
  for (const auto& name : bodies) solids.push_back(mesh::parametric_vertebra(name, data_dir));
  if (request.triangles < 100 || request.triangles > 2000000)
    throw std::invalid_argument("--triangles " + std::to_string(request.triangles) +
                                ": give 100 to 2,000,000 per vertebra");
  if (!request.out_dir.empty()) {
    namespace fs = std::filesystem;
    const fs::path dir(request.out_dir);
    prepare_output_folder(request.out_dir, "--out");
    for (const auto& v : solids) require_output_folder((dir / (v.name + ".obj")).string(), "--out");
  }

  VertebraSurfacesResult r;
  const Timer total;
  for (std::size_t i = 0; i < solids.size(); ++i) {
    const Timer t;
    r.surfaces.push_back(mesh::mesh_vertebra(solids[i], request.triangles));
    const auto& s = r.surfaces.back();
    const auto check = mesh::check_surface(s.surface);
    VertebraSurfaceSummary sum;
    sum.name = s.name;
    sum.vertices = int(s.surface.V.rows());
    sum.triangles = int(s.surface.F.rows());
    sum.volume_mm3 = check.volume_mm3;
    sum.area_mm2 = check.area_mm2;
    sum.closed = check.closed;
    sum.oriented = check.oriented;
    sum.seconds = t.seconds();
    if (!request.out_dir.empty()) {
      sum.file = (std::filesystem::path(request.out_dir) / (s.name + ".obj")).string();
      mesh::write_obj(sum.file, s.surface,
                      "spinesim parametric vertebra " + s.name + " at the reference posture");
    }
    r.summaries.push_back(sum);
    if (progress) progress(int(i + 1), int(solids.size()));
  }
  r.seconds = total.seconds();
  return r;
}

nlohmann::json vertebra_surfaces_json(const VertebraSurfacesResult& r) {
  nlohmann::json bodies = nlohmann::json::array();
  for (const auto& s : r.summaries)
    bodies.push_back({{"name", s.name},
                      {"vertices", s.vertices},
                      {"triangles", s.triangles},
                      {"volume_mm3", s.volume_mm3},
                      {"area_mm2", s.area_mm2},
                      {"closed", s.closed},
                      {"oriented", s.oriented},
                      {"seconds", s.seconds},
                      {"file", s.file}});
  return {{"bodies", bodies}, {"seconds", r.seconds}};
}

std::string vertebra_surfaces_table(const VertebraSurfacesResult& r) {
  TextTable t({"body", "triangles", "vertices", "volume cm^3", "area cm^2", "closed", "file"});
  for (const auto& s : r.summaries)
    t.add({s.name, std::to_string(s.triangles), std::to_string(s.vertices),
           fixed(s.volume_mm3 / 1000, 1), fixed(s.area_mm2 / 100, 1),
           s.closed && s.oriented ? "yes" : "NO", s.file.empty() ? "-" : s.file});
  std::ostringstream os;
  t.print(os, false);
  return os.str();
}

}  // namespace spinesim::studies

// The vertebra surfaces of the haptic scene: the parametric T1…L5 and sacrum of
// mesh/vertebra_geometry.hpp, meshed at a chosen resolution and optionally written as OBJ.
#pragma once

#include "spinesim/mesh/vertebra_geometry.hpp"

#include <nlohmann/json.hpp>

#include <functional>
#include <string>
#include <vector>

namespace spinesim::studies {

struct VertebraSurfacesRequest {
  std::vector<std::string> bodies;  ///< "T1" … "L5", "S1"; empty: all 18
  int triangles = 8000;             ///< per body (the count lands within about ±30 %)
  std::string out_dir;              ///< empty: nothing written; else <out_dir>/<name>.obj
};

struct VertebraSurfaceSummary {
  std::string name;
  int vertices = 0, triangles = 0;
  double volume_mm3 = 0, area_mm2 = 0;
  bool closed = false, oriented = false;
  double seconds = 0;
  std::string file;  ///< written OBJ (empty when not written)
};

struct VertebraSurfacesResult {
  std::vector<mesh::VertebraSurface> surfaces;
  std::vector<VertebraSurfaceSummary> summaries;
  double seconds = 0;
};

/// Builds (and writes) the surfaces; `progress(done, total)` after each body. Throws
/// std::invalid_argument for an unknown body or resolution (one line); an output folder that
/// cannot be written is refused before any meshing.
VertebraSurfacesResult make_vertebra_surfaces(const VertebraSurfacesRequest& request,
                                              const std::string& data_dir,
                                              const std::function<void(int, int)>& progress = {});

nlohmann::json vertebra_surfaces_json(const VertebraSurfacesResult& r);
std::string vertebra_surfaces_table(const VertebraSurfacesResult& r);

}  // namespace spinesim::studies

#include "spinesim/studies/disc_level.hpp"

#include "spinesim/mesh/disc_geometry.hpp"
#include "spinesim/studies/data.hpp"

namespace spinesim::studies {

mesh::DiscFrame disc_level_frame(const std::string& level, DiscPlacement placement) {
  const auto dims = mesh::disc_dimensions(level, data_dir());  // refuses an unknown level
  return placement == DiscPlacement::spine ? mesh::disc_frame_in_spine(dims.level, data_dir())
                                           : mesh::DiscFrame();
}

mesh::TetMesh mesh_disc_level(const std::string& level, const mesh::MeshOptions& options,
                              DiscPlacement placement) {
  const auto dims = mesh::disc_dimensions(level, data_dir());
  return mesh::mesh_parametric_disc(dims, options, disc_level_frame(dims.level, placement));
}

mesh::TetMesh mesh_disc_level(const std::string& level, double cell_size_mm) {
  mesh::MeshOptions options;
  options.cell_size_mm = cell_size_mm;
  return mesh_disc_level(level, options);
}

mesh::TetMesh mesh_structured_level(const std::string& level,
                                    const mesh::StructuredDiscOptions& options,
                                    DiscPlacement placement) {
  const auto dims = mesh::disc_dimensions(level, data_dir());
  return mesh::mesh_structured_disc(dims, options, disc_level_frame(dims.level, placement));
}

}  // namespace spinesim::studies

#include "spinesim/mesh/disc_level.hpp"

#include "spinesim/mesh/disc_geometry.hpp"

namespace spinesim::mesh {

DiscFrame disc_level_frame(const std::string& level, const std::string& data_dir,
                           DiscPlacement placement) {
  const auto dims = disc_dimensions(level, data_dir);  // refuses an unknown level
  return placement == DiscPlacement::spine ? disc_frame_in_spine(dims.level, data_dir)
                                           : DiscFrame();
}

TetMesh mesh_disc_level(const std::string& level, const MeshOptions& options,
                        const std::string& data_dir, DiscPlacement placement) {
  const auto dims = disc_dimensions(level, data_dir);
  return mesh_parametric_disc(dims, options, disc_level_frame(dims.level, data_dir, placement));
}

TetMesh mesh_disc_level(const std::string& level, double cell_size_mm,
                        const std::string& data_dir) {
  MeshOptions options;
  options.cell_size_mm = cell_size_mm;
  return mesh_disc_level(level, options, data_dir);
}

TetMesh mesh_structured_level(const std::string& level, const StructuredDiscOptions& options,
                              const std::string& data_dir, DiscPlacement placement) {
  const auto dims = disc_dimensions(level, data_dir);
  return mesh_structured_disc(dims, options, disc_level_frame(dims.level, data_dir, placement));
}

}  // namespace spinesim::mesh

// Parametric disc geometry for the 17 thoracolumbar levels T1-T2 ... L5-S1.
//
// Cross-section: a kidney-shaped closed curve (posterior concavity) of lateral width W and
// antero-posterior depth D; the nucleus is the same curve scaled by sqrt(0.4) about the
// area centroid, i.e. 40 % of the cross-section area (thesis 5.2.5, Krismer et al. 1996).
// The lower outline (inferior vertebra's upper endplate) and the upper outline (superior
// vertebra's lower endplate) may differ in size; the wall is the linear loft between them.
// Dimensions come from data/disc_morphometry.csv (each value cited there).
#pragma once

#include "spinesim/mesh/tet_mesh.hpp"

#include <Eigen/Core>

#include <string>
#include <vector>

namespace spinesim::mesh {

/// One level's sourced dimensions, mm.
struct DiscDimensions {
  std::string level;              ///< e.g. "L4-L5"
  double lower_width_mm = 0;      ///< lateral width of the lower outline
  double lower_depth_mm = 0;      ///< antero-posterior depth of the lower outline
  double upper_width_mm = 0;
  double upper_depth_mm = 0;
  double height_mm = 0;           ///< mid-disc height
};

/// The 17 level names in cranial-to-caudal order: "T1-T2", ..., "L5-S1".
const std::vector<std::string>& disc_levels();

/// Reads data/disc_morphometry.csv; throws std::invalid_argument for an unknown level
/// (the message lists the known ones).
DiscDimensions disc_dimensions(const std::string& level, const std::string& data_dir);

/// Where the disc sits in the spine model: origin at the table F.2 joint point of the level,
/// axial direction from the inferior to the superior vertebra centre (table F.1), lateral
/// axis = global x. Reads data/thesis/F1_vertebra_cm.csv and F2_joint_markers.csv.
DiscFrame disc_frame_in_spine(const std::string& level, const std::string& data_dir);

}  // namespace spinesim::mesh

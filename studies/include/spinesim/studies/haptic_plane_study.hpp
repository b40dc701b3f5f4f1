// The thesis's plane test of the Gao–Gibson probe-normal force (thesis 4.4.2, figs 4.16–4.19):
// two spherical probes whose diameters are in the thesis's ratio (400 and 800 units: 1 : 2) pass
// through a plane; the force magnitude against the intrusion depth, with eq 4.9 (sum over the
// sample points) and with eq 4.10 (divided by the probe's largest cross-section). Each column
// comes with its closed form (the midpoint-rule sum of the samples converges to it).
#pragma once

#include <nlohmann/json.hpp>

#include <string>
#include <vector>

namespace spinesim::studies {

struct HapticPlaneRequest {
  double small_radius_mm = 5;  ///< the large probe's is twice this
  double step_mm = 0.1;        ///< depth step
  double spacing_mm = 0.1;     ///< surface sample spacing
  double stiffness_eq410_n_per_mm = 0.5;
  /// Eq 4.9's stiffness (N/mm³); 0: chosen so that the small probe's peak equals eq 4.10's
  /// (k / (π r²)), which makes the two laws' curves comparable in one plot.
  double stiffness_eq49_n_per_mm3 = 0;
};

struct HapticPlaneRow {
  double depth_mm = 0;
  double small_eq49_n = 0, large_eq49_n = 0, small_eq410_n = 0, large_eq410_n = 0;
  double small_eq49_exact_n = 0, large_eq49_exact_n = 0, small_eq410_exact_n = 0,
         large_eq410_exact_n = 0;
};

struct HapticPlaneResult {
  HapticPlaneRequest request;
  double stiffness_eq49 = 0;
  std::vector<HapticPlaneRow> rows;
  // The thesis's observations, measured:
  double small_peak_depth_eq49_mm = 0, large_peak_depth_eq49_mm = 0;
  bool large_higher_everywhere_eq49 = false;  ///< at every depth where the small one touches
  double ratio_at_small_peak_eq49 = 0;        ///< large / small at depth = small radius
  double ratio_at_small_peak_eq410 = 0;       ///< thesis fig 4.19: "nearly the same"
  bool small_higher_before_peak_eq410 = false;
  double max_relative_error_vs_exact = 0;
  double seconds = 0;
};

HapticPlaneResult run_haptic_plane_study(const HapticPlaneRequest& r);
std::string haptic_plane_csv(const HapticPlaneResult& r);
nlohmann::json haptic_plane_json(const HapticPlaneResult& r);
std::string haptic_plane_table(const HapticPlaneResult& r);

}  // namespace spinesim::studies

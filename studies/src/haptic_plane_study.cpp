#include "spinesim/studies/haptic_plane_study.hpp"
#include "spinesim/common/constants.hpp"

#include "spinesim/common/timer.hpp"
#include "spinesim/haptics/renderer.hpp"
#include "spinesim/studies/toolkit.hpp"

#include <cmath>
#include <sstream>
#include <stdexcept>

namespace spinesim::studies {

namespace {

// ∫ (r − |p − c|) dA over the plane's part inside the ball of radius r centred at height h.
double depth_integral(double r, double h) {
  if (std::abs(h) >= r) return 0;
  return kPi * r * (r * r - h * h) - 2.0 * kPi / 3.0 * (r * r * r - std::pow(std::abs(h), 3));
}

}  // namespace

HapticPlaneResult run_haptic_plane_study(const HapticPlaneRequest& req) {
  if (!(req.small_radius_mm > 0) || req.small_radius_mm > 50 || !(req.step_mm > 0) ||
      !(req.spacing_mm > 0) || !(req.stiffness_eq410_n_per_mm > 0) ||
      !(req.stiffness_eq49_n_per_mm3 >= 0))
    throw std::invalid_argument(
        "haptic-plane: radius must be in (0, 50] mm, step, spacing and stiffness > 0");
  const double r = req.small_radius_mm, R = 2 * r;
  if (2 * R / req.step_mm > 1e5 || std::pow(4 * R / req.spacing_mm, 2) > 2e7)
    throw std::invalid_argument("haptic-plane: step or spacing too fine for the probe size");
  const Timer timer;
  HapticPlaneResult out;
  out.request = req;
  const double k410 = req.stiffness_eq410_n_per_mm;
  const double k49 =
      req.stiffness_eq49_n_per_mm3 > 0 ? req.stiffness_eq49_n_per_mm3 : k410 / (kPi * r * r);
  out.stiffness_eq49 = k49;

  haptics::Scene scene;
  scene.add_body("plane", haptics::square_plane(2.5 * R, 1.0));
  scene.sample_surfaces(req.spacing_mm);
  const haptics::ScenePoses poses{};
  auto renderer = [&](double radius, haptics::GaoGibsonLaw law, double k) {
    haptics::GaoGibsonParameters p;
    p.radius_mm = radius;
    p.law = law;
    p.stiffness = k;
    p.max_triangles = 1 << 16;
    return haptics::GaoGibsonRenderer(p);
  };
  auto small49 = renderer(r, haptics::GaoGibsonLaw::eq_4_9, k49);
  auto large49 = renderer(R, haptics::GaoGibsonLaw::eq_4_9, k49);
  auto small410 = renderer(r, haptics::GaoGibsonLaw::eq_4_10, k410);
  auto large410 = renderer(R, haptics::GaoGibsonLaw::eq_4_10, k410);
  auto force = [&](haptics::GaoGibsonRenderer& g, double radius, double depth) {
    haptics::ProbeState probe;
    probe.position_mm = Eigen::Vector3d(0.013, -0.021, radius - depth);  // off the grid's nodes
    return g.render(probe, scene, poses, 1e-3).force_n.norm();
  };
  const int steps = int(std::round(2 * R / req.step_mm));
  double small_peak = -1, large_peak = -1;
  out.large_higher_everywhere_eq49 = true;
  out.small_higher_before_peak_eq410 = true;
  for (int i = 0; i <= steps; ++i) {
    HapticPlaneRow row;
    row.depth_mm = i * req.step_mm;
    const double d = row.depth_mm;
    row.small_eq49_n = force(small49, r, d);
    row.large_eq49_n = force(large49, R, d);
    row.small_eq410_n = force(small410, r, d);
    row.large_eq410_n = force(large410, R, d);
    row.small_eq49_exact_n = k49 * depth_integral(r, r - d);
    row.large_eq49_exact_n = k49 * depth_integral(R, R - d);
    row.small_eq410_exact_n = k410 * depth_integral(r, r - d) / (kPi * r * r);
    row.large_eq410_exact_n = k410 * depth_integral(R, R - d) / (kPi * R * R);
    if (row.small_eq49_n > small_peak) {
      small_peak = row.small_eq49_n;
      out.small_peak_depth_eq49_mm = d;
    }
    if (row.large_eq49_n > large_peak) {
      large_peak = row.large_eq49_n;
      out.large_peak_depth_eq49_mm = d;
    }
    if (d > 0 && d < 2 * r && !(row.large_eq49_n > row.small_eq49_n))
      out.large_higher_everywhere_eq49 = false;
    if (d > 0 && d < r - 1e-9 && !(row.small_eq410_n > row.large_eq410_n))
      out.small_higher_before_peak_eq410 = false;
    if (std::abs(d - r) < 0.5 * req.step_mm) {
      out.ratio_at_small_peak_eq49 = row.large_eq49_n / row.small_eq49_n;
      out.ratio_at_small_peak_eq410 = row.large_eq410_n / row.small_eq410_n;
    }
    const double scale = std::max(row.large_eq49_exact_n, 1e-3);
    out.max_relative_error_vs_exact =
        std::max({out.max_relative_error_vs_exact,
                  std::abs(row.large_eq49_n - row.large_eq49_exact_n) / scale,
                  std::abs(row.small_eq410_n - row.small_eq410_exact_n) /
                      std::max(row.small_eq410_exact_n, 0.05 * k410 * r / 3)});
    out.rows.push_back(row);
  }
  out.seconds = timer.seconds();
  return out;
}

std::string haptic_plane_csv(const HapticPlaneResult& r) {
  std::ostringstream os;
  os << "# spinesim study haptic-plane: Gao-Gibson force magnitude against intrusion depth; "
        "probe radii "
     << r.request.small_radius_mm << " and " << 2 * r.request.small_radius_mm
     << " mm; eq 4.9 k = " << r.stiffness_eq49
     << " N/mm^3, eq 4.10 k = " << r.request.stiffness_eq410_n_per_mm
     << " N/mm; *_exact: the closed-form integral\n"
     << "depth_mm,small_eq49_n,large_eq49_n,small_eq410_n,large_eq410_n,small_eq49_exact_n,"
        "large_eq49_exact_n,small_eq410_exact_n,large_eq410_exact_n\n";
  os.precision(8);
  for (const auto& row : r.rows)
    os << row.depth_mm << ',' << row.small_eq49_n << ',' << row.large_eq49_n << ','
       << row.small_eq410_n << ',' << row.large_eq410_n << ',' << row.small_eq49_exact_n << ','
       << row.large_eq49_exact_n << ',' << row.small_eq410_exact_n << ',' << row.large_eq410_exact_n
       << '\n';
  return os.str();
}

nlohmann::json haptic_plane_json(const HapticPlaneResult& r) {
  return {{"small_radius_mm", r.request.small_radius_mm},
          {"large_radius_mm", 2 * r.request.small_radius_mm},
          {"stiffness_eq49_n_per_mm3", r.stiffness_eq49},
          {"stiffness_eq410_n_per_mm", r.request.stiffness_eq410_n_per_mm},
          {"small_peak_depth_eq49_mm", r.small_peak_depth_eq49_mm},
          {"large_peak_depth_eq49_mm", r.large_peak_depth_eq49_mm},
          {"large_higher_everywhere_eq49", r.large_higher_everywhere_eq49},
          {"ratio_at_small_peak_eq49", r.ratio_at_small_peak_eq49},
          {"ratio_at_small_peak_eq410", r.ratio_at_small_peak_eq410},
          {"small_higher_before_peak_eq410", r.small_higher_before_peak_eq410},
          {"max_relative_error_vs_exact", r.max_relative_error_vs_exact},
          {"rows", r.rows.size()},
          {"seconds", r.seconds}};
}

std::string haptic_plane_table(const HapticPlaneResult& r) {
  std::ostringstream os;
  const double a = r.request.small_radius_mm;
  os << "  probes: radius " << fixed(a, 1) << " and " << fixed(2 * a, 1)
     << " mm (diameters 1 : 2, the thesis's 400 and 800 units)\n"
     << "  eq 4.9  (sum over samples): small probe peaks at "
     << fixed(r.small_peak_depth_eq49_mm, 2) << " mm, large at "
     << fixed(r.large_peak_depth_eq49_mm, 2)
     << " mm (thesis fig 4.16: at depth = radius); large/small at the small one's peak "
     << fixed(r.ratio_at_small_peak_eq49, 2) << " (thesis fig 4.18: over 2); large higher at every "
     << "depth: " << (r.large_higher_everywhere_eq49 ? "yes" : "NO") << "\n"
     << "  eq 4.10 (/ largest cross-section): large/small at the small one's peak "
     << fixed(r.ratio_at_small_peak_eq410, 4) << " (thesis fig 4.19: nearly the same; exactly 1 "
     << "in the continuum); small higher before it: "
     << (r.small_higher_before_peak_eq410 ? "yes" : "NO") << "\n"
     << "  sampled sums vs closed form: largest relative difference "
     << percent(r.max_relative_error_vs_exact, 2) << " (" << r.rows.size() << " depths, "
     << fixed(r.seconds, 1) << " s)\n";
  return os.str();
}

}  // namespace spinesim::studies

// A sweep plan: one study (a verb and its fixed options, as in a study file) and the options
// that vary, expanded into points. `spinesim sweep PLAN` runs the points (docs/sweeps.md).
//
//   {"spinesim_sweep": 1,
//    "description": "…",                                   (optional text)
//    "verb": "spine solve",
//    "options": {"force": ["T7:0,0,300"]},                 the options every point shares
//    "parameters": {
//      "height": {"values": [1.6, 1.778]},                 a list
//      "mass": {"from": 50, "to": 100, "steps": 3},         evenly spaced, both ends included
//      "sex": {"values": ["male", "female"]}},
//    "design": "grid",                                      or "zip", or
//              {"latin_hypercube": {"points": 20, "seed": 1}}, or (sensitivity.hpp)
//              {"morris": {"trajectories": 10, "levels": 4, "seed": 1}}, or
//              {"sobol": {"base_points": 256, "seed": 1}}
//              (both also take "resamples": 1000 and "confidence": 0.95, the bootstrap
//              intervals of their indices)
//    "outputs": {"L5-S1 axial (N)": "/joints/16/axial_n"},  JSON pointers into a point's --json
//    "windows": {"L5-S1 axial (N)": {"low": 500, "high": 900, "source": "…"}}}   (optional)
//
// Designs: "grid" is every combination (the first parameter varies slowest); "zip" takes the
// i-th value of every list (all of one length); a Latin hypercube draws `points` points of the
// parameters' ranges ({"from", "to"}, continuous; a list is drawn from by index), one per
// stratum in every parameter, from a seeded generator whose stream is fixed here (SplitMix64),
// so the same plan gives the same points on every machine. The sensitivity designs (Morris
// screening, Sobol indices by Saltelli's scheme) take ranges only, and the summary then carries
// each numeric output's sensitivity to each parameter (sweep_sensitivity). Windows, measured
// ranges of outputs, weigh a Latin hypercube's points by how well they meet them, and the summary
// then carries every parameter's and output's spread before and after (uncertainty.hpp
// sweep_uncertainty).
#pragma once

#include "spinesim/calibration/window_fit.hpp"

#include <nlohmann/json.hpp>

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

namespace spinesim::studies {

/// The sweep plan format's version, "spinesim_sweep".
inline constexpr int kSweepPlanVersion = 1;

struct SweepParameter {
  std::string option;                  ///< the verb's option, without "--"
  std::vector<nlohmann::json> values;  ///< a list (or the evenly spaced steps); empty: a range
  double from = 0, to = 0;             ///< a continuous range (values empty)
};

struct SweepPlan {
  std::string description;
  std::string verb;
  nlohmann::json options = nlohmann::json::object();  ///< shared by every point
  std::vector<SweepParameter> parameters;
  std::string design = "grid";  ///< grid, zip, latin_hypercube, morris or sobol
  int sample_points = 0;        ///< latin_hypercube: how many
  int trajectories = 0, levels = 4;  ///< morris (sensitivity.hpp)
  int base_points = 0;               ///< sobol: N of Saltelli's N (k + 2) runs
  std::uint64_t seed = 1;            ///< the sampling designs' generator seed
  int resamples = 1000;              ///< morris, sobol: bootstrap resamples of the intervals
  double confidence = 0.95;          ///< morris, sobol: the intervals' confidence
  std::vector<std::pair<std::string, std::string>> outputs;  ///< column name, JSON pointer
  std::vector<calibration::WindowTarget> windows;  ///< latin_hypercube: measured outputs (by name)
  std::vector<std::string> window_sources;         ///< each window's "source" ("" when none)
};

struct SweepPoint {
  int index = 0;
  nlohmann::json values = nlohmann::json::object();  ///< the parameters' values, by option
};

/// Reads a plan (already parsed JSON). Throws std::invalid_argument (one line, naming `where`
/// and the field) for an unknown or missing field, a parameter also among the fixed options,
/// an empty list, a range whose ends are not finite numbers with from < to, steps < 2, a grid
/// or zip over a continuous range, zip lists of different lengths, a Latin hypercube of fewer
/// than 2 or more than 10^6 points, an output that is not a JSON pointer, or a plan of more
/// than 10^6 points.
SweepPlan parse_sweep_plan(const nlohmann::json& plan, const std::string& where);

/// The plan's points, indexed 0 … n-1 in the design's order.
std::vector<SweepPoint> expand_sweep(const SweepPlan& plan);

/// The study file of one point: the plan's verb with its options and the point's values.
nlohmann::json point_study(const SweepPlan& plan, const SweepPoint& point);

/// The outputs of one point read from its JSON result (null where the pointer finds nothing).
nlohmann::json point_outputs(const SweepPlan& plan, const nlohmann::json& result);

/// Each numeric output's sensitivity to each parameter, for a morris or sobol plan (null for the
/// other designs): {"output": {"parameter": {"mu_star", "mu", "sigma"} or {"first", "total"}}},
/// with the number of runs and the bootstrap intervals at the plan's confidence ([low, high]:
/// "mu_star_interval", "mu_star_over_range_interval", "first_interval", "total_interval").
/// `outputs[i]` is point i's point_outputs; an output missing at any
/// point (a failed point, a non-number) gets {"error": why} instead. Morris's mu_star_over_range
/// is mu* times the parameter's range: the output's mean change across it, to rank parameters of
/// different units.
nlohmann::json sweep_sensitivity(const SweepPlan& plan, const std::vector<SweepPoint>& points,
                                 const std::vector<nlohmann::json>& outputs);

/// SplitMix64 (Steele, Lea & Flood 2014): the sweep's own random stream, the same on every
/// platform and standard library. uniform() is in [0, 1) with 53 random bits.
class SplitMix64 {
 public:
  explicit SplitMix64(std::uint64_t seed) : state_(seed) {}
  std::uint64_t next();
  double uniform() { return double(next() >> 11) * 0x1.0p-53; }

 private:
  std::uint64_t state_;
};

}  // namespace spinesim::studies

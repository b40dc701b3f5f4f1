// The MSS-vs-FEM comparison (calibration/compare.hpp) as JSON, a readable table and CSV.
#pragma once

#include "spinesim/calibration/compare.hpp"

#include <nlohmann/json.hpp>

#include <ostream>
#include <string>

namespace spinesim::studies {

using calibration::CaseComparison;
using calibration::MssFemComparison;

/// Every case's errors, plate motions (mm, deg) and reaction wrenches, the means, the K6
/// diagonals (N/mm, N·mm/deg) and the timings.
nlohmann::json comparison_json(const MssFemComparison& c);
/// Readable table (markdown when `markdown`), one row per case, then the K6 diagonal ratios.
void print_comparison(std::ostream& os, const MssFemComparison& c, bool markdown);
/// One CSV row per case: errors and both reaction wrenches.
std::string comparison_csv(const MssFemComparison& c);

}  // namespace spinesim::studies

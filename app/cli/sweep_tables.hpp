// The sweep's tables beside its summary (cli_sweep.cpp): CSV cells, the sensitivity (Morris,
// Sobol) and the uncertainty (windows) as CSV files and as printed tables.
#pragma once

#include "spinesim/studies/sweep_plan.hpp"

#include <nlohmann/json.hpp>

#include <string>

namespace spinesim::cli {

/// One CSV cell: null empty, numbers in the shortest text that reads back exactly, text quoted
/// when it holds a comma, a quote or a line break.
std::string csv_cell(const nlohmann::json& v);

/// summary["sensitivity"] (studies::sweep_sensitivity) as CSV: one row per output and parameter,
/// the estimates and their bootstrap intervals; and as a table on stdout.
std::string sensitivity_csv(const studies::SweepPlan& plan, const nlohmann::json& summary);
void print_sensitivity(const studies::SweepPlan& plan, const nlohmann::json& summary);

/// summary["uncertainty"] (studies::sweep_uncertainty) as CSV: one row per parameter and output,
/// its prior and posterior mean, SD and 5/50/95 % quantiles; and as a table on stdout.
std::string uncertainty_csv(const studies::SweepPlan& plan, const nlohmann::json& summary);
void print_uncertainty(const studies::SweepPlan& plan, const nlohmann::json& summary);

}  // namespace spinesim::cli

// The drivers speak the output toolkit (spinesim/output/: numbers, tables, JSON, progress, files,
// the HTML report) unqualified, as their own.
#pragma once

#include "spinesim/output/files.hpp"
#include "spinesim/output/format.hpp"
#include "spinesim/output/html_report.hpp"
#include "spinesim/output/json.hpp"
#include "spinesim/output/progress.hpp"
#include "spinesim/output/table.hpp"

namespace spinesim::studies {
using namespace spinesim::output;
}  // namespace spinesim::studies

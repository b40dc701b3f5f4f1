// Where the shipped tables are (data/: thesis tables, morphometry, materials, tuned discs).
#pragma once

#include <string>

namespace spinesim::studies {

/// $SPINESIM_DATA_DIR if set and not empty, else the source tree's data/ folder.
std::string data_dir();

}  // namespace spinesim::studies

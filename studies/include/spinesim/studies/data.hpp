// Where the shipped tables are (data/: thesis tables, morphometry, materials, tuned discs).
#pragma once

#include <string>

namespace spinesim::studies {

/// $SPINESIM_DATA_DIR if set and not empty, else the source tree's data/ folder.
std::string data_dir();

/// $SPINESIM_TESTDATA_DIR if set and not empty, else the build's test-data folder (the shared
/// folder beside the source tree): real input data from elsewhere, never part of the project.
std::string testdata_dir();

}  // namespace spinesim::studies

#include "spinesim/studies/data.hpp"

#include <cstdlib>

namespace spinesim::studies {

std::string data_dir() {
  if (const char* env = std::getenv("SPINESIM_DATA_DIR"); env && *env) return env;
  return SPINESIM_DATA_DIR;
}

std::string testdata_dir() {
  if (const char* env = std::getenv("SPINESIM_TESTDATA_DIR"); env && *env) return env;
  return SPINESIM_TESTDATA_DIR;
}

}  // namespace spinesim::studies

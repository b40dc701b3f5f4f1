#include "spinesim/studies/data.hpp"

#include <cstdlib>

namespace spinesim::studies {

std::string data_dir() {
  if (const char* env = std::getenv("SPINESIM_DATA_DIR"); env && *env) return env;
  return SPINESIM_DATA_DIR;
}

}  // namespace spinesim::studies

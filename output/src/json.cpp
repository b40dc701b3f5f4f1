#include "spinesim/output/json.hpp"

#include "spinesim/common/provenance.hpp"

#include <iostream>

namespace spinesim::output {

namespace {
bool g_json_printed = false;
}  // namespace

void print_json(const nlohmann::json& j) {
  std::cout << with_provenance(j).dump(2) << std::endl;
  g_json_printed = true;
}

bool json_printed() { return g_json_printed; }

void reset_json_printed() { g_json_printed = false; }

}  // namespace spinesim::output

#include "spinesim/studies/json.hpp"

#include <iostream>

namespace spinesim::studies {

void print_json(const nlohmann::json& j) { std::cout << j.dump(2) << std::endl; }

}  // namespace spinesim::studies

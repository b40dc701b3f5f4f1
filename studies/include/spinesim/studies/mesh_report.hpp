// Readable and JSON forms of a mesh quality report (shared by `mesh`, `fem` and `demo`).
#pragma once

#include "spinesim/mesh/quality.hpp"

#include <nlohmann/json.hpp>

#include <ostream>
#include <string>

namespace spinesim::studies {

nlohmann::json quality_json(const mesh::QualityReport& q);
void print_quality(std::ostream& os, const mesh::QualityReport& q, const std::string& title);

}  // namespace spinesim::studies

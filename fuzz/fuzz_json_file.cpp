// libFuzzer target: the one JSON file reader (size and depth bounds, strict parsing) and the
// material parser behind it, on arbitrary bytes. Every input must be read or refused with
// std::invalid_argument; anything else is a finding.
#include "fuzz_input.hpp"
#include "spinesim/common/input_file.hpp"
#include "spinesim/mesh/material.hpp"

#include <cstdint>
#include <cstdio>
#include <stdexcept>
#include <string>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string path = spinesim::fuzz::input_file("json", data, size);
  try {
    const nlohmann::json j = spinesim::read_json_file(path, "fuzz input");
    (void)spinesim::mesh::material_from_json(j);
  } catch (const std::invalid_argument&) {}
  return 0;
}

// libFuzzer target: the one JSON file reader (size and depth bounds, strict parsing, no key
// twice) and the parsers behind it — a material, and a disc-joints file applied to the spine
// model — on arbitrary bytes. Every input must be read or refused with std::invalid_argument (the
// spine model's broken-data contract: std::runtime_error); anything else is a finding.
#include "fuzz_input.hpp"
#include "spinesim/common/input_file.hpp"
#include "spinesim/mesh/material.hpp"
#include "spinesim/spine/model.hpp"

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
  try {
    spinesim::spine::ModelOptions o;
    o.disc_joints = path;
    (void)spinesim::spine::load_spine_model(SPINESIM_DATA_DIR, o);
  } catch (const std::invalid_argument&) {
  } catch (const std::runtime_error&) {}
  return 0;
}

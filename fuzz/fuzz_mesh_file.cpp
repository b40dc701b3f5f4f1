// libFuzzer target: the tetrahedral mesh readers (VTU in every encoding, legacy .vtk) on
// arbitrary bytes. Every input must be read or refused with std::invalid_argument /
// std::runtime_error; a crash, a hang, a leak or undefined behaviour is a finding.
#include "fuzz_input.hpp"
#include "spinesim/mesh/io.hpp"

#include <cstdint>
#include <cstdio>
#include <stdexcept>
#include <string>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string path = spinesim::fuzz::input_file("mesh", data, size);
  try {
    (void)spinesim::mesh::read_tet_mesh(path);
  } catch (const std::invalid_argument&) {
  } catch (const std::runtime_error&) {}
  return 0;
}

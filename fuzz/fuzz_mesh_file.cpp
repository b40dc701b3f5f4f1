// libFuzzer target: the tetrahedral mesh readers (VTU in every encoding, legacy .vtk) on
// arbitrary bytes. Every input must be read or refused with std::invalid_argument /
// std::runtime_error; a crash, a hang, a leak or undefined behaviour is a finding.
#include "spinesim/mesh/io.hpp"

#include <unistd.h>

#include <cstdint>
#include <cstdio>
#include <stdexcept>
#include <string>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static const std::string path = "/tmp/spinesim-fuzz-mesh-" + std::to_string(::getpid());
  if (std::FILE* f = std::fopen(path.c_str(), "wb")) {
    std::fwrite(data, 1, size, f);
    std::fclose(f);
  }
  try {
    (void)spinesim::mesh::read_tet_mesh(path);
  } catch (const std::invalid_argument&) {
  } catch (const std::runtime_error&) {}
  return 0;
}

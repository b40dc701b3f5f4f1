// The fuzz targets' input as a file: the readers under test take paths, as the program gives
// them. One file per target process (libFuzzer runs inputs one after another), rewritten for
// each input and removed when the process ends.
#pragma once

#include <unistd.h>

#include <cstdint>
#include <cstdio>
#include <string>

namespace spinesim::fuzz {

/// Writes `size` bytes to "/tmp/spinesim-fuzz-<tag>-<pid><suffix>" and returns that path.
inline std::string input_file(const std::string& tag, const std::uint8_t* data, std::size_t size,
                              const std::string& suffix = "") {
  const std::string path = "/tmp/spinesim-fuzz-" + tag + "-" + std::to_string(::getpid()) + suffix;
  struct Remover {
    std::string path;
    ~Remover() { std::remove(path.c_str()); }
  };
  static Remover last{path};
  if (last.path != path) std::remove(last.path.c_str()), last.path = path;
  if (std::FILE* f = std::fopen(path.c_str(), "wb")) {
    std::fwrite(data, 1, size, f);
    std::fclose(f);
  }
  return path;
}

}  // namespace spinesim::fuzz

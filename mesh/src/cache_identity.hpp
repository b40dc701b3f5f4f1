// What the disk caches of generated meshes key their files by: a 64-bit FNV-1a hash of the
// key's text, and the running program's identity (its executable's size and modification
// time: a rebuilt or updated program retires the files of the old one).
#pragma once

#include <sys/stat.h>

#include <cstdint>
#include <string>

namespace spinesim::mesh::detail {

inline std::uint64_t fnv1a(const std::string& s) {
  std::uint64_t h = 14695981039346656037ull;
  for (const unsigned char c : s) {
    h ^= c;
    h *= 1099511628211ull;
  }
  return h;
}

inline std::string program_identity() {
  struct stat st {};
  if (::stat("/proc/self/exe", &st) != 0) return "unknown-program";
  return std::to_string(st.st_size) + ":" + std::to_string(st.st_mtim.tv_sec) + "." +
         std::to_string(st.st_mtim.tv_nsec);
}

}  // namespace spinesim::mesh::detail

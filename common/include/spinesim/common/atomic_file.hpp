// Writing a file so that `path` either gets the complete new content or is left untouched
// (every writer of the project: meshes, tuned discs, databases, reports). The content goes to `path + ".tmp-XXXXXX"` (same folder, so the
// rename is atomic on POSIX file systems), is flushed and checked, then renamed over `path`.
// On any failure the temporary file is removed and the exception propagates.
#pragma once

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <stdexcept>
#include <string>
#include <vector>

#include <sys/stat.h>
#include <unistd.h>

namespace spinesim {

/// Calls `fill(std::ostream&)` on a temporary file next to `path`, then renames it to `path`.
/// `who` prefixes the error messages (e.g. "write_vtu"). Throws std::runtime_error when the
/// operating system refuses (folder missing, permission, disk full).
template <class Fill>
void write_atomically(const std::string& who, const std::string& path, Fill&& fill) {
  std::string tmpl = path + ".tmp-XXXXXX";
  std::vector<char> name(tmpl.begin(), tmpl.end());
  name.push_back('\0');
  const int fd = ::mkstemp(name.data());
  if (fd < 0)
    throw std::runtime_error(who + ": " + path + ": cannot create a file there (" +
                             std::strerror(errno) + ")");
  ::fchmod(fd, 0644);  // mkstemp makes 0600; results are meant to be shared
  ::close(fd);
  const std::string tmp(name.data());
  try {
    {
      std::ofstream os(tmp, std::ios::binary | std::ios::trunc);
      if (!os) throw std::runtime_error(who + ": " + path + ": cannot open the temporary file");
      fill(os);
      os.flush();
      if (!os) throw std::runtime_error(who + ": " + path + ": write failed (disk full?)");
    }
    if (std::rename(tmp.c_str(), path.c_str()) != 0)
      throw std::runtime_error(who + ": " + path + ": cannot replace the file (" +
                               std::strerror(errno) + ")");
  } catch (...) {
    std::remove(tmp.c_str());
    throw;
  }
}

/// Writes `text` to `path` completely or not at all; errors name `path`.
inline void write_text_atomically(const std::string& path, const std::string& text) {
  write_atomically("write", path, [&text](std::ostream& os) { os << text; });
}

}  // namespace spinesim

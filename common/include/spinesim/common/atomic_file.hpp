// Writing a file so that `path` either gets the complete new content or is left untouched
// (every writer of the project: meshes, tuned discs, databases, reports). The content goes to
// `path + ".tmp-XXXXXX"` (same folder, so the rename is atomic on POSIX file systems), is flushed
// and checked, then renamed over `path`. On any failure the temporary file is removed and the
// exception propagates; a run killed meanwhile removes it too (pending_output.hpp). A `path` that
// exists and is not a regular file (a symbolic link, directory, FIFO, socket or device) is never
// replaced: as root, `--out /dev/null` must not turn /dev/null into a file.
#pragma once

#include "spinesim/common/pending_output.hpp"

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <optional>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include <sys/stat.h>
#include <unistd.h>

namespace spinesim {

/// Throws std::invalid_argument "<who>: <path> is <kind>, not a regular file: ..." unless `path`
/// is absent or a regular file (lstat: a symbolic link is refused, not followed).
inline void require_replaceable(const std::string& who, const std::string& path) {
  struct stat st {};
  if (::lstat(path.c_str(), &st) != 0 || S_ISREG(st.st_mode)) return;
  const char* kind = S_ISLNK(st.st_mode)    ? "a symbolic link"
                     : S_ISDIR(st.st_mode)  ? "a directory"
                     : S_ISFIFO(st.st_mode) ? "a FIFO"
                     : S_ISSOCK(st.st_mode) ? "a socket"
                                            : "a device";
  throw std::invalid_argument(who + ": " + path + " is " + kind +
                              ", not a regular file: refusing to replace it (give a file name)");
}

/// Calls `fill(std::ostream&)` on a temporary file next to `path`, then renames it to `path`.
/// `who` prefixes the error messages (e.g. "write_vtu"). Throws std::runtime_error when the
/// operating system refuses (folder missing, permission, disk full).
template <class Fill>
void write_atomically(const std::string& who, const std::string& path, Fill&& fill) {
  require_replaceable(who, path);
  std::string tmpl = path + ".tmp-XXXXXX";
  std::vector<char> name(tmpl.begin(), tmpl.end());
  name.push_back('\0');
  std::optional<SignalBlock> hold;  // no kill between creating the temporary and registering it
  hold.emplace();
  const int fd = ::mkstemp(name.data());
  if (fd < 0)
    throw std::runtime_error(who + ": " + path + ": cannot create a file there (" +
                             std::strerror(errno) + ")");
  ::fchmod(fd, 0644);  // mkstemp makes 0600; results are meant to be shared
  ::close(fd);
  const std::string tmp(name.data());
  PendingOutput pending(tmp);
  hold.reset();
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

/// Several files written together or not at all (a mesh's VTU and its MEDIT copy): each is
/// written to stage(path), a temporary name beside it; commit() renames them all onto their
/// paths, with the catchable signals held back so that a kill cannot split the set; a set
/// destroyed before commit() — or a run killed before it — removes what it staged. Every path is
/// checked with require_replaceable first.
class OutputSet {
 public:
  explicit OutputSet(std::string who) : who_(std::move(who)) {}
  OutputSet(const OutputSet&) = delete;
  OutputSet& operator=(const OutputSet&) = delete;
  ~OutputSet() {
    for (const auto& [tmp, path] : staged_) std::remove(tmp.c_str());
  }
  /// The temporary name to write `path`'s content to.
  std::string stage(const std::string& path) {
    require_replaceable(who_, path);
    std::string tmp = path + ".staged-" + std::to_string(::getpid());
    staged_.emplace_back(tmp, path);
    pending_.emplace_back(tmp);
    return tmp;
  }
  void commit() {
    const SignalBlock whole;
    for (const auto& [tmp, path] : staged_)
      if (std::rename(tmp.c_str(), path.c_str()) != 0)
        throw std::runtime_error(who_ + ": " + path + ": cannot replace the file (" +
                                 std::strerror(errno) + ")");
    staged_.clear();
    pending_.clear();
  }

 private:
  std::string who_;
  std::vector<std::pair<std::string, std::string>> staged_;  ///< (temporary, final)
  std::vector<PendingOutput> pending_;                       ///< the temporaries, until commit
};

/// Writes `text` to `path` completely or not at all; errors name `path`.
inline void write_text_atomically(const std::string& path, const std::string& text) {
  write_atomically("write", path, [&text](std::ostream& os) { os << text; });
}

}  // namespace spinesim

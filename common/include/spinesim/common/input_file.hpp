// Reading an input file safely: only a regular file is read (a directory, FIFO, socket or device
// is refused by name instead of blocking or failing obscurely), its size is bounded, and every
// error names the file and the real cause in one line. JSON inputs (materials, tuned discs, the
// spine model, databases) are also bounded in nesting depth, so a hostile file cannot exhaust the
// stack of the parser or of the value's destructor, and are parsed strictly (nothing after the
// value, no key twice in one object; require_known_keys refuses fields a reader does not know). Every JSON file the project reads goes through read_json_file.
#pragma once

#include "spinesim/common/provenance.hpp"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cerrno>
#include <cstddef>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <string>
#include <vector>

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

namespace spinesim {

/// Limits of read_regular_file and read_json_file.
struct InputLimits {
  std::size_t max_bytes = std::size_t(1) << 30;  ///< 1 GiB
  int max_json_depth = 64;                       ///< nested arrays/objects
};

/// What a path names, for messages: "a directory", "a FIFO", "a device", "a socket", "a symbolic
/// link" (from lstat when `follow` is false), "a regular file", or "" when it does not exist.
inline std::string path_kind(const std::string& path, bool follow = true) {
  struct stat st {};
  if ((follow ? ::stat(path.c_str(), &st) : ::lstat(path.c_str(), &st)) != 0) return "";
  if (S_ISREG(st.st_mode)) return "a regular file";
  if (S_ISDIR(st.st_mode)) return "a directory";
  if (S_ISFIFO(st.st_mode)) return "a FIFO";
  if (S_ISSOCK(st.st_mode)) return "a socket";
  if (S_ISLNK(st.st_mode)) return "a symbolic link";
  return "a device";
}

/// The whole content of the regular file `path`. Throws std::invalid_argument "cannot read
/// <what> '<path>': <cause>" — no such file, not a regular file (named), too large, or the
/// system's reason.
inline std::string read_regular_file(const std::string& path, const std::string& what,
                                     const InputLimits& limits = InputLimits()) {
  const auto refuse = [&](const std::string& cause) {
    return std::invalid_argument("cannot read " + what + " '" + path + "': " + cause);
  };
  // O_NONBLOCK: opening a FIFO with no writer must not block; it is refused below anyway.
  const int fd = ::open(path.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC);
  if (fd < 0) throw refuse(errno == ENOENT ? "no such file" : std::strerror(errno));
  struct stat st {};
  if (::fstat(fd, &st) != 0 || !S_ISREG(st.st_mode)) {
    ::close(fd);
    throw refuse("it is " + path_kind(path) + ", not a regular file");
  }
  if (std::size_t(st.st_size) > limits.max_bytes) {
    ::close(fd);
    throw refuse("it has " + std::to_string(st.st_size) + " bytes, more than the limit of " +
                 std::to_string(limits.max_bytes));
  }
  std::string text(std::size_t(st.st_size), '\0');
  std::size_t done = 0;
  while (done < text.size()) {
    const ssize_t n = ::read(fd, &text[done], text.size() - done);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) break;
    done += std::size_t(n);
  }
  ::close(fd);
  text.resize(done);  // a file that shrank while read: what was there
  record_input_file(path);
  return text;
}

/// The regular file `path` opened for reading line by line (a large input is streamed, not held
/// twice in memory), after the checks of read_regular_file: no such file, not a regular file
/// (named), too large. Throws std::invalid_argument "cannot read <what> '<path>': <cause>".
inline std::ifstream open_regular_file(const std::string& path, const std::string& what,
                                       const InputLimits& limits = InputLimits()) {
  const auto refuse = [&](const std::string& cause) {
    return std::invalid_argument("cannot read " + what + " '" + path + "': " + cause);
  };
  struct stat st {};
  if (::stat(path.c_str(), &st) != 0)
    throw refuse(errno == ENOENT ? "no such file" : std::strerror(errno));
  if (!S_ISREG(st.st_mode)) throw refuse("it is " + path_kind(path) + ", not a regular file");
  if (std::size_t(st.st_size) > limits.max_bytes)
    throw refuse("it has " + std::to_string(st.st_size) + " bytes, more than the limit of " +
                 std::to_string(limits.max_bytes));
  std::ifstream in(path, std::ios::binary);
  if (!in) throw refuse(std::strerror(errno));
  record_input_file(path);
  return in;
}

/// The deepest nesting of arrays and objects in JSON text (brackets inside strings ignored).
inline int json_depth(const std::string& text) {
  int depth = 0, deepest = 0;
  bool in_string = false, escaped = false;
  for (const char c : text) {
    if (in_string) {
      if (escaped)
        escaped = false;
      else if (c == '\\')
        escaped = true;
      else if (c == '"')
        in_string = false;
      continue;
    }
    if (c == '"') {
      in_string = true;
    } else if (c == '[' || c == '{') {
      if (++depth > deepest) deepest = depth;
    } else if (c == ']' || c == '}') {
      --depth;
    }
  }
  return deepest;
}

/// The parsed JSON of the regular file `path`: std::invalid_argument naming the file and the
/// cause (see read_regular_file; nested deeper than the limit; not valid JSON, with the parser's
/// position; anything after the value).
inline nlohmann::json read_json_file(const std::string& path, const std::string& what,
                                     const InputLimits& limits = InputLimits()) {
  const std::string text = read_regular_file(path, what, limits);
  const int depth = json_depth(text);
  if (depth > limits.max_json_depth)
    throw std::invalid_argument(what + " '" + path + "' is nested " + std::to_string(depth) +
                                " levels deep (the limit is " +
                                std::to_string(limits.max_json_depth) + "): not a file of ours");
  // Strict: a key given twice in one object is refused (nlohmann keeps the last silently, so a
  // file could say two things and mean one).
  std::vector<std::vector<std::string>> keys;  // per open object
  std::string duplicate;
  const auto strict = [&](int, nlohmann::json::parse_event_t event, nlohmann::json& parsed) {
    using E = nlohmann::json::parse_event_t;
    if (event == E::object_start) keys.emplace_back();
    if (event == E::object_end && !keys.empty()) keys.pop_back();
    if (event == E::key && !keys.empty() && duplicate.empty()) {
      const std::string key = parsed.get<std::string>();
      auto& seen = keys.back();
      if (std::find(seen.begin(), seen.end(), key) != seen.end())
        duplicate = key;
      else
        seen.push_back(key);
    }
    return true;
  };
  try {
    nlohmann::json j = nlohmann::json::parse(text, strict);
    if (!duplicate.empty())
      throw std::invalid_argument(what + " '" + path + "' gives the key \"" + duplicate +
                                  "\" twice in one object");
    return j;
  } catch (const nlohmann::json::parse_error& e) {
    throw std::invalid_argument(what + " '" + path + "' is not valid JSON (byte " +
                                std::to_string(e.byte) + ")");
  } catch (const nlohmann::json::exception& e) {  // a number beyond double's range (1e400)
    std::string why = e.what();  // "[json.exception.out_of_range.406] number overflow ...'"
    if (why.find("] ") != std::string::npos) why = why.substr(why.find("] ") + 2);
    throw std::invalid_argument(what + " '" + path + "' cannot be read: " + why);
  }
}

/// Refuses (std::invalid_argument naming `where` and the key) a key of the object `j` that is not
/// one of `known`: a misspelt or misplaced field is an error, not a silently ignored line.
inline void require_known_keys(const nlohmann::json& j, const std::vector<std::string>& known,
                               const std::string& where) {
  if (!j.is_object()) return;
  for (const auto& item : j.items())
    if (std::find(known.begin(), known.end(), item.key()) == known.end()) {
      std::string list;
      for (const auto& k : known) list += (list.empty() ? "" : ", ") + k;
      throw std::invalid_argument(where + ": unknown field \"" + item.key() + "\" (known: " + list +
                                  ")");
    }
}

/// A preset name or a path: `name_or_path` itself when it exists, else `folder`/NAME.json. Neither:
/// std::invalid_argument "unknown WHAT 'NAME' (no such file; presets: a, b)", the presets being
/// the .json files of `folder` in name order.
inline std::string resolve_preset(const std::string& name_or_path, const std::string& folder,
                                  const std::string& what) {
  namespace fs = std::filesystem;
  if (fs::exists(name_or_path)) return name_or_path;
  const fs::path preset = fs::path(folder) / (name_or_path + ".json");
  if (fs::exists(preset)) return preset.string();
  std::vector<std::string> names;
  if (fs::is_directory(folder))
    for (const auto& e : fs::directory_iterator(folder))
      if (e.path().extension() == ".json") names.push_back(e.path().stem().string());
  std::sort(names.begin(), names.end());
  std::string known;
  for (const auto& n : names) known += (known.empty() ? "" : ", ") + n;
  throw std::invalid_argument("unknown " + what + " '" + name_or_path +
                              "' (no such file; presets: " + known + ")");
}

}  // namespace spinesim

// Where a run's outputs came from: the program (version and commit, build_info.hpp), the command
// line and working folder that ran it, and every input file it read (path, size, SHA-256).
//
// The program records its command line once at start (record_run_command); the input readers
// record the files they read (record_input_file: read_regular_file and open_regular_file, the
// mesh and CSV readers); every writer of an output kind — VTU field data, JSON, the CSV header
// line, the reports — writes run_provenance(). Outside a recorded run (a unit test, a library
// user who never called record_run_command) run_provenance() is null and writers add nothing.
//
// No clock time is recorded: the same command on the same inputs writes the same bytes, so two
// runs' outputs can be compared file for file (the file's own time says when).
#pragma once

#include "spinesim/common/build_info.hpp"

#include <nlohmann/json.hpp>
#include <openssl/evp.h>

#include <cstdint>
#include <filesystem>
#include <fstream>
#include <map>
#include <memory>
#include <mutex>
#include <stdexcept>
#include <string>
#include <vector>

namespace spinesim {

/// The lowercase hex SHA-256 of the file `path` (libcrypto); "" when it cannot be read.
inline std::string sha256_of_file(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return "";
  std::unique_ptr<EVP_MD_CTX, decltype(&EVP_MD_CTX_free)> ctx(EVP_MD_CTX_new(), EVP_MD_CTX_free);
  if (!ctx || EVP_DigestInit_ex(ctx.get(), EVP_sha256(), nullptr) != 1) return "";
  std::vector<char> buffer(1 << 16);
  while (in) {
    in.read(buffer.data(), std::streamsize(buffer.size()));
    if (in.gcount() > 0 && EVP_DigestUpdate(ctx.get(), buffer.data(), std::size_t(in.gcount())) != 1)
      return "";
  }
  if (in.bad()) return "";
  unsigned char digest[EVP_MAX_MD_SIZE];
  unsigned int length = 0;
  if (EVP_DigestFinal_ex(ctx.get(), digest, &length) != 1) return "";
  static const char* hex = "0123456789abcdef";
  std::string out;
  for (unsigned int i = 0; i < length; ++i) {
    out += hex[digest[i] >> 4];
    out += hex[digest[i] & 15];
  }
  return out;
}

/// `arg` quoted for a POSIX shell when it needs it (a space, a quote, a `$` …), so that the
/// recorded command line can be pasted back into a shell.
inline std::string shell_quoted(const std::string& arg) {
  if (!arg.empty() &&
      arg.find_first_not_of("abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789"
                            "-_./=,:+@%") == std::string::npos)
    return arg;
  std::string q = "'";
  for (const char c : arg) q += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return q + "'";
}

namespace detail {

struct InputRecord {
  std::string absolute;  ///< the key: one entry per file
  std::uintmax_t bytes = 0;
  std::filesystem::file_time_type written{};
  std::string sha256;  ///< computed when first asked for, again when the file changed
};

struct RunRecord {
  std::mutex mutex;
  bool recorded = false;
  std::vector<std::string> arguments;
  std::string working_directory;
  std::vector<InputRecord> inputs;  ///< in the order first read
};

/// `absolute` relative to the run's working folder when it is inside it, else as it is: short,
/// and unambiguous even after the run changed folder (`spinesim run` works in the study's).
inline std::string shown_path(const std::string& absolute, const std::string& working_directory) {
  const std::filesystem::path rel =
      std::filesystem::path(absolute).lexically_relative(working_directory);
  if (working_directory.empty() || rel.empty() || *rel.begin() == "..") return absolute;
  return rel.string();
}

inline RunRecord& run_record() {
  static RunRecord r;
  return r;
}

}  // namespace detail

/// Records the command that runs this process (argv as given) and the working folder, and starts
/// the list of inputs afresh (a process that runs several commands, such as the Python module,
/// records each).
inline void record_run_command(int argc, const char* const* argv) {
  auto& r = detail::run_record();
  std::lock_guard<std::mutex> lock(r.mutex);
  r.recorded = true;
  r.arguments.assign(argv, argv + argc);
  r.inputs.clear();
  std::error_code ec;
  r.working_directory = std::filesystem::current_path(ec).string();
}

/// Whether record_run_command was called: outputs then carry their provenance.
inline bool run_recorded() {
  auto& r = detail::run_record();
  std::lock_guard<std::mutex> lock(r.mutex);
  return r.recorded;
}

/// Records that the run read the file `path` (once per file; a file that does not exist is not
/// recorded). Cheap: the hash is taken when an output asks for the provenance.
inline void record_input_file(const std::string& path) {
  namespace fs = std::filesystem;
  std::error_code ec;
  const fs::path absolute = fs::absolute(path, ec).lexically_normal();
  if (ec || !fs::is_regular_file(absolute, ec)) return;
  auto& r = detail::run_record();
  std::lock_guard<std::mutex> lock(r.mutex);
  for (const auto& in : r.inputs)
    if (in.absolute == absolute.string()) return;
  detail::InputRecord in;
  in.absolute = absolute.string();
  r.inputs.push_back(std::move(in));
}

/// The provenance of this run's outputs, or null outside a recorded run:
///   {"program": "spinesim", "version": "0.1.0", "commit": "<sha>[-dirty]",
///    "command": "spinesim fem --mesh disc.vtu …" (shell-quoted), "arguments": [argv …],
///    "working_directory": "/…",
///    "inputs": [{"path": "<relative to working_directory, or absolute>", "bytes": n,
///                "sha256": "<hex>"}, …]}  (in the order first read)
inline nlohmann::json run_provenance() {
  namespace fs = std::filesystem;
  auto& r = detail::run_record();
  std::lock_guard<std::mutex> lock(r.mutex);
  if (!r.recorded) return nullptr;
  nlohmann::json inputs = nlohmann::json::array();
  for (auto& in : r.inputs) {
    std::error_code ec;
    const auto bytes = fs::file_size(in.absolute, ec);
    const auto written = fs::last_write_time(in.absolute, ec);
    if (ec) {
      inputs.push_back({{"path", detail::shown_path(in.absolute, r.working_directory)},
                        {"bytes", nullptr},
                        {"sha256", nullptr}});
      continue;
    }
    if (in.sha256.empty() || bytes != in.bytes || written != in.written) {
      in.sha256 = sha256_of_file(in.absolute);
      in.bytes = bytes;
      in.written = written;
    }
    inputs.push_back({{"path", detail::shown_path(in.absolute, r.working_directory)},
                      {"bytes", in.bytes},
                      {"sha256", in.sha256}});
  }
  std::string command;
  for (const auto& a : r.arguments) command += (command.empty() ? "" : " ") + shell_quoted(a);
  return {{"program", "spinesim"},
          {"version", build_version()},
          {"commit", build_commit()},
          {"command", command},
          {"arguments", r.arguments},
          {"working_directory", r.working_directory},
          {"inputs", std::move(inputs)}};
}

/// The provenance as the first line of a CSV file, "# provenance: {…}\n" (one line of compact
/// JSON after the comment mark; "" outside a recorded run). CSV readers that skip '#' lines
/// (ours, numpy.loadtxt, pandas with comment='#', gnuplot) read the table as before.
inline std::string csv_provenance_line() {
  const nlohmann::json p = run_provenance();
  if (p.is_null()) return "";
  return "# provenance: " + p.dump() + "\n";
}

/// `j` with the run's provenance under "provenance" when `j` is an object and a run is
/// recorded; `j` unchanged otherwise.
inline nlohmann::json with_provenance(nlohmann::json j) {
  if (!j.is_object()) return j;
  nlohmann::json p = run_provenance();
  if (!p.is_null()) j["provenance"] = std::move(p);
  return j;
}

}  // namespace spinesim

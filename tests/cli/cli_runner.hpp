// Running the `spinesim` program from a test: a per-process temp folder, capture of stdout,
// stderr and exit status, and the "refused bad input" check every CLI suite makes.
#pragma once

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>
#include <string>

namespace spinesim::test_cli {

namespace fs = std::filesystem;

/// ctest runs each test in its own process, in parallel: every process gets its own folder.
inline fs::path tmp_dir() {
  static const fs::path dir = fs::path(SPINESIM_TEST_TMP) / ("cli-" + std::to_string(getpid()));
  fs::create_directories(dir);
  return dir;
}

/// A fresh path in tmp_dir() (whatever was there is removed).
inline std::string tmp(const std::string& name) {
  const fs::path p = tmp_dir() / name;
  fs::remove_all(p);
  return p.string();
}

inline std::string slurp(const std::string& path) {
  std::ifstream is(path);
  std::stringstream ss;
  ss << is.rdbuf();
  return ss.str();
}

/// Writes `text` to `path`.
inline void spit(const std::string& path, const std::string& text) {
  std::ofstream os(path, std::ios::binary);
  os << text;
}

/// Whether Debian's python3-jsonschema is installed (the independent schema validator).
inline bool has_jsonschema() {
  return fs::exists("/usr/bin/python3") &&
         std::system("/usr/bin/python3 -c 'import jsonschema' >/dev/null 2>&1") == 0;
}

/// Debian's jsonschema on the JSON file `document` against the schema file: true when valid.
inline bool schema_accepts(const std::string& schema, const std::string& document) {
  const std::string cmd =
      "/usr/bin/python3 -c 'import json,sys,jsonschema; jsonschema.validate("
      "json.load(open(sys.argv[2])), json.load(open(sys.argv[1])))' '" +
      schema + "' '" + document + "' >/dev/null 2>&1";
  return std::system(cmd.c_str()) == 0;
}

/// The table of a CSV file the program wrote, after checking its first line: the provenance,
/// "# provenance: {…}" with the program, its commit and the command line.
inline std::string csv_table(const std::string& path) {
  const std::string text = slurp(path);
  const std::string mark = "# provenance: ";
  const auto end = text.find('\n');
  EXPECT_EQ(text.rfind(mark, 0), 0u) << path << " has no provenance line";
  if (text.rfind(mark, 0) != 0 || end == std::string::npos) return text;
  const nlohmann::json p = nlohmann::json::parse(text.substr(mark.size(), end - mark.size()));
  EXPECT_EQ(p.at("program"), "spinesim") << path;
  EXPECT_FALSE(p.at("commit").get<std::string>().empty()) << path;
  EXPECT_NE(p.at("command").get<std::string>().find("spinesim"), std::string::npos) << path;
  return text.substr(end + 1);
}

struct CliRun {
  int status = -1;
  std::string out, err;
};

/// Runs spinesim with `args` (shell words), capturing stdout and stderr; `before` is shell text
/// run first in the same shell (e.g. "ulimit -v 600000; ").
inline CliRun run_spinesim(const std::string& args, const std::string& before = "") {
  const fs::path out = tmp_dir() / "cli.stdout", err = tmp_dir() / "cli.stderr";
  const std::string cmd = before + "'" + SPINESIM_EXE + "' " + args + " >'" + out.string() +
                          "' 2>'" + err.string() + "' </dev/null";
  const int raw = std::system(cmd.c_str());
  CliRun r;
  r.status = WIFEXITED(raw) ? WEXITSTATUS(raw) : -1;
  r.out = slurp(out.string());
  r.err = slurp(err.string());
  return r;
}

/// The files a run added to tmp_dir() (besides the runner's own stdout/stderr captures and
/// `expected`, which may be empty): `before` is files_in(tmp_dir()) taken before the run.
inline std::set<std::string> files_in(const fs::path& dir) {
  std::set<std::string> out;
  for (const auto& e : fs::recursive_directory_iterator(dir)) out.insert(e.path().string());
  return out;
}
inline std::set<std::string> new_files(const std::set<std::string>& before,
                                       const std::string& expected = "") {
  std::set<std::string> after = files_in(tmp_dir());
  for (const auto& f : {tmp_dir() / "cli.stdout", tmp_dir() / "cli.stderr"})
    after.erase(f.string());
  if (!expected.empty()) after.erase(expected);
  for (const auto& f : before) after.erase(f);
  return after;
}

inline int count_lines(const std::string& s) { return int(std::count(s.begin(), s.end(), '\n')); }

/// Starts spinesim with `args` in the background (stdout and stderr to bg.stdout and bg.stderr
/// in tmp_dir()); `before` is shell text put before the command (e.g. "VAR=1 "). Returns its pid.
inline pid_t start_spinesim(const std::string& args, const std::string& before = "") {
  const std::string out = (tmp_dir() / "bg.stdout").string(),
                    err = (tmp_dir() / "bg.stderr").string();
  const std::string cmd =
      before + "exec '" + SPINESIM_EXE + "' " + args + " >'" + out + "' 2>'" + err + "' </dev/null";
  const pid_t pid = ::fork();
  if (pid == 0) {
    ::execl("/bin/sh", "sh", "-c", cmd.c_str(), static_cast<char*>(nullptr));
    ::_exit(127);
  }
  return pid;
}

/// A refused run: exit status 1, exactly one line on stderr mentioning `needle`, nothing on stdout.
inline void expect_refused(const CliRun& r, const std::string& needle) {
  EXPECT_EQ(r.status, 1) << r.err;
  EXPECT_EQ(count_lines(r.err), 1) << r.err;
  EXPECT_NE(r.err.find(needle), std::string::npos) << "stderr: " << r.err;
  EXPECT_TRUE(r.out.empty()) << r.out;
}

}  // namespace spinesim::test_cli

#include "spinesim/output/html_report.hpp"

#include <sys/wait.h>
#include <array>
#include <cstdio>
#include <filesystem>
#include <string>

namespace spinesim::output {

namespace {

namespace fs = std::filesystem;

constexpr const char* kPython = "/usr/bin/python3";  // Debian's, where the apt packages are

/// `s` as one single-quoted shell word.
std::string shell_quote(const std::string& s) {
  std::string q = "'";
  for (const char c : s) q += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return q + "'";
}

/// The last non-empty line of `text`.
std::string last_line(const std::string& text) {
  std::string line, last;
  for (const char c : text) {
    if (c == '\n') {
      if (!line.empty()) last = line;
      line.clear();
    } else {
      line += c;
    }
  }
  return line.empty() ? last : line;
}

}  // namespace

HtmlReport write_html_report(const std::string& folder, const std::string& script_name) {
  HtmlReport r;
  r.path = (fs::path(folder) / "report.html").string();
  const fs::path script = fs::path(SPINESIM_SCRIPTS_DIR) / script_name;
  if (!fs::exists(kPython)) {
    r.message = std::string("report.html not written: ") + kPython +
                " is missing (apt-get install python3 python3-matplotlib python3-markdown)";
    return r;
  }
  if (!fs::exists(script)) {
    r.message = "report.html not written: the report script " + script.string() + " is missing";
    return r;
  }
  std::error_code ec;
  fs::remove(r.path, ec);  // a stale report must not pass for a new one
  const std::string command = std::string(kPython) + " " + shell_quote(script.string()) + " " +
                              shell_quote(folder) + " 2>&1";
  std::string output;
  if (FILE* pipe = ::popen(command.c_str(), "r")) {
    std::array<char, 512> buffer{};
    while (std::fgets(buffer.data(), int(buffer.size()), pipe)) output += buffer.data();
    const int status = ::pclose(pipe);
    r.written = status == 0 && fs::exists(r.path);
    r.failed = !r.written && !(WIFEXITED(status) && WEXITSTATUS(status) == 2);
  }
  r.message = last_line(output);
  if (r.message.empty()) r.message = "report.html not written: the report script said nothing";
  return r;
}

}  // namespace spinesim::output

// The `spinesim` command line as a function: what main() runs, and what the Python module runs
// in-process (spinesim.main, spinesim.run_study).
#pragma once

#include <string>
#include <vector>

namespace spinesim::cli {

/// Parses and runs one command line (`args` without the program's name: {"fem", "--mesh", …}).
/// Records it as the run's command (provenance.hpp; inputs read by an earlier run in the process
/// are forgotten). Throws what the verb throws: std::invalid_argument for refused input (a
/// malformed command line included, with the nearest valid verb or flag), another std::exception
/// when the work ran and failed. --help and --version print and return normally.
void execute_command_line(const std::vector<std::string>& args);

/// execute_command_line as the program does it: every error one line on stderr ("spinesim: error:
/// …"), a failed run with --json still one JSON object on stdout; returns the exit status (0, or 1).
int run_command_line(const std::vector<std::string>& args);

}  // namespace spinesim::cli

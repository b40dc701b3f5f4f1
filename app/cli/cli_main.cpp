#include "cli_main.hpp"

#include "cli_common.hpp"
#include "study_file.hpp"
#include "suggest.hpp"

#include "spinesim/common/provenance.hpp"

#include <iostream>
#include <memory>
#include <new>

namespace spinesim::cli {
namespace {

/// --json among the arguments (before a "--").
bool asked_for_json(const std::vector<std::string>& args) {
  for (const auto& a : args) {
    if (a == "--") return false;
    if (a == "--json") return true;
  }
  return false;
}

/// How CLI11 ended a parse that is not an error (--help, --version): prints it, true; false for
/// a real parse error.
bool printed_help(CLI::App& app, const CLI::ParseError& e) {
  if (dynamic_cast<const CLI::CallForHelp*>(&e) || dynamic_cast<const CLI::CallForAllHelp*>(&e) ||
      dynamic_cast<const CLI::CallForVersion*>(&e)) {
    app.exit(e);
    return true;
  }
  return false;
}

}  // namespace

void execute_command_line(const std::vector<std::string>& args) {
  std::vector<const char*> argv{"spinesim"};
  for (const auto& a : args) argv.push_back(a.c_str());
  record_run_command(int(argv.size()), argv.data());  // every output says what made it
  output::reset_json_printed();
  const std::unique_ptr<CLI::App> program = make_app();
  CLI::App& app = *program;
  if (app.get_name().empty()) app.name("spinesim");  // "Usage: spinesim fem [OPTIONS]"
  try {
    std::vector<std::string> reversed(args.rbegin(), args.rend());  // CLI11 parses from the back
    app.parse(reversed);
  } catch (const CLI::ParseError& e) {
    if (printed_help(app, e)) return;
    // A mistyped verb or flag gets the nearest valid one.
    const std::string hint = suggest(app, args);
    throw std::invalid_argument((hint.empty() ? std::string(e.what()) : hint) + " (see --help)");
  }
  save_study_if_asked(app);
}

int run_command_line(const std::vector<std::string>& args) {
  try {
    execute_command_line(args);
  } catch (const std::bad_alloc&) {
    std::cerr << "spinesim: error: out of memory: the input asks for more than this machine has "
                 "(a finer resolution or a larger surface than intended?)"
              << std::endl;
    return 1;
  } catch (const std::invalid_argument& e) {
    // Refused input: one line on stderr, nothing on stdout. The error is always the last line,
    // and one line: a newline in a user's string (a case or material name) is folded into it.
    std::cerr << "spinesim: error: " << one_line(e.what()) << std::endl;
    return 1;
  } catch (const std::exception& e) {
    // The work ran and failed (no convergence, a diverged run, a full disk): with --json the
    // program's answer is still one JSON object, saying that it failed and why.
    const std::string why = one_line(e.what());
    if (asked_for_json(args) && !json_printed())
      print_json({{"ok", false}, {"converged", false}, {"error", why}});
    std::cerr << "spinesim: error: " << why << std::endl;
    return 1;
  }
  return 0;
}

}  // namespace spinesim::cli

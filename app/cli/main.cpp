// spinesim — finite-element-validated intervertebral-disc deformation.
//
//   spinesim mesh disc --level L4-L5 --out disc.vtu
//   spinesim fem --mesh disc.vtu --material real-disc --motion 0,-0.1,0,0,0,0
//   spinesim mss --mesh disc.vtu --case compression; spinesim mss compare --mesh disc.vtu
//   spinesim calibrate --mesh disc.vtu --out tuned.json; spinesim mss --mesh disc.vtu --params tuned.json
//   spinesim study probe; spinesim study drive; spinesim study materials
//   spinesim demo --out demo-out
//
// Every verb has --help and --json (one JSON object on stdout). Bad input, a malformed command
// line included: one line on stderr, exit status 1, no partial output file.
#include "cli_common.hpp"
#include "study_file.hpp"
#include "suggest.hpp"

#include "spinesim/common/memory.hpp"
#include "spinesim/common/pending_output.hpp"
#include "spinesim/common/provenance.hpp"

#include <cstdlib>
#include <iostream>
#include <memory>
#include <new>
#include <string>
#include <vector>

// OpenBLAS (under supernodal CHOLMOD) busy-waits its worker threads; on 2-core machines any
// other load made a P2 factorisation several times slower with 2 threads than with 1
// (docs/benchmarks.md, "OpenBLAS threads"). One thread unless the user sets OPENBLAS_NUM_THREADS.
extern "C" void openblas_set_num_threads(int) __attribute__((weak));

namespace {

/// --json among the arguments (before a "--").
bool asked_for_json(int argc, char** argv) {
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--") return false;
    if (a == "--json") return true;
  }
  return false;
}

}  // namespace

int main(int argc, char** argv) {
  spinesim::keep_freed_memory();  // Newton's large temporaries, reused (common/memory.hpp)
  // A run killed by Ctrl-C, SIGTERM or SIGHUP removes what it had not finished writing.
  spinesim::remove_pending_outputs_on_signals();
  spinesim::record_run_command(argc, argv);  // every output says what made it (provenance.hpp)
  if (openblas_set_num_threads && !std::getenv("OPENBLAS_NUM_THREADS")) openblas_set_num_threads(1);
  const std::unique_ptr<CLI::App> program = spinesim::cli::make_app();
  CLI::App& app = *program;
  try {
    app.parse(argc, argv);
    spinesim::cli::save_study_if_asked(app);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForAllHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForVersion& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    // One line and status 1, like every other error (CLI11's own exit() adds a second line
    // and uses codes such as 104 for a bad number).
    // A mistyped verb or flag gets the nearest valid one.
    const std::string hint =
        spinesim::cli::suggest(app, std::vector<std::string>(argv + 1, argv + argc));
    std::cerr << "spinesim: error: " << spinesim::studies::one_line(hint.empty() ? e.what() : hint)
              << " (see --help)" << std::endl;
    return 1;
  } catch (const std::bad_alloc&) {
    std::cerr << "spinesim: error: out of memory: the input asks for more than this machine has "
                 "(a finer resolution or a larger surface than intended?)"
              << std::endl;
    return 1;
  } catch (const std::invalid_argument& e) {
    // Refused input: one line on stderr, nothing on stdout. The error is always the last line,
    // and one line: a newline in a user's string (a case or material name) is folded into it.
    std::cerr << "spinesim: error: " << spinesim::studies::one_line(e.what()) << std::endl;
    return 1;
  } catch (const std::exception& e) {
    // The work ran and failed (no convergence, a diverged run, a full disk): with --json the
    // program's answer is still one JSON object, saying that it failed and why.
    const std::string why = spinesim::studies::one_line(e.what());
    if (asked_for_json(argc, argv) && !spinesim::studies::json_printed())
      spinesim::studies::print_json({{"ok", false}, {"converged", false}, {"error", why}});
    std::cerr << "spinesim: error: " << why << std::endl;
    return 1;
  }
  return 0;
}

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
#include "cli_main.hpp"

#include "spinesim/common/memory.hpp"
#include "spinesim/common/pending_output.hpp"

#include <cstdlib>
#include <string>
#include <vector>

// OpenBLAS (under supernodal CHOLMOD) busy-waits its worker threads; on 2-core machines any
// other load made a P2 factorisation several times slower with 2 threads than with 1
// (docs/benchmarks.md, "OpenBLAS threads"). One thread unless the user sets OPENBLAS_NUM_THREADS.
extern "C" void openblas_set_num_threads(int) __attribute__((weak));

int main(int argc, char** argv) {
  spinesim::keep_freed_memory();  // Newton's large temporaries, reused (common/memory.hpp)
  // A run killed by Ctrl-C, SIGTERM or SIGHUP removes what it had not finished writing.
  spinesim::remove_pending_outputs_on_signals();
  if (openblas_set_num_threads && !std::getenv("OPENBLAS_NUM_THREADS")) openblas_set_num_threads(1);
  return spinesim::cli::run_command_line(std::vector<std::string>(argv + 1, argv + argc));
}

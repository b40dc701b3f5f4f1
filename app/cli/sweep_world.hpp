// Where a sweep's points run: the ranks of an MPI job (`mpirun -np N spinesim sweep PLAN`), the
// tasks of a Slurm job array (SLURM_ARRAY_TASK_ID, …_MIN, …_COUNT), or one process. Each runs the
// points i with i mod size == rank; the points' outputs are files, so nothing is sent between
// ranks but a barrier before the summary is gathered.
//
// And how one point runs: as a child process (this program, `run STUDY --json`) in its own
// folder, its stdout and stderr to files, so a point that fails or crashes is recorded and the
// others go on.
#pragma once

#include <string>
#include <utility>
#include <vector>

namespace spinesim::cli {

struct SweepWorld {
  std::string kind = "one process";  ///< "one process", "MPI" or "Slurm array"
  int rank = 0, size = 1;
};

/// The world this process is part of. Under mpirun (OpenMPI's OMPI_COMM_WORLD_SIZE or PMIx's
/// PMIX_RANK in the environment) MPI is initialised here, once; a Slurm array task reads its
/// variables (std::invalid_argument, one line, when they are malformed); otherwise one process.
SweepWorld sweep_world();

/// Waits until every rank reached it (MPI), and ends MPI when `last`. Nothing elsewhere.
void sweep_barrier(const SweepWorld& world, bool last);

/// Starts `argv` (argv[0] an executable path) in `folder`, stdout to `out_path`, stderr to
/// `err_path`, and returns its pid. Until it is waited for, a SIGTERM or SIGINT to this process
/// is passed on to it (and stop_requested() turns true). At most 256 at once.
int start_child(const std::vector<std::string>& argv, const std::string& folder,
                const std::string& out_path, const std::string& err_path);

/// Waits for the child `pid` (-1: any started child) and returns its pid and exit status (128 +
/// the signal when a signal ended it).
std::pair<int, int> wait_child(int pid);

/// start_child and wait_child in one.
int run_child(const std::vector<std::string>& argv, const std::string& folder,
              const std::string& out_path, const std::string& err_path);

/// Whether this process was asked to stop (SIGTERM or SIGINT) since install_stop_handlers().
bool stop_requested();
void install_stop_handlers();

/// This program's own path (/proc/self/exe).
std::string own_executable();

}  // namespace spinesim::cli

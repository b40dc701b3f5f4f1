#include "sweep_world.hpp"

#ifdef SPINESIM_HAVE_MPI
#include <mpi.h>
#endif

#include <fcntl.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <csignal>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <stdexcept>

extern char** environ;

namespace spinesim::cli {
namespace {

constexpr int kMostChildren = 256;
volatile std::sig_atomic_t g_stop = 0;
volatile pid_t g_children[kMostChildren] = {};  ///< running children (0: a free slot)

void on_stop(int signal) {
  g_stop = 1;
  for (int i = 0; i < kMostChildren; ++i)
    if (g_children[i] > 0) ::kill(g_children[i], signal);
}

void forget_child(pid_t pid) {
  for (int i = 0; i < kMostChildren; ++i)
    if (g_children[i] == pid) g_children[i] = 0;
}

int exit_status(int status) {
  if (WIFEXITED(status)) return WEXITSTATUS(status);
  if (WIFSIGNALED(status)) return 128 + WTERMSIG(status);
  return 1;
}

/// A Slurm variable as a whole number >= 0 (-1 when unset).
long slurm_number(const char* name) {
  const char* v = std::getenv(name);
  if (!v) return -1;
  char* end = nullptr;
  errno = 0;
  const long n = std::strtol(v, &end, 10);
  if (errno != 0 || end == v || *end != '\0' || n < 0)
    throw std::invalid_argument(std::string(name) + "=" + v + ": not a whole number >= 0");
  return n;
}

bool under_mpirun() {
  return std::getenv("OMPI_COMM_WORLD_SIZE") != nullptr || std::getenv("PMIX_RANK") != nullptr;
}

}  // namespace

SweepWorld sweep_world() {
  SweepWorld w;
  if (under_mpirun()) {
#ifdef SPINESIM_HAVE_MPI
    // Through the profiling names (PMPI_*, which the MPI standard requires of every MPI library):
    // Ipopt's sequential MUMPS brings stub MPI_Init and MPI_Comm_rank symbols that would shadow
    // OpenMPI's, so MPI_Init would do nothing and MPI_Comm_size then abort the job.
    int initialised = 0;
    PMPI_Initialized(&initialised);
    if (!initialised) PMPI_Init(nullptr, nullptr);
    PMPI_Comm_rank(MPI_COMM_WORLD, &w.rank);
    PMPI_Comm_size(MPI_COMM_WORLD, &w.size);
    w.kind = "MPI";
    return w;
#else
    throw std::invalid_argument(
        "run under mpirun, but this spinesim was built without MPI (install libopenmpi-dev and "
        "rebuild)");
#endif
  }
  const long task = slurm_number("SLURM_ARRAY_TASK_ID");
  if (task >= 0) {
    const long first = slurm_number("SLURM_ARRAY_TASK_MIN");
    const long count = slurm_number("SLURM_ARRAY_TASK_COUNT");
    if (first < 0 || count < 1 || task < first || task - first >= count)
      throw std::invalid_argument(
          "SLURM_ARRAY_TASK_ID is set, but SLURM_ARRAY_TASK_MIN and SLURM_ARRAY_TASK_COUNT do not "
          "describe an array holding it (submit with sbatch --array=0-N)");
    w.kind = "Slurm array";
    w.rank = int(task - first);
    w.size = int(count);
  }
  return w;
}

void sweep_barrier(const SweepWorld& world, bool last) {
#ifdef SPINESIM_HAVE_MPI
  if (world.kind != "MPI") return;
  PMPI_Barrier(MPI_COMM_WORLD);
  if (last) PMPI_Finalize();
#else
  (void)world;
  (void)last;
#endif
}

void install_stop_handlers() {
  struct sigaction sa {};
  sa.sa_handler = on_stop;
  sigemptyset(&sa.sa_mask);
  sigaction(SIGTERM, &sa, nullptr);
  sigaction(SIGINT, &sa, nullptr);
}

bool stop_requested() { return g_stop != 0; }

std::string own_executable() {
  std::error_code ec;
  const auto p = std::filesystem::read_symlink("/proc/self/exe", ec);
  if (ec) throw std::runtime_error("cannot find this program's path (/proc/self/exe)");
  return p.string();
}

int start_child(const std::vector<std::string>& argv, const std::string& folder,
                const std::string& out_path, const std::string& err_path) {
  int slot = 0;
  while (slot < kMostChildren && g_children[slot] != 0) ++slot;
  if (slot == kMostChildren)
    throw std::runtime_error("more than " + std::to_string(kMostChildren) + " points at once");
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addchdir_np(&actions, folder.c_str());
  posix_spawn_file_actions_addopen(&actions, STDOUT_FILENO, out_path.c_str(),
                                   O_WRONLY | O_CREAT | O_TRUNC, 0644);
  posix_spawn_file_actions_addopen(&actions, STDERR_FILENO, err_path.c_str(),
                                   O_WRONLY | O_CREAT | O_TRUNC, 0644);
  std::vector<char*> args;
  for (const auto& a : argv) args.push_back(const_cast<char*>(a.c_str()));
  args.push_back(nullptr);
  pid_t pid = 0;
  const int rc = posix_spawn(&pid, args[0], &actions, nullptr, args.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  if (rc != 0) throw std::runtime_error("cannot start " + argv[0] + ": " + std::strerror(rc));
  g_children[slot] = pid;
  if (g_stop) ::kill(pid, SIGTERM);  // asked to stop while it started
  return pid;
}

std::pair<int, int> wait_child(int pid) {
  int status = 0;
  pid_t done = -1;
  while ((done = ::waitpid(pid, &status, 0)) < 0)
    if (errno != EINTR) throw std::runtime_error("waitpid: " + std::string(std::strerror(errno)));
  forget_child(done);
  return {int(done), exit_status(status)};
}

int run_child(const std::vector<std::string>& argv, const std::string& folder,
              const std::string& out_path, const std::string& err_path) {
  return wait_child(start_child(argv, folder, out_path, err_path)).second;
}

}  // namespace spinesim::cli

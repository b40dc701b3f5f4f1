// A run killed by a signal it can catch removes what it had not finished: the handler, run in a
// child process that registers outputs and is then killed, must remove exactly the registered
// files and folders (with their contents), leave everything else, and end the child by the same
// signal. Blocked signals wait until the block ends.
#include "spinesim/common/pending_output.hpp"

#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <csignal>
#include <filesystem>
#include <fstream>
#include <string>
#include <thread>

namespace fs = std::filesystem;

namespace {

fs::path fresh_dir(const std::string& name) {
  const fs::path dir =
      fs::path(SPINESIM_TEST_TMP) / ("pending-" + std::to_string(::getpid())) / name;
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

void touch(const fs::path& p) { std::ofstream(p) << "x"; }

/// Runs `body` in a child process with the handler installed; returns the child's wait status.
template <class Body>
int in_child(Body&& body) {
  const pid_t pid = ::fork();
  if (pid == 0) {
    spinesim::remove_pending_outputs_on_signals();
    body();
    ::_exit(0);  // not killed: a failure the parent sees as exit status 0
  }
  int status = 0;
  ::waitpid(pid, &status, 0);
  return status;
}

}  // namespace

TEST(PendingOutput, AKilledRunRemovesWhatItRegisteredAndNothingElse) {
  for (const int sig : {SIGINT, SIGTERM, SIGHUP, SIGQUIT}) {
    SCOPED_TRACE(sig);
    const fs::path dir = fresh_dir("kill-" + std::to_string(sig));
    const fs::path tmp_file = dir / "out.vtu.tmp-abc123", kept = dir / "earlier.vtu";
    const fs::path frames = dir / "run.staged-1";
    touch(kept);
    const int status = in_child([&] {
      touch(tmp_file);
      fs::create_directory(frames);
      for (int k = 0; k < 300; ++k)  // more entries than one getdents64 buffer holds
        touch(frames / ("run_" + std::to_string(100000 + k) + ".vtu"));
      spinesim::PendingOutput f(tmp_file.string());
      spinesim::PendingOutput d(frames.string(), spinesim::PendingOutput::Kind::folder);
      ::raise(sig);
    });
    ASSERT_TRUE(WIFSIGNALED(status)) << "the child was not killed: status " << status;
    EXPECT_EQ(WTERMSIG(status), sig);
    EXPECT_FALSE(fs::exists(tmp_file));
    EXPECT_FALSE(fs::exists(frames));
    EXPECT_TRUE(fs::exists(kept));
  }
}

TEST(PendingOutput, ReleasedOutputsAreKept) {
  const fs::path dir = fresh_dir("released");
  const fs::path done = dir / "done.vtu";
  const int status = in_child([&] {
    touch(done);
    spinesim::PendingOutput f(done.string());
    f.release();
    ::raise(SIGTERM);
  });
  ASSERT_TRUE(WIFSIGNALED(status));
  EXPECT_TRUE(fs::exists(done));
}

// A signal during a SignalBlock waits for its end: what the block did is complete.
TEST(PendingOutput, ASignalDuringABlockWaitsForItsEnd) {
  const fs::path dir = fresh_dir("block");
  const fs::path a = dir / "a.vtu", b = dir / "b.vtu";
  const int status = in_child([&] {
    spinesim::PendingOutput pa(a.string()), pb(b.string());
    {
      const spinesim::SignalBlock whole;
      ::raise(SIGTERM);  // held back
      touch(a);
      touch(b);
      pa.release();
      pb.release();
    }  // delivered here
    ::_exit(0);
  });
  ASSERT_TRUE(WIFSIGNALED(status));
  EXPECT_EQ(WTERMSIG(status), SIGTERM);
  EXPECT_TRUE(fs::exists(a));
  EXPECT_TRUE(fs::exists(b));
}

// The signal may be delivered to another thread (OpenMP's workers): held all the same.
TEST(PendingOutput, ASignalOnAnotherThreadDuringABlockWaitsToo) {
  const fs::path dir = fresh_dir("block-thread");
  const fs::path a = dir / "a.vtu";
  const int status = in_child([&] {
    spinesim::PendingOutput pa(a.string());
    {
      const spinesim::SignalBlock whole;
      std::thread([] { ::raise(SIGTERM); }).join();  // handled on that thread, held
      touch(a);
      pa.release();
    }
    ::_exit(0);
  });
  ASSERT_TRUE(WIFSIGNALED(status));
  EXPECT_EQ(WTERMSIG(status), SIGTERM);
  EXPECT_TRUE(fs::exists(a));
}

// Every slot taken: further outputs are not tracked (and say so), and freed slots are reused.
TEST(PendingOutput, TheTableIsBoundedAndItsSlotsAreReused) {
  std::vector<spinesim::PendingOutput> held;
  for (std::size_t k = 0; k < spinesim::pending_detail::kSlots; ++k) {
    held.emplace_back("/nonexistent/" + std::to_string(k));
    EXPECT_TRUE(held.back().tracked());
  }
  spinesim::PendingOutput extra("/nonexistent/extra");
  EXPECT_FALSE(extra.tracked());
  held.pop_back();
  spinesim::PendingOutput again("/nonexistent/again");
  EXPECT_TRUE(again.tracked());
}

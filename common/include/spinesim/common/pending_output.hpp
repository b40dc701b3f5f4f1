// Output a run has begun but not finished — a temporary file being written, a file staged for an
// all-or-nothing set, a folder of time-series frames — registered so that a run killed by a
// signal it can catch (Ctrl-C, SIGTERM from a scheduler or `timeout`, SIGHUP when the terminal
// closes, SIGQUIT) removes it on the way out: a killed run leaves no temporary file and no half
// output behind, only what earlier runs had finished.
//
// The program installs the handler once (remove_pending_outputs_on_signals, in main); libraries
// only register and release. The handler is async-signal-safe: it reads a fixed table of paths
// with atomics, removes with unlink/unlinkat/rmdir and raw directory reads (getdents64, no
// allocation), writes one line to stderr, then dies by the same signal so that the parent sees how
// the run ended. SIGKILL cannot be caught: what it can leave is named `*.tmp-XXXXXX`,
// `*.staged-PID` or `<series>.staged-PID/` — never an output's own name, so a later run never
// reads it as output.
//
// Blocking the signals (SignalBlock) makes a short sequence of renames — committing a set — happen
// whole or not at all.
#pragma once

#include <array>
#include <atomic>
#include <csignal>
#include <cstddef>
#include <cstring>
#include <string>

#include <dirent.h>
#include <fcntl.h>
#include <sys/syscall.h>
#include <unistd.h>

namespace spinesim {

namespace pending_detail {

constexpr std::size_t kMaxPath = 4096;
constexpr std::size_t kSlots = 64;  ///< concurrently registered outputs; more are not tracked
enum State : int { kFree = 0, kWriting = 1, kReady = 2 };

struct Slot {
  std::atomic<int> state{kFree};
  bool folder = false;
  char path[kMaxPath] = {};
};

// Namespace-scope and constant-initialised, so that the handler never meets an initialisation
// guard.
inline std::array<Slot, kSlots> g_slots;
inline std::array<Slot, kSlots>& slots() { return g_slots; }

/// SignalBlock's state, process-wide (a signal may be delivered to any thread): how many blocks
/// are open, and the signal that arrived meanwhile.
inline std::atomic<int> g_hold_depth{0};
inline std::atomic<int> g_held_signal{0};

/// The signals a run is killed by and can catch.
constexpr int kSignals[] = {SIGINT, SIGTERM, SIGHUP, SIGQUIT};

/// Removes the entries of a folder that this run owns entirely (no recursion: the folders
/// registered hold files only), then the folder. Async-signal-safe.
inline void remove_folder(const char* path) {
  const int fd = ::open(path, O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (fd >= 0) {
    alignas(8) char buf[4096];
    for (;;) {
      const long n = ::syscall(SYS_getdents64, fd, buf, sizeof buf);
      if (n <= 0) break;
      for (long at = 0; at < n;) {
        // struct linux_dirent64: u64 ino, s64 off, u16 reclen, u8 type, char name[]
        unsigned short reclen = 0;
        std::memcpy(&reclen, buf + at + 16, sizeof reclen);
        const char* name = buf + at + 19;
        if (std::strcmp(name, ".") != 0 && std::strcmp(name, "..") != 0) ::unlinkat(fd, name, 0);
        at += reclen;
      }
    }
    ::close(fd);
  }
  ::rmdir(path);
}

inline void on_signal(int sig) {
  if (g_hold_depth.load() > 0) {  // a SignalBlock is open: act when it ends
    g_held_signal.store(sig);
    return;
  }
  for (Slot& s : slots()) {
    if (s.state.load(std::memory_order_acquire) != kReady) continue;
    if (s.folder)
      remove_folder(s.path);
    else
      ::unlink(s.path);
  }
  const char* name = sig == SIGINT    ? "SIGINT"
                     : sig == SIGTERM ? "SIGTERM"
                     : sig == SIGHUP  ? "SIGHUP"
                                      : "SIGQUIT";
  const char head[] = "spinesim: error: interrupted by ";
  const char tail[] = ": unfinished outputs removed\n";
  (void)!::write(STDERR_FILENO, head, sizeof head - 1);
  (void)!::write(STDERR_FILENO, name, std::strlen(name));
  (void)!::write(STDERR_FILENO, tail, sizeof tail - 1);
  std::signal(sig, SIG_DFL);
  ::raise(sig);
}

}  // namespace pending_detail

/// Registers a path (a file, or a folder the run owns entirely) for removal if the run is killed,
/// until the object is destroyed or release() is called. It removes nothing itself.
class PendingOutput {
 public:
  enum class Kind { file, folder };
  PendingOutput() = default;  ///< tracks nothing
  explicit PendingOutput(const std::string& path, Kind kind = Kind::file) {
    if (path.size() >= pending_detail::kMaxPath) return;  // not openable anyway
    for (pending_detail::Slot& s : pending_detail::slots()) {
      int expected = pending_detail::kFree;
      if (!s.state.compare_exchange_strong(expected, pending_detail::kWriting)) continue;
      std::memcpy(s.path, path.c_str(), path.size() + 1);
      s.folder = kind == Kind::folder;
      s.state.store(pending_detail::kReady, std::memory_order_release);
      slot_ = &s;
      return;
    }
  }
  ~PendingOutput() { release(); }
  PendingOutput(const PendingOutput&) = delete;
  PendingOutput& operator=(const PendingOutput&) = delete;
  PendingOutput(PendingOutput&& o) noexcept : slot_(o.slot_) { o.slot_ = nullptr; }
  PendingOutput& operator=(PendingOutput&& o) noexcept {
    if (this != &o) {
      release();
      slot_ = o.slot_;
      o.slot_ = nullptr;
    }
    return *this;
  }
  /// The output is finished (or removed): a signal no longer touches it.
  void release() {
    if (slot_) slot_->state.store(pending_detail::kFree, std::memory_order_release);
    slot_ = nullptr;
  }
  /// False when the table was full and the path is not tracked.
  bool tracked() const { return slot_ != nullptr; }

 private:
  pending_detail::Slot* slot_ = nullptr;
};

/// Installs the handler for SIGINT, SIGTERM, SIGHUP and SIGQUIT (a signal the caller ignores
/// stays ignored, as for a run under nohup). Call once, from main.
inline void remove_pending_outputs_on_signals() {
  for (const int sig : pending_detail::kSignals) {
    struct sigaction old {};
    if (::sigaction(sig, nullptr, &old) == 0 && old.sa_handler == SIG_IGN) continue;
    struct sigaction sa {};
    sa.sa_handler = pending_detail::on_signal;
    sigfillset(&sa.sa_mask);  // one handler at a time
    ::sigaction(sig, &sa, nullptr);
  }
}

/// While alive, the signals above wait, whichever thread they are delivered to: what happens in
/// its scope (the renames that commit a set of outputs) is done whole before the run is killed.
/// A signal that arrived meanwhile takes effect when the last open block ends.
class SignalBlock {
 public:
  SignalBlock() { pending_detail::g_hold_depth.fetch_add(1); }
  ~SignalBlock() {
    if (pending_detail::g_hold_depth.fetch_sub(1) != 1) return;
    if (const int sig = pending_detail::g_held_signal.exchange(0)) ::raise(sig);
  }
  SignalBlock(const SignalBlock&) = delete;
  SignalBlock& operator=(const SignalBlock&) = delete;
};

}  // namespace spinesim

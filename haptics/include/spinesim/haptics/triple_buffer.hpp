// Lock-free hand-off of the latest value between one writer and one reader running at different
// rates (the servo thread and a slower thread: the scene's poses in, status and graphics out).
// Three slots: the writer fills its own, then swaps it with the middle one; the reader swaps the
// middle one with its own when a new value is there. Neither ever waits or allocates (T's copy
// assignment must not allocate for the servo side to stay allocation-free).
#pragma once

#include <atomic>
#include <cstdint>

namespace spinesim::haptics {

template <class T>
class TripleBuffer {
 public:
  TripleBuffer() = default;
  explicit TripleBuffer(const T& initial) {
    for (auto& s : slots_) s = initial;
  }
  /// Fills every slot with `value` (before the threads start: not thread-safe), e.g. to size
  /// vectors once so that later copies do not allocate.
  void reset(const T& value) {
    for (auto& s : slots_) s = value;
  }
  /// Writer: publishes `value` (the reader sees it at its next read()).
  void write(const T& value) {
    slots_[write_] = value;
    const std::uint8_t old =
        middle_.exchange(std::uint8_t(write_ | kFresh), std::memory_order_acq_rel);
    write_ = old & kIndex;
  }
  /// Reader: the latest published value (or the previous one if nothing new).
  const T& read() {
    if (middle_.load(std::memory_order_relaxed) & kFresh) {
      const std::uint8_t old = middle_.exchange(std::uint8_t(read_), std::memory_order_acq_rel);
      read_ = old & kIndex;
    }
    return slots_[read_];
  }
  /// Reader: true when a value newer than the last read() is waiting.
  bool fresh() const { return middle_.load(std::memory_order_acquire) & kFresh; }

 private:
  static constexpr std::uint8_t kIndex = 3, kFresh = 4;
  T slots_[3]{};
  std::atomic<std::uint8_t> middle_{1};
  int write_ = 0, read_ = 2;
};

}  // namespace spinesim::haptics

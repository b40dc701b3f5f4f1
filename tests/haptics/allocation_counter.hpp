// Counts operator new calls while armed (the replacement operators are defined once, in
// test_servo.cpp, for the whole haptics test program): a servo tick must allocate nothing.
#pragma once

#include <atomic>

namespace spinesim::haptics::testing {

extern std::atomic<bool> g_count_allocations;
extern std::atomic<long> g_allocations;

/// Arms the counter for its lifetime; allocations() is the count so far.
class CountAllocations {
 public:
  CountAllocations() {
    g_allocations = 0;
    g_count_allocations = true;
  }
  ~CountAllocations() { g_count_allocations = false; }
  long allocations() const { return g_allocations.load(); }
};

}  // namespace spinesim::haptics::testing

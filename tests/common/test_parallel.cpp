// parallel_for (common/parallel.hpp): every item once, the same results on any thread count, and
// an item's exception back in the caller instead of ending the program.
#include "spinesim/common/parallel.hpp"

#include <gtest/gtest.h>

#include <atomic>
#include <cmath>
#include <stdexcept>
#include <vector>

namespace spinesim {
namespace {

TEST(ParallelFor, RunsEveryItemExactlyOnceOnAnyThreadCount) {
  for (int threads : {1, 2, 3, 8}) {
    std::vector<std::atomic<int>> visits(37);
    parallel_for(visits.size(), threads, [&](std::size_t k) { ++visits[k]; });
    for (std::size_t k = 0; k < visits.size(); ++k) EXPECT_EQ(visits[k], 1) << threads << " " << k;
  }
  parallel_for(0, 4, [](std::size_t) { FAIL() << "no item to run"; });
}

TEST(ParallelFor, GivesTheSameResultsOnOneThreadAndOnSeveral) {
  const auto run = [](int threads) {
    std::vector<double> out(100);
    parallel_for(out.size(), threads,
                 [&](std::size_t k) { out[k] = std::sin(double(k)) / (k + 1); });
    return out;
  };
  EXPECT_EQ(run(1), run(4));
}

TEST(ParallelFor, RethrowsAnItemsExceptionInTheCallerAfterTheOthersRan) {
  for (int threads : {1, 2}) {
    std::atomic<int> ran{0};
    EXPECT_THROW(parallel_for(10, threads,
                              [&](std::size_t k) {
                                ++ran;
                                if (k == 3) throw std::runtime_error("item 3");
                              }),
                 std::runtime_error);
    EXPECT_EQ(ran, 10) << threads;
  }
}

}  // namespace
}  // namespace spinesim

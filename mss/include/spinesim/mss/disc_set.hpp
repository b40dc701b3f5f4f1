// DiscSet — several MSS discs stepped together: the spine case of thesis 5.4, where the 17 discs
// T1-T2 … L5-S1 are simulated between recorded vertebra poses. The discs are independent, so
// one step of the set runs the discs' steps in parallel over `threads` (OpenMP, dynamic
// schedule: the discs differ in size); with one thread it is a plain loop.
#pragma once

#include "spinesim/mss/model.hpp"
#include "spinesim/mss/simulator.hpp"
#include "spinesim/mss/solver.hpp"

#include <functional>
#include <memory>
#include <vector>

namespace spinesim::mss {

class DiscSet {
 public:
  /// threads >= 1 (throws std::invalid_argument otherwise).
  explicit DiscSet(int threads = 1);
  ~DiscSet();
  DiscSet(DiscSet&&) noexcept;
  DiscSet& operator=(DiscSet&&) noexcept;

  /// Adds a disc at rest; returns its index.
  int add(MssModel model, const DynamicsOptions& options);
  int size() const;
  int threads() const;

  const MssModel& model(int i) const;
  const State& state(int i) const;
  /// Replaces disc i's state (an equilibrium to start from, say); throws std::invalid_argument
  /// for a state of the wrong size or with non-finite values.
  void set_state(int i, State state);
  double total_tets() const;

  /// Advances every disc by its dt; bcs[i] is disc i's boundary at the end of the step
  /// (throws std::invalid_argument if bcs.size() != size()). A rejected step leaves that disc
  /// unchanged and is reported in its StepReport; the others still advance.
  const std::vector<StepReport>& step(const std::vector<Boundary>& bcs);

  /// Calls work(i) for every disc i, over the set's threads as step() does (work on different
  /// discs must be independent); the first exception is rethrown after all have run.
  void for_each(const std::function<void(int)>& work) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace spinesim::mss

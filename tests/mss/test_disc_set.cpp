// DiscSet: stepping discs together, serially or in parallel, gives each disc exactly the
// result of stepping it alone.
#include "spinesim/mss/disc_set.hpp"
#include "spinesim/mss/simulator.hpp"

#include "solver_fixtures.hpp"

#include <gtest/gtest.h>

namespace spinesim::mss {
namespace {

std::vector<Boundary> boundaries(const DiscSet& set, double squeeze_mm) {
  std::vector<Boundary> bcs;
  for (int i = 0; i < set.size(); ++i)
    bcs.push_back(fixtures::motion_boundary(
        set.model(i).mesh(), fixtures::vec6(0, -squeeze_mm * (i + 1), 0, 0.01 * i, 0, 0)));
  return bcs;
}

TEST(DiscSet, ParallelStepsEqualSeparateSteps) {
  DynamicsOptions opt;
  opt.dt_s = 1e-3;
  const mesh::TetMesh box = fixtures::small_box();
  DiscSet serial(1), parallel(2);
  for (DiscSet* set : {&serial, &parallel})
    for (int i = 0; i < 3; ++i) set->add(MssModel(box, fixtures::real_disc()), opt);
  Simulator alone(serial.model(2), opt);
  State s = alone.rest_state();
  for (int step = 0; step < 5; ++step) {
    for (DiscSet* set : {&serial, &parallel})
      for (const StepReport& r : set->step(boundaries(*set, 0.02 * (step + 1))))
        ASSERT_TRUE(r.ok) << r.message;
    ASSERT_TRUE(alone.step(s, boundaries(serial, 0.02 * (step + 1))[2]).ok);
  }
  for (int i = 0; i < 3; ++i)
    EXPECT_EQ((serial.state(i).x_mm - parallel.state(i).x_mm).norm(), 0.0);
  EXPECT_EQ((serial.state(2).x_mm - s.x_mm).norm(), 0.0);
  EXPECT_GT((serial.state(2).x_mm - serial.model(2).rest_positions_mm()).norm(), 0.0);
  EXPECT_EQ(serial.total_tets(), 3.0 * double(box.num_tets()));
}

TEST(DiscSet, BadInputIsRefused) {
  EXPECT_THROW(DiscSet(0), std::invalid_argument);
  DiscSet set(1);
  set.add(MssModel(fixtures::small_box(), fixtures::real_disc()), DynamicsOptions());
  EXPECT_THROW(set.step({}), std::invalid_argument);
}

}  // namespace
}  // namespace spinesim::mss

namespace spinesim::mss {
namespace {

// for_each runs every disc once, over the threads; set_state replaces one disc's state and
// refuses a state of the wrong size.
TEST(DiscSet, ForEachVisitsEveryDiscOnceAndSetStateChecksTheSize) {
  const mesh::TetMesh m = fixtures::small_box();
  DiscSet set(2);
  for (int i = 0; i < 5; ++i) set.add(MssModel(m, fixtures::real_disc()), DynamicsOptions());
  std::vector<int> visits(5, 0);
  set.for_each([&](int i) { ++visits[std::size_t(i)]; });
  EXPECT_EQ(visits, std::vector<int>(5, 1));
  EXPECT_THROW(set.for_each([](int i) {
    if (i == 3) throw std::runtime_error("disc 3 failed");
  }),
               std::runtime_error);
  State s = set.state(2);
  s.x_mm.array() += 0.01;
  s.time_s = 0.5;
  set.set_state(2, s);
  EXPECT_EQ(set.state(2).x_mm, s.x_mm);
  EXPECT_EQ(set.state(2).time_s, 0.5);
  State wrong = s;
  wrong.x_mm.resize(3);
  EXPECT_THROW(set.set_state(2, wrong), std::invalid_argument);
  State nan = s;
  nan.v_mm_s(0) = std::nan("");
  EXPECT_THROW(set.set_state(2, nan), std::invalid_argument);
}

}  // namespace
}  // namespace spinesim::mss

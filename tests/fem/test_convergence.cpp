// Convergence on a manufactured solution (manufactured.hpp): L² error orders 2 (P1), 3 (P2).
// P2 with n = 16 (108k DOF, ~12 s) is in test_convergence_slow.cpp.
#include "manufactured.hpp"

#include <gtest/gtest.h>

using spinesim::fem::manufactured::measured_orders;

TEST(Convergence, P1IsSecondOrderInL2) {
  const std::vector<double> rates = measured_orders(1, {2, 4, 8, 16});
  ASSERT_EQ(rates.size(), 3u);
  EXPECT_GE(rates.back(), 1.8);
  EXPECT_GE(rates[1], 1.7);
}

TEST(Convergence, P2IsThirdOrderInL2) {
  const std::vector<double> rates = measured_orders(2, {2, 4, 8});
  ASSERT_EQ(rates.size(), 2u);
  EXPECT_GE(rates.back(), 2.7);
}

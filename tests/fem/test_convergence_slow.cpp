// Slow convergence runs (label 'slow'): P2 up to n = 16 (108k DOF).
#include "manufactured.hpp"

#include <gtest/gtest.h>

using spinesim::fem::manufactured::measured_orders;

TEST(ConvergenceSlow, P2IsThirdOrderInL2UpTo16CellsPerSide) {
  const std::vector<double> rates = measured_orders(2, {4, 8, 16});
  ASSERT_EQ(rates.size(), 2u);
  EXPECT_GE(rates[0], 2.7);
  EXPECT_GE(rates[1], 2.7);
}

TEST(ConvergenceSlow, P1IsSecondOrderInL2UpTo32CellsPerSide) {
  const std::vector<double> rates = measured_orders(1, {8, 16, 32});
  ASSERT_EQ(rates.size(), 2u);
  EXPECT_GE(rates[1], 1.8);
}

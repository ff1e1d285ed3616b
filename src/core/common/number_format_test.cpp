#include "hrg_gyro/core/common/number_format.h"

#include <gtest/gtest.h>

#include <cmath>
#include <string>

namespace hrg_gyro {
namespace core {
namespace {

TEST(NumberFormat, DoubleReadsBackToTheSameBits) {
  for (const double v : {0.1, 1.0 / 3.0, -2.5e-17, 7.2921150e-5, 1e300, 123456789.125}) {
    const std::string text = formatDouble(v);
    EXPECT_EQ(std::stod(text), v) << text;
  }
  EXPECT_EQ(formatDouble(0.1), "0.1");  // the shortest, not 0.1000000000000000055
}

TEST(NumberFormat, WholeNumberStaysAFloat) {
  EXPECT_EQ(formatDouble(1.0), "1.0");
  EXPECT_EQ(formatDouble(-40.0), "-40.0");
  EXPECT_EQ(formatDouble(1e22), "1e+22");  // an exponent already says float
  EXPECT_EQ(formatDouble(INFINITY), "inf");
}

TEST(NumberFormat, ShortHasTheDigitsAsked) {
  EXPECT_EQ(formatShort(3.14159265), "3.142");
  EXPECT_EQ(formatShort(3.14159265, 2), "3.1");
  EXPECT_EQ(formatShort(86400.0, 6), "86400");
  EXPECT_EQ(formatShort(1.5e-7, 3), "1.5e-07");
}

TEST(NumberFormat, NumbersIntoAPattern) {
  EXPECT_EQ(formatNumbers("axis %.0f: %.2f turns", 2.0, 1.256), "axis 2: 1.26 turns");
  EXPECT_EQ(formatNumbers("%.3g %.3g %.3g %.3g", 1.0, 2e-5, -3.14159, 4e10), "1 2e-05 -3.14 4e+10");
  EXPECT_EQ(formatNumbers("no number"), "no number");
}

}  // namespace
}  // namespace core
}  // namespace hrg_gyro

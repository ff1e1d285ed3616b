#include "hrg_gyro/core/common/fast_atan2.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <limits>
#include <random>
#include <vector>

#include "hrg_gyro/core/common/units.h"

namespace hrg_gyro {
namespace core {
namespace {

constexpr double kBound = 1e-15;  // rad, the bound the header states

// A dense grid of directions (every octant, near every boundary of the reduction) at radii from
// 1e-300 to 1e300.
TEST(FastAtan2Test, MatchesTheLibraryOnADenseGridOfDirectionsAndRadii) {
  double worst = 0.0;
  const int directions = 400000;
  for (double radius : {1e-300, 1e-9, 1.0, 3.7, 1e9, 1e300}) {
    for (int i = 0; i < directions; ++i) {
      const double phi = -kPi + kTwoPi * (i + 0.5) / directions;
      const double y = radius * std::sin(phi), x = radius * std::cos(phi);
      worst = std::max(worst, std::abs(fastAtan2(y, x) - std::atan2(y, x)));
    }
  }
  std::printf("[ measured ] dense grid: largest difference from std::atan2 %.3g rad\n", worst);
  EXPECT_LT(worst, kBound);
  // The ratios at the table entries (k/32), where the reduction switches entries (k/32 +- 1/64) and
  // octants (1).
  for (int j = 0; j <= 64; ++j) {
    for (double nudge : {-1e-16, 0.0, 1e-16}) {
      const double t = j / 64.0 + nudge;
      for (double sx : {1.0, -1.0}) {
        for (double sy : {1.0, -1.0}) {
          EXPECT_NEAR(fastAtan2(sy * t, sx), std::atan2(sy * t, sx), kBound) << t;
          EXPECT_NEAR(fastAtan2(sy, sx * t), std::atan2(sy, sx * t), kBound) << t;
        }
      }
    }
  }
}

// Random operands over the whole exponent range (random bit patterns), so ratios far from 1 too.
TEST(FastAtan2Test, MatchesTheLibraryOnRandomOperands) {
  std::mt19937_64 random(31);
  double worst = 0.0;
  int compared = 0;
  for (int i = 0; i < 2000000; ++i) {
    const std::uint64_t a = random(), b = random();
    double y, x;
    std::memcpy(&y, &a, sizeof y);
    std::memcpy(&x, &b, sizeof x);
    if (!std::isfinite(y) || !std::isfinite(x)) continue;
    worst = std::max(worst, std::abs(fastAtan2(y, x) - std::atan2(y, x)));
    ++compared;
  }
  EXPECT_GT(compared, 1900000);
  std::printf("[ measured ] random operands: largest difference from std::atan2 %.3g rad\n", worst);
  EXPECT_LT(worst, kBound);
}

// Lanes (the pair of the one-sample path, the four of the batch path) give every operand the bits
// one double gets: every octant, signed zeros of y, and the table's switching points.
TEST(FastAtan2Test, LanesGiveTheBitsOfOneDouble) {
  std::mt19937_64 random(5);
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);
  std::vector<double> ys, xs;
  for (int i = 0; i < 20000; ++i) {
    ys.push_back(uniform(random));
    xs.push_back(uniform(random));
  }
  for (int j = 0; j <= 64; ++j) {
    for (double sx : {1.0, -1.0}) {
      for (double sy : {1.0, -1.0}) {
        ys.push_back(sy * j / 64.0);
        xs.push_back(sx);
        ys.push_back(sy);
        xs.push_back(sx * j / 64.0);
      }
    }
  }
  for (double sx : {1.0, -1.0}) {
    ys.push_back(-0.0);
    xs.push_back(sx);
  }
  while (ys.size() % 4 != 0) {
    ys.push_back(0.5);
    xs.push_back(-0.25);
  }
  int differing = 0;
  for (std::size_t i = 0; i < ys.size(); i += 4) {
    const DoubleLanes4 four = fastAtan2Reduced(DoubleLanes4{ys[i], ys[i + 1], ys[i + 2], ys[i + 3]},
                                               DoubleLanes4{xs[i], xs[i + 1], xs[i + 2], xs[i + 3]});
    const DoubleLanes2 pair = fastAtan2Reduced(DoubleLanes2{ys[i], ys[i + 1]}, DoubleLanes2{xs[i], xs[i + 1]});
    for (int lane = 0; lane < 4; ++lane) {
      const double one = fastAtan2Reduced(ys[i + lane], xs[i + lane]);
      differing += std::memcmp(&one, &four[lane], sizeof one) != 0;
      if (lane < 2) differing += std::memcmp(&one, &pair[lane], sizeof one) != 0;
      EXPECT_NEAR(one, std::atan2(ys[i + lane], xs[i + lane]), kBound) << ys[i + lane] << ", " << xs[i + lane];
    }
  }
  EXPECT_EQ(differing, 0);
}

TEST(FastAtan2Test, KeepsTheLibraryConventionsForZerosInfinitiesAndNaN) {
  const double inf = std::numeric_limits<double>::infinity(), nan = std::numeric_limits<double>::quiet_NaN();
  for (double y : {0.0, -0.0, 1.0, -1.0, inf, -inf, 1e-310, -1e-310}) {
    for (double x : {0.0, -0.0, 1.0, -1.0, inf, -inf, 1e-310, -1e-310}) {
      const double expected = std::atan2(y, x), got = fastAtan2(y, x);
      EXPECT_NEAR(got, expected, kBound) << y << ", " << x;
      EXPECT_EQ(std::signbit(got), std::signbit(expected)) << y << ", " << x;
    }
  }
  EXPECT_TRUE(std::isnan(fastAtan2(nan, 1.0)));
  EXPECT_TRUE(std::isnan(fastAtan2(1.0, nan)));
}

}  // namespace
}  // namespace core
}  // namespace hrg_gyro

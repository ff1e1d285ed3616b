// The wave parameters' guarded quadrature ratio B/A.
#include "hrg_gyro/core/model/wave_parameters.h"

#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>
#include <vector>

namespace hrg_gyro {
namespace core {
namespace {

TEST(QuadratureRatioTest, IsBOverAAndNaNWithoutAPositiveAmplitude) {
  EXPECT_DOUBLE_EQ(quadratureRatio(0.02, 0.5), 0.04);
  EXPECT_TRUE(std::isnan(quadratureRatio(0.02, 0.0)));
  EXPECT_TRUE(std::isnan(quadratureRatio(0.02, -1.0)));
  EXPECT_TRUE(std::isnan(quadratureRatio(NAN, 1.0)));
  EXPECT_TRUE(std::isnan(quadratureRatio(0.0, INFINITY)));
}

// ---- staged calibration ----------------------------------------------------------------------------

}  // namespace
}  // namespace core
}  // namespace hrg_gyro

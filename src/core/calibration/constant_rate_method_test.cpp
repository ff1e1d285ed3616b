// The constant-rate method on a fast angle-level session (docs/math.md, 'Calibration methods'): its
// known weakness, D's harmonics leaking into K by D_k / Omega.
#include <gtest/gtest.h>

#include <cmath>

#include "core/testing/angle_level_session.h"
#include "core/testing/method_test_settings.h"

namespace hrg_gyro {
namespace core {
namespace {

TEST(ConstantRateTest, DriftHarmonicsLeakIntoKByDkOverOmega) {
  testing::AngleLevelGyro g = testing::referenceGyro();
  const CalibrationOutcome o = testing::calibrateAngleLevel(
      g, testing::constantRateProfile(), testing::methodSettings(CalibrationMethodKind::kConstantRate),
      testing::referencePrior());
  ASSERT_TRUE(o.accepted) << o.reason;
  const HarmonicFitResult& k = o.scale_factor[0];
  const double omega = 0.05 + g.earth_rate;
  // the method's known weakness: D_k / Omega leaks into the harmonics (2e-5 / 0.05 = 4e-4 here)...
  EXPECT_NEAR(k.cos[0], -6e-4 + 2e-5 / omega, 1e-7);
  EXPECT_NEAR(k.sin[0], 4e-4 - 1e-5 / omega, 1e-7);
  // ... and is unbiased where D has no harmonic, once the Earth rate is scaled by K.
  EXPECT_NEAR(k.cos[1], 2e-3, 1e-7);
  // K0 is off by (mean drift - drift at the dwell angles) / Omega: here D varies by 2.2e-5 rad/s
  // around its mean, so up to ~4e-4.
  EXPECT_GT(std::abs(k.mean + 0.56), 1e-5);
  EXPECT_LT(std::abs(k.mean + 0.56), 2.3e-5 / 0.05);
  EXPECT_FALSE(o.notes.empty());
}

}  // namespace
}  // namespace core
}  // namespace hrg_gyro

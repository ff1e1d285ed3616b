// The step method on a fast angle-level session (docs/math.md, 'Calibration methods'): K from the
// steps, D from the dwells.
#include <gtest/gtest.h>

#include "core/testing/angle_level_session.h"
#include "core/testing/method_test_settings.h"

namespace hrg_gyro {
namespace core {
namespace {

TEST(StepTest, RecoversKFromStepsAndDFromDwells) {
  testing::AngleLevelGyro g = testing::referenceGyro();
  g.noise = 1.1e-5;
  YAML::Node n =
      YAML::Load("[{type: steps, angle: 0.3490658503988659, rate: 0.17453292519943295, dwell: 15.0, count: 18}]");
  const TurntableProfile p = TurntableProfile::parse(YamlField(n, "profile"), 0.5);
  CalibrationSettings s = testing::methodSettings(CalibrationMethodKind::kStep);
  s.bins = 64;
  const CalibrationOutcome o = testing::calibrateAngleLevel(g, p, s, testing::referencePrior());
  ASSERT_TRUE(o.accepted) << o.reason << "\n" << emitCalibrationReport(o);
  const HarmonicFitResult& k = o.scale_factor[0];
  EXPECT_NEAR(k.mean, -0.56, 5 * k.mean_std + 1e-7);
  EXPECT_NEAR(k.cos[0], -6e-4, 5 * k.cos_std[0] + 1e-7);
  EXPECT_NEAR(k.sin[0], 4e-4, 5 * k.sin_std[0] + 1e-7);
  EXPECT_NEAR(k.cos[1], 2e-3, 5 * k.cos_std[1] + 1e-7);
  EXPECT_LT(k.cos_std[1], 1e-5);
  EXPECT_NEAR(o.drift[0].mean, 1e-5, 2e-7);
}

}  // namespace
}  // namespace core
}  // namespace hrg_gyro

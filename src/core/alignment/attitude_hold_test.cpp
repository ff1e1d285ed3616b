// The attitude hold: exact increments from an exact start keep the attitude (the Earth's rate removed
// in ENU) at rest and on a turning platform; the covariance grows as the noise model says (N^2 t for an
// angle random walk, the bias's image for a constant bias); a gap, a reset or a wave turned on command
// loses the attitude.
#include "hrg_gyro/core/alignment/attitude_hold.h"

#include <gtest/gtest.h>

#include <cmath>

#include "core/testing/angle_level_mount.h"

namespace hrg_gyro {
namespace core {
namespace {

using testing::MountScenario;

AttitudeHoldSettings holdSettings(double latitude) {
  AttitudeHoldSettings s;
  s.latitude = latitude;
  s.noise.angle_white_noise = 1e-12;
  return s;
}

HoldStart exactStart(const MountScenario& s) {
  HoldStart start;
  start.stamp = toNanoseconds(s.start);
  start.body_to_enu = orientationFromEuler(s.mount);
  return start;
}

// Feeds the scenario's triad samples into the hold; returns the body's true orientation at the end.
Eigen::Quaterniond runHold(const MountScenario& s, AttitudeHold* hold) {
  testing::MountSinks sinks;
  sinks.triad = [&](const TriadBodySample& x) { hold->add(x); };
  testing::runMountScenario(s, sinks);
  double logged, truth, rate;
  testing::indexerAngle(s, s.length(), &logged, &truth, &rate);
  return orientationFromEuler(s.mount) * Eigen::AngleAxisd(s.indexed ? truth : 0.0, Eigen::Vector3d::UnitZ());
}

TEST(AttitudeHoldTest, ExactIncrementsKeepTheAttitude) {
  MountScenario s;
  s.white_noise = 1e-13;
  s.accelerometer = false;
  s.mount = EulerAngles{0.02, -0.01, 2.5};
  s.duration = 3600.0;
  AttitudeHold hold(holdSettings(s.latitude), exactStart(s));
  const Eigen::Quaterniond truth = runHold(s, &hold);
  ASSERT_TRUE(hold.holding()) << hold.lostReason();
  EXPECT_NEAR(hold.elapsed(), 3600.0, 1e-6);
  const double error = hold.orientation().angularDistance(truth);
  std::printf("[ measured ] one hour at rest, exact increments: attitude off by %.3e rad\n", error);
  EXPECT_LT(error, 1e-9);

  // On a platform turning at 0.05 rad/s about the vertical for 300 s.
  MountScenario turning = s;
  turning.indexed = true;
  turning.continuous = true;
  turning.duration = 300.0;
  AttitudeHold spun(holdSettings(s.latitude), exactStart(turning));
  const Eigen::Quaterniond turned = runHold(turning, &spun);
  ASSERT_TRUE(spun.holding());
  std::printf("[ measured ] 300 s turning at 0.05 rad/s: attitude off by %.3e rad\n",
              spun.orientation().angularDistance(turned));
  EXPECT_LT(spun.orientation().angularDistance(turned), 1e-8);
}

TEST(AttitudeHoldTest, TheCovarianceGrowsAsTheNoiseModelSays) {
  MountScenario s;
  s.accelerometer = false;
  s.duration = 1000.0;
  s.white_noise = 1e-13;
  // An angle random walk alone: each axis's variance grows as N^2 t.
  AttitudeHoldSettings settings = holdSettings(s.latitude);
  settings.noise.angle_random_walk = 1e-6;
  AttitudeHold hold(settings, exactStart(s));
  runHold(s, &hold);
  const Eigen::Matrix3d p = hold.covariance();
  for (int i = 0; i < 3; ++i) EXPECT_NEAR(p(i, i) / (1e-12 * 1000.0), 1.0, 1e-3) << i;
  // A constant bias of 1e-8 rad/s per axis, uncorrelated at the start: the heading's sigma grows as the
  // up-axis bias times t (the tilts' coupling through the Earth's rate adds a little).
  HoldStart start = exactStart(s);
  start.bias_variance = 1e-16;
  AttitudeHold biased(holdSettings(s.latitude), start);
  runHold(s, &biased);
  const double sigma_yaw = std::sqrt(biased.covarianceRpy()(2, 2));
  std::printf("[ measured ] 1e-8 rad/s bias, 1000 s: heading sigma %.3e rad (b t = %.3e)\n", sigma_yaw, 1e-5);
  EXPECT_NEAR(sigma_yaw / 1e-5, 1.0, 0.05);
  EXPECT_NEAR(biased.headingSigma(), sigma_yaw * 180.0 / kPi, 1e-12);
}

TEST(AttitudeHoldTest, AGapOrACommandedWaveLosesTheAttitude) {
  HoldStart start;
  start.stamp = toNanoseconds(1.0);
  AttitudeHold hold(holdSettings(0.9), start);
  TriadBodySample x;
  x.stamp = toNanoseconds(1.005);
  x.dt = 0.005;
  EXPECT_TRUE(hold.add(x));
  TriadBodySample stale = x;
  EXPECT_TRUE(hold.add(stale));  // at the latest stamp: dropped
  EXPECT_EQ(hold.dropped(), 1u);
  x.stamp = toNanoseconds(1.010);
  x.flags = kTriadFlagPrecessing;
  EXPECT_FALSE(hold.add(x));
  EXPECT_FALSE(hold.holding());
  EXPECT_NE(hold.lostReason().find("FLAG_PRECESSING"), std::string::npos);

  AttitudeHold gapped(holdSettings(0.9), start);
  x.flags = kTriadFlagGap;
  EXPECT_FALSE(gapped.add(x));
  AttitudeHold skipped(holdSettings(0.9), start);
  x.flags = 0;
  x.stamp = toNanoseconds(1.050);  // samples missing in between
  EXPECT_FALSE(skipped.add(x));
  EXPECT_NE(skipped.lostReason().find("missing"), std::string::npos);
  // A refused alignment or one gyro's gives no start.
  AlignmentResult refused;
  EXPECT_THROW(holdStartFrom(refused), std::invalid_argument);
}

}  // namespace
}  // namespace core
}  // namespace hrg_gyro

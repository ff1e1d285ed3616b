// An IMU's rate stream back into increments: a driver's delta-angles divided by its period come back
// bit-near exact through a mounting (RFU to FLU); jittered stamps with the driver's period keep each
// increment; a lost sample is bridged, an interval beyond max_bridge is a gap with no rotation, a
// stamp glitched far ahead or behind costs that sample only; the message's covariance is rotated, a
// missing one replaced; nothing non-finite comes out; bad settings are refused by name.
#include "hrg_gyro/core/processing/imu_increment_converter.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "core/testing/refusal.h"
#include "hrg_gyro/core/common/yaml_field.h"

namespace hrg_gyro {
namespace core {
namespace {

constexpr Nanoseconds kPeriod = 10000000;  // 100 Hz
constexpr Nanoseconds kStart = 1700000000LL * 1000000000LL;

/// x Right, y Front, z Up -> x Front, y Left, z Up.
Eigen::Quaterniond rfuToFlu() {
  Eigen::Matrix3d r;
  r << 0, 1, 0, -1, 0, 0, 0, 0, 1;
  return Eigen::Quaterniond(r);
}

/// A driver's sample k: its delta-angle (sensor frame) divided by the nominal period.
ImuSample driverSample(Nanoseconds stamp, const Eigen::Vector3d& delta) {
  ImuSample s;
  s.stamp = stamp;
  s.angular_velocity = delta / toSeconds(kPeriod);
  return s;
}

std::vector<Eigen::Vector3d> randomIncrements(std::size_t n) {
  std::mt19937_64 rng(7);
  std::normal_distribution<double> d(0.0, 1e-6);
  std::vector<Eigen::Vector3d> out;
  for (std::size_t k = 0; k < n; ++k) out.emplace_back(d(rng) + 7e-7, d(rng), d(rng) + 4e-7);
  return out;
}

TEST(ImuIncrementConverterTest, ADriversDeltaAnglesComeBackThroughTheMounting) {
  ImuInputSettings settings;
  settings.imu_to_body = rfuToFlu();
  ImuIncrementConverter converter(settings);
  const std::vector<Eigen::Vector3d> deltas = randomIncrements(1000);
  EXPECT_FALSE(converter.convert(driverSample(kStart, deltas[0])).has_value()) << "the first has no interval";
  double worst = 0.0;
  for (std::size_t k = 1; k < deltas.size(); ++k) {
    const auto out = converter.convert(driverSample(kStart + static_cast<Nanoseconds>(k) * kPeriod, deltas[k]));
    ASSERT_TRUE(out.has_value());
    EXPECT_EQ(out->flags, 0);
    EXPECT_TRUE(out->integrated());
    EXPECT_NEAR(out->dt, 0.01, 1e-15);
    const Eigen::Vector3d expected(deltas[k].y(), -deltas[k].x(), deltas[k].z());
    worst = std::max(worst, (out->delta_angle - expected).cwiseAbs().maxCoeff() / expected.norm());
  }
  EXPECT_LT(worst, 1e-14) << "relative error of the increments";
  EXPECT_EQ(converter.counts().samples, 999u);
  EXPECT_NEAR(converter.typicalPeriod(), 0.01, 1e-12);
}

TEST(ImuIncrementConverterTest, JitteredStampsWithTheDriversPeriodKeepEachIncrement) {
  ImuInputSettings settings;
  settings.period = 0.01;
  ImuIncrementConverter converter(settings);
  std::mt19937_64 rng(3);
  std::uniform_int_distribution<Nanoseconds> jitter(-100000, 100000);  // +-0.1 ms, hardware stamps
  const std::vector<Eigen::Vector3d> deltas = randomIncrements(500);
  Eigen::Vector3d sum_in = Eigen::Vector3d::Zero(), sum_out = Eigen::Vector3d::Zero();
  for (std::size_t k = 0; k < deltas.size(); ++k) {
    const Nanoseconds stamp = kStart + static_cast<Nanoseconds>(k) * kPeriod + jitter(rng);
    const auto out = converter.convert(driverSample(stamp, deltas[k]));
    if (k == 0) continue;
    ASSERT_TRUE(out.has_value());
    EXPECT_EQ(out->dt, 0.01);
    EXPECT_LT((out->delta_angle - deltas[k]).norm(), 1e-20);
    sum_in += deltas[k];
    sum_out += out->delta_angle;
  }
  EXPECT_LT((sum_out - sum_in).norm(), 1e-18);
  // The stamps' intervals instead: each increment off by its jitter, the sum by the end's only.
  ImuIncrementConverter by_stamps{ImuInputSettings()};
  rng.seed(3);
  Eigen::Vector3d sum_stamps = Eigen::Vector3d::Zero();
  for (std::size_t k = 0; k < deltas.size(); ++k) {
    const auto out =
        by_stamps.convert(driverSample(kStart + static_cast<Nanoseconds>(k) * kPeriod + jitter(rng), deltas[k]));
    if (out) sum_stamps += out->delta_angle;
  }
  EXPECT_LT((sum_stamps - sum_in).norm(), 0.05 * sum_in.norm());
}

TEST(ImuIncrementConverterTest, ALostSampleIsBridgedALongHoleIsAGapAGlitchCostsItsSample) {
  ImuIncrementConverter converter{ImuInputSettings()};
  const Eigen::Vector3d delta(1e-6, 2e-6, 3e-6);
  Nanoseconds t = kStart;
  for (int k = 0; k < 40; ++k, t += kPeriod) converter.convert(driverSample(t, delta));
  t += kPeriod;  // one sample lost
  auto out = converter.convert(driverSample(t, delta));
  ASSERT_TRUE(out.has_value());
  EXPECT_EQ(out->flags, 0);
  EXPECT_NEAR(out->dt, 0.02, 1e-12);
  EXPECT_NEAR((out->delta_angle - 2.0 * delta).norm(), 0.0, 1e-18) << "the next rate stands for the lost one";
  // A hole of 0.5 s (within the stamp rule's forward jump): a gap, no rotation.
  t += 50 * kPeriod;
  out = converter.convert(driverSample(t, delta));
  ASSERT_TRUE(out.has_value());
  EXPECT_EQ(out->flags, kTriadFlagGap);
  EXPECT_FALSE(out->integrated());
  EXPECT_EQ(out->delta_angle, Eigen::Vector3d::Zero());
  EXPECT_EQ(converter.counts().gaps, 1u);
  // One stamp 1e6 s ahead, one 100 s behind: dropped; the next good one is bridged over the lost one.
  const std::uint64_t dropped = converter.counts().dropped;
  EXPECT_FALSE(converter.convert(driverSample(t + 1000000LL * 1000000000LL, delta)).has_value());
  EXPECT_FALSE(converter.convert(driverSample(t - 100LL * 1000000000LL, delta)).has_value());
  EXPECT_EQ(converter.counts().dropped, dropped + 2);
  t += 3 * kPeriod;  // two lost, the glitched ones among them: beyond the bridge of 2.5 periods
  out = converter.convert(driverSample(t, delta));
  ASSERT_TRUE(out.has_value());
  EXPECT_EQ(out->flags, kTriadFlagGap);
  t += kPeriod;
  out = converter.convert(driverSample(t, delta));
  ASSERT_TRUE(out.has_value());
  EXPECT_EQ(out->flags, 0);
  EXPECT_NEAR(out->dt, 0.01, 1e-12);
}

TEST(ImuIncrementConverterTest, TheStreamsCovarianceIsRotatedOrReplaced) {
  ImuInputSettings settings;
  settings.imu_to_body = rfuToFlu();
  settings.fallback_rate_variance = 4e-12;
  ImuIncrementConverter converter(settings);
  ImuSample s = driverSample(kStart, Eigen::Vector3d(1e-6, 0, 0));
  s.angular_velocity_covariance = Eigen::Vector3d(1e-10, 2e-10, 3e-10).asDiagonal();
  converter.convert(s);
  s.stamp += kPeriod;
  auto out = converter.convert(s);
  ASSERT_TRUE(out.has_value());
  EXPECT_NEAR(out->covariance(0, 0), 2e-10, 1e-25);  // body x is the IMU's y (front)
  EXPECT_NEAR(out->covariance(1, 1), 1e-10, 1e-25);
  EXPECT_NEAR(out->covariance(2, 2), 3e-10, 1e-25);
  s.stamp += kPeriod;
  s.angular_velocity_covariance.setZero();  // REP-145: unknown
  out = converter.convert(s);
  ASSERT_TRUE(out.has_value());
  EXPECT_EQ(out->covariance, Eigen::Matrix3d(4e-12 * Eigen::Matrix3d::Identity()));
  s.stamp += kPeriod;
  s.angular_velocity_covariance(0, 0) = -1.0;  // REP-145: no angular velocity... yet finite rates: not given
  out = converter.convert(s);
  ASSERT_TRUE(out.has_value());
  EXPECT_EQ(out->covariance(0, 0), 4e-12);
  // The specific force through the same mounting; none without one.
  s.linear_acceleration = Eigen::Vector3d(0.1, 0.2, 9.8);
  EXPECT_FALSE(converter.specificForce(s).has_value());
  s.has_acceleration = true;
  const auto f = converter.specificForce(s);
  ASSERT_TRUE(f.has_value());
  EXPECT_NEAR((*f - Eigen::Vector3d(0.2, -0.1, 9.8)).norm(), 0.0, 1e-15);
}

TEST(ImuIncrementConverterTest, NothingNonFiniteOrImplausibleComesOut) {
  ImuIncrementConverter converter{ImuInputSettings()};
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  Nanoseconds t = kStart;
  for (int k = 0; k < 20000; ++k) {
    ImuSample s = driverSample(t, Eigen::Vector3d(1e-6, -1e-6, 5e-7));
    const double r = u(rng);
    if (r < 0.02)
      s.angular_velocity.x() = NAN;
    else if (r < 0.04)
      s.angular_velocity.y() = INFINITY;
    else if (r < 0.05)
      s.angular_velocity.z() = 1e6;
    else if (r < 0.07)
      s.stamp = 0;
    else if (r < 0.09)
      s.stamp -= 5 * kPeriod;
    else if (r < 0.10)
      s.stamp += static_cast<Nanoseconds>(u(rng) * 1e15);
    t += r > 0.99 ? 40 * kPeriod : kPeriod;
    const auto out = converter.convert(s);
    if (!out) continue;
    EXPECT_TRUE(out->delta_angle.allFinite());
    EXPECT_TRUE(out->angular_velocity.allFinite());
    EXPECT_TRUE(std::isfinite(out->dt) && out->dt > 0.0);
    EXPECT_LE(out->delta_angle.norm(), 1e-6 * 3.0 * 2.5 + 1e-12);
  }
  EXPECT_GT(converter.counts().samples, 15000u);
  EXPECT_GT(converter.counts().dropped, 1000u);
}

TEST(ImuIncrementConverterTest, BadSettingsAreRefusedByName) {
  auto key = [](auto change) {
    return refusedKey([&] {
      ImuInputSettings s;
      change(&s);
      ImuIncrementConverter c(s);
    });
  };
  EXPECT_EQ(key([](ImuInputSettings* s) { s->imu_to_body.coeffs() << 0.5, 0, 0, 0.5; }), "imu/mounting");
  EXPECT_EQ(key([](ImuInputSettings* s) { s->period = -0.01; }), "imu/period");
  EXPECT_EQ(key([](ImuInputSettings* s) { s->period = NAN; }), "imu/period");
  EXPECT_EQ(key([](ImuInputSettings* s) { s->max_bridge = 0.5; }), "imu/max_bridge");
  EXPECT_EQ(key([](ImuInputSettings* s) { s->fallback_rate_variance = -1.0; }), "imu/rate_variance");
  EXPECT_EQ(key([](ImuInputSettings* s) { s->max_rate = 0.0; }), "imu/max_rate");
}

}  // namespace
}  // namespace core
}  // namespace hrg_gyro

#include "hrg_gyro/core/alignment/inertial_frame_alignment.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <functional>

#include "hrg_gyro/core/alignment/local_level.h"
#include "hrg_gyro/core/common/units.h"
#include "hrg_gyro/core/simulation/gaussian_noise.h"

namespace hrg_gyro {
namespace core {
namespace {

constexpr double kLatitude = 0.9, kDt = 0.005;

Eigen::Vector3d rotationVector(const Eigen::Matrix3d& r) {
  const Eigen::AngleAxisd a(r);
  return a.axis() * a.angle();
}

// A body whose attitude (-> ENU) is `attitude(t)`: its gyro increments (the integral of its inertial
// rate, by Simpson's rule on the attitude's own relative rotations) and its accelerometer.
struct Session {
  BodyAttitudeTrack track{0.0};
  InertialFrameInput input;
};

Session record(const std::function<Eigen::Matrix3d(double)>& attitude, double seconds, double accel_noise,
               double gyro_noise, std::uint64_t seed = 1) {
  Session s;
  s.input.latitude = kLatitude;
  GaussianNoise noise(seed);
  const Eigen::Vector3d u(0.0, std::cos(kLatitude), std::sin(kLatitude));
  // Inertial attitude: the Earth turns the local level about its axis.
  auto inertial = [&](double t) {
    return Eigen::Matrix3d(Eigen::AngleAxisd(kEarthRotationRate * t, u).toRotationMatrix() * attitude(t));
  };
  const long n = std::lround(seconds / kDt);
  Eigen::Vector3d previous_noise = Eigen::Vector3d::Zero();
  for (long k = 1; k <= n; ++k) {
    Eigen::Vector3d increment = Eigen::Vector3d::Zero();
    const int fine = 8;
    for (int j = 0; j < fine; ++j) {
      const double t0 = (k - 1 + double(j) / fine) * kDt, t1 = t0 + kDt / fine;
      increment += rotationVector(inertial(t0).transpose() * inertial(t1));
    }
    const Eigen::Vector3d angle_noise = gyro_noise * Eigen::Vector3d(noise.next(), noise.next(), noise.next());
    s.track.add(k * kDt, kDt, increment + angle_noise - previous_noise);
    previous_noise = angle_noise;
    const Eigen::Vector3d f = attitude(k * kDt).transpose() * Eigen::Vector3d(0.0, 0.0, kStandardGravity);
    s.input.accel_time.push_back(k * kDt);
    s.input.accel_force.push_back(f + accel_noise * Eigen::Vector3d(noise.next(), noise.next(), noise.next()));
  }
  return s;
}

double headingError(const Eigen::Matrix3d& estimate, const Eigen::Matrix3d& truth) {
  return rotationVector(truth * estimate.transpose()).z();  // ENU small rotation's Up part
}

TEST(InertialFrameAlignmentTest, TheReferenceIsGravityTurningWithTheSite) {
  const Eigen::Vector3d u(0.0, std::cos(kLatitude), std::sin(kLatitude)), up(0.0, 0.0, kStandardGravity);
  const double t = 300.0;
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  const int n = 300000;
  for (int k = 0; k < n; ++k) {
    sum += Eigen::AngleAxisd(kEarthRotationRate * (k + 0.5) * t / n, u).toRotationMatrix() * up * (t / n);
  }
  EXPECT_LT((turningGravityIntegral(u, up, t) - sum).norm(), 1e-9);
  // Gravity turns East first: the site moves east with the Earth.
  EXPECT_GT(turningGravityIntegral(u, up, t).x(), 0.0);
}

TEST(InertialFrameAlignmentTest, AStillBodyWithoutNoiseIsFoundExactly) {
  for (double yaw : {0.3, -2.0, 3.0}) {
    const Eigen::Matrix3d c = orientationFromEuler(EulerAngles{0.01, -0.02, yaw}).toRotationMatrix();
    Session s = record([&](double) { return c; }, 120.0, 0.0, 0.0);
    const InertialFrameResult r = alignInInertialFrame(s.track, s.input);
    ASSERT_TRUE(r.ok) << r.problem;
    EXPECT_LT(rotationVector(c * r.end_to_enu.transpose()).norm(), 1e-8) << yaw;
    EXPECT_LT(rotationVector(c * r.coarse_start_to_enu.transpose()).norm(), 1e-3) << yaw;
    EXPECT_NEAR(r.gravity, kStandardGravity, 1e-9);
  }
}

TEST(InertialFrameAlignmentTest, ASwayingBodyIsTrackedAndItsHeadingUnbiased) {
  // A sway of 1e-4 rad about East with a 20 s period and a lean of 25 urad: the gyros carry both.
  const Eigen::Matrix3d c = orientationFromEuler(EulerAngles{0.002, 0.001, 0.7}).toRotationMatrix();
  auto attitude = [&](double t) {
    const double lean = t < 60.0 ? 0.0 : 2.5e-5;
    return Eigen::Matrix3d(Eigen::AngleAxisd(1e-4 * std::sin(0.31416 * t) + lean, Eigen::Vector3d::UnitX()) * c);
  };
  Session s = record(attitude, 120.0, 0.0, 0.0);
  const InertialFrameResult r = alignInInertialFrame(s.track, s.input);
  ASSERT_TRUE(r.ok) << r.problem;
  EXPECT_LT(std::abs(headingError(r.end_to_enu, attitude(120.0))), 1e-8);
  EXPECT_LT(rotationVector(attitude(120.0) * r.end_to_enu.transpose()).norm(), 1e-8);
}

TEST(InertialFrameAlignmentTest, TheSigmaCoversTheErrorOverSeeds) {
  // The accelerometer's white noise (2.5e-4 m/s^2/sqrt(Hz), 3.5e-3 per 200 Hz sample) is what limits
  // it: N sqrt(12 / T^3) / (g Omega cos(lat)) = 0.38 mrad over 300 s.
  const Eigen::Matrix3d c = orientationFromEuler(EulerAngles{0.01, 0.005, -1.1}).toRotationMatrix();
  int within = 0;
  double sigma = 0.0;
  const int seeds = 12;
  for (int seed = 1; seed <= seeds; ++seed) {
    Session s = record([&](double) { return c; }, 300.0, 3.5e-3, 8.75e-6, seed);
    const InertialFrameResult r = alignInInertialFrame(s.track, s.input);
    ASSERT_TRUE(r.ok) << r.problem;
    sigma = std::sqrt(r.budget.total()(2, 2));
    const double error = headingError(r.end_to_enu, c);
    within += std::abs(error) < 2.0 * sigma;
    EXPECT_NEAR(r.velocity_random_walk, 3.5e-3 * std::sqrt(kDt), 0.25 * 3.5e-3 * std::sqrt(kDt)) << seed;
  }
  std::printf(
      "[ measured ] tracking, 300 s, accelerometer 3.5e-3 m/s^2 per sample: sigma %.3f mrad, %d of %d "
      "within 2 sigma\n",
      1e3 * sigma, within, seeds);
  EXPECT_NEAR(sigma, 0.38e-3, 0.08e-3);
  EXPECT_GE(within, 10);
}

TEST(InertialFrameAlignmentTest, AGyroBiasAndAnAccelerometerBiasEnterAsTheirResponsesSay) {
  // The responses the budget uses are the fit's own: a bias injected moves the heading by them.
  const Eigen::Matrix3d c = orientationFromEuler(EulerAngles{0.0, 0.0, 0.4}).toRotationMatrix();
  Session clean = record([&](double) { return c; }, 200.0, 0.0, 0.0);
  const InertialFrameResult r0 = alignInInertialFrame(clean.track, clean.input);
  ASSERT_TRUE(r0.ok);
  // A gyro bias of 1e-8 rad/s along the body's x: b_East / (Omega cos(lat)) of heading.
  BodyAttitudeTrack biased(0.0);
  {
    const Eigen::Vector3d u(0.0, std::cos(kLatitude), std::sin(kLatitude));
    const Eigen::Vector3d rate = c.transpose() * (kEarthRotationRate * u) + Eigen::Vector3d(1e-8, 0.0, 0.0);
    for (int k = 1; k <= 40000; ++k) biased.add(k * kDt, kDt, rate * kDt);
  }
  const InertialFrameResult rb = alignInInertialFrame(biased, clean.input);
  ASSERT_TRUE(rb.ok);
  const double moved = headingError(rb.end_to_enu, c);
  const double east = (c * Eigen::Vector3d(1e-8, 0.0, 0.0)).x();
  EXPECT_NEAR(std::abs(moved), std::abs(east) / horizontalEarthRate(kLatitude),
              0.05 * 1e-8 / horizontalEarthRate(kLatitude));
  // What the budget predicts for a 1e-8 bias: of the same size.
  InertialFrameInput with_bias = clean.input;
  with_bias.gyro_bias = 1e-8;
  const InertialFrameResult rs = alignInInertialFrame(clean.track, with_bias);
  EXPECT_NEAR(std::sqrt(rs.budget.residual_bias(2, 2)), 1e-8 / horizontalEarthRate(kLatitude),
              0.05 * 1e-8 / horizontalEarthRate(kLatitude));
}

TEST(InertialFrameAlignmentTest, TooShortOrWithoutAnAccelerometerIsRefused) {
  const Eigen::Matrix3d c = Eigen::Matrix3d::Identity();
  Session s = record([&](double) { return c; }, 5.0, 0.0, 0.0);
  EXPECT_FALSE(alignInInertialFrame(s.track, s.input).ok);
  InertialFrameInput none;
  none.latitude = kLatitude;
  EXPECT_FALSE(alignInInertialFrame(s.track, none).ok);
}

}  // namespace
}  // namespace core
}  // namespace hrg_gyro

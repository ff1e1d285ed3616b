#include "hrg_gyro/core/simulation/base_motion.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>

#include "core/testing/refusal.h"
#include "hrg_gyro/core/common/units.h"

namespace hrg_gyro {
namespace core {
namespace {

Eigen::Vector3d rotationVector(const Eigen::Matrix3d& r) {
  const Eigen::AngleAxisd a(r);
  return a.axis() * a.angle();
}

/// A lean of (2.5e-5, -1e-5, 0) rad from 10 s over 2 s, and a knock of 2e-5 rad about z at 20 s.
BaseMotionConfig leanAndKnock() {
  BaseMotionConfig c;
  c.leans.push_back({10.0, 2.0, Eigen::Vector3d(2.5e-5, -1e-5, 0.0)});
  BaseKnock k;
  k.time = 20.0;
  k.rotation = Eigen::Vector3d(0.0, 0.0, 2e-5);
  c.knocks.push_back(k);
  return c;
}

BaseMotionConfig everyMotion() {
  BaseMotionConfig c = leanAndKnock();
  c.sways.push_back({1e-4, 7.0, Eigen::Vector3d(0.6, 0.8, 0.0), 0.3});
  c.yaw_jitter = {1e-5, 0.5, 5.0, 20};
  c.vibration = {0.05, 10.0, 40.0, 20};
  return c;
}

TEST(BaseMotionTest, AStillBaseIsTheIdentity) {
  const BaseMotion still(BaseMotionConfig(), 1);
  EXPECT_FALSE(still.enabled());
  EXPECT_TRUE(still.rotationAt(12.3).isApprox(Eigen::Matrix3d::Identity(), 0.0));
  EXPECT_EQ(still.accelerationAt(4.0).norm(), 0.0);
}

TEST(BaseMotionTest, ALeanAndAKnockLeaveTheBaseTurnedByTheirRotation) {
  const BaseMotionConfig c = leanAndKnock();
  const BaseMotion m(c, 3);
  EXPECT_NEAR(rotationVector(m.rotationAt(9.999)).norm(), 0.0, 1e-15);
  EXPECT_LT((rotationVector(m.rotationAt(15.0)) - c.leans[0].rotation).norm(), 1e-15);
  // The knock rings, then the base stays turned by both: D_lean D_knock, in that order. The sum of the
  // rotation vectors is that only to first order: the product's is off it by half their cross product
  // (BCH), 2.7e-10 rad here.
  EXPECT_GT(std::abs(rotationVector(m.rotationAt(20.1)).z() - 2e-5), 1e-6);
  const Eigen::Vector3d& lean = c.leans[0].rotation;
  const Eigen::Matrix3d both = Eigen::AngleAxisd(lean.norm(), lean.normalized()).toRotationMatrix() *
                               Eigen::AngleAxisd(2e-5, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  EXPECT_LT((m.rotationAt(40.0) - both).cwiseAbs().maxCoeff(), 1e-16);
  const Eigen::Vector3d sum(2.5e-5, -1e-5, 2e-5), half_cross = 0.5 * lean.cross(c.knocks[0].rotation);
  EXPECT_LT((rotationVector(m.rotationAt(40.0)) - (sum + half_cross)).norm(), 1e-14);
}

TEST(BaseMotionTest, TheRateIsTheDerivativeOfTheRotation) {
  const BaseMotion m(everyMotion(), 7);
  for (double t : {3.0, 10.7, 20.02, 20.3, 33.3}) {
    Eigen::Matrix3d d;
    Eigen::Vector3d w;
    m.stateAt(t, &d, &w);
    const double h = 1e-6;
    const Eigen::Matrix3d derivative = (m.rotationAt(t + h) - m.rotationAt(t - h)) / (2.0 * h);
    const Eigen::Matrix3d skew = derivative * d.transpose();  // [w x]
    const Eigen::Vector3d numeric(skew(2, 1), skew(0, 2), skew(1, 0));
    EXPECT_LT((numeric - w).norm(), 1e-9 * std::max(1.0, w.norm()) + 1e-11) << t;
  }
}

TEST(BaseMotionTest, TheVibrationsMeanIsItsExactAverage) {
  const BaseMotion m(everyMotion(), 9);
  const double a = 5.0, b = 5.005;
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  const int n = 2000;
  for (int k = 0; k < n; ++k) sum += m.accelerationAt(a + (k + 0.5) * (b - a) / n);
  EXPECT_LT((sum / n - m.meanAccelerationOver(a, b)).norm(), 1e-7);
  // Its rms per axis is the one asked for (within the draw of 20 sinusoids over 100 s).
  double squares = 0.0;
  const int samples = 200000;
  for (int k = 0; k < samples; ++k) squares += m.accelerationAt(1e-3 * k).squaredNorm();
  EXPECT_NEAR(std::sqrt(squares / samples / 3.0), 0.05, 0.005);
}

TEST(BaseMotionTest, TheSectionIsReadAndEveryBadKeyNamed) {
  const YAML::Node root = YAML::Load(
      "leans: [{time: 60.0, rotation: [2.5e-5, 0.0, 0.0]}]\n"
      "knocks: [{time: 30.0, rotation: [0.0, 2e-5, 0.0], ring: 1.0}]\n"
      "sways: [{amplitude: 1.0e-4, period: 10.0, axis: [0.0, 1.0, 0.0]}]\n"
      "yaw_jitter: {rms: 1.0e-5}\n"
      "vibration: {rms: 0.05, low: 10.0, high: 40.0}\n");
  const BaseMotionConfig c = parseBaseMotion(YamlField(root, "base_motion"));
  ASSERT_EQ(c.leans.size(), 1u);
  EXPECT_EQ(c.leans[0].duration, 1.0);
  EXPECT_EQ(c.knocks[0].ring, 1.0);
  EXPECT_EQ(c.sways[0].axis, Eigen::Vector3d::UnitY());
  EXPECT_EQ(c.vibration.rms, 0.05);
  EXPECT_TRUE(c.enabled());
  const std::pair<const char*, const char*> bad[] = {
      {"leans: [{time: 1.0, rotation: [0.2, 0, 0]}]", "base_motion.leans[0].rotation"},
      {"leans: [{time: 1.0, duration: 0.0, rotation: [0, 0, 1e-5]}]", "base_motion.leans[0].duration"},
      {"sways: [{amplitude: 1e-4, period: 10.0, axis: [1.0, 1.0, 0.0]}]", "base_motion.sways[0].axis"},
      {"sways: [{amplitude: 1e-4, period: -1.0}]", "base_motion.sways[0].period"},
      {"vibration: {rms: 0.05, low: 40.0, high: 10.0}", "base_motion.vibration.low"},
      {"yaw_jitter: {rms: -1.0}", "base_motion.yaw_jitter.rms"},
      {"knocks: [{time: 1.0, rotation: [0, 0, 1e-5], ring_decay: 0.0}]", "base_motion.knocks[0].ring_decay"},
      {"sway: []", "sway"},
  };
  for (const auto& b : bad) {
    const YAML::Node node = YAML::Load(b.first);
    const std::string key = refusedKey([&] { parseBaseMotion(YamlField(node, "base_motion")); });
    EXPECT_NE(key.find(b.second), std::string::npos) << b.first << ": " << key;
  }
}

}  // namespace
}  // namespace core
}  // namespace hrg_gyro

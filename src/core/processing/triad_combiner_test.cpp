// The triad combiner: three axes' outputs of one stamp through M and the bias into one body-frame
// sample with the covariance M diag(sigma^2) M^T; a missing, flagged or mismatched axis gives a
// gap and never a mix; the result does not depend on the order the axes arrive in; a stopped
// axis costs bounded memory; a reload takes effect between samples; nothing non-finite comes out
// of any input (a fuzz-like random test).
#include "hrg_gyro/core/processing/triad_combiner.h"

#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <random>

#include "hrg_gyro/core/common/yaml_field.h"
#include "hrg_gyro/core/processing/gyro_processor.h"

namespace hrg_gyro {
namespace core {
namespace {

constexpr Nanoseconds kPeriod = 5000000;  // 200 Hz
constexpr double kDt = 0.005;
constexpr Nanoseconds kStart = 1700000000LL * 1000000000LL;  // a wall-clock stamp: dt must keep full precision

std::shared_ptr<const TriadParameters> misalignedTriad() {
  auto t = std::make_shared<TriadParameters>();
  t->axes = {{"gx", "gy", "gz"}};
  t->frame_id = "imu_link";
  t->axis_to_body << 1.0002, -3e-3, 1.2e-3, 4e-3, 0.9997, -2e-3, -1e-3, 2.5e-3, 1.0001;
  t->bias << 1e-5, -2e-5, 3e-6;
  return t;
}

// The increment of axis `axis` at sample i: each axis turning at its own rate, with a wobble.
double dalphaOf(std::size_t axis, std::int64_t i) {
  const double rates[3] = {0.1, -0.05, 0.2};
  return rates[axis] * kDt + 1e-6 * std::sin(0.01 * static_cast<double>(i) + static_cast<double>(axis));
}

AxisOutput output(std::size_t axis, std::int64_t i, double variance = NAN) {
  AxisOutput o;
  o.stamp = kStart + i * kPeriod;
  o.dt = kDt;
  o.dalpha = dalphaOf(axis, i);
  o.rate_variance = variance;
  return o;
}

bool sameBits(double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; }

bool sameSample(const TriadBodySample& a, const TriadBodySample& b) {
  if (a.stamp != b.stamp || a.flags != b.flags || a.missing_axes != b.missing_axes || !sameBits(a.dt, b.dt)) {
    return false;
  }
  for (int i = 0; i < 3; ++i) {
    if (!sameBits(a.delta_angle(i), b.delta_angle(i)) || !sameBits(a.angular_velocity(i), b.angular_velocity(i))) {
      return false;
    }
    for (int j = 0; j < 3; ++j) {
      if (!sameBits(a.covariance(i, j), b.covariance(i, j))) return false;
    }
  }
  return true;
}

void expectFiniteAndSymmetric(const TriadBodySample& s) {
  ASSERT_TRUE(std::isfinite(s.dt));
  ASSERT_TRUE(s.delta_angle.allFinite());
  ASSERT_TRUE(s.angular_velocity.allFinite());
  ASSERT_TRUE(s.covariance.allFinite());
  ASSERT_EQ(s.covariance, s.covariance.transpose());
}

TEST(TriadCombinerTest, CombinesOneStampThroughTheMatrixAndBias) {
  const auto triad = misalignedTriad();
  TriadCombiner combiner(TriadCombinerSettings(), triad);
  std::vector<TriadBodySample> out;
  const double variances[3] = {4e-6, 9e-6, 2.5e-5};
  for (std::size_t a = 0; a < 3; ++a) {
    EXPECT_TRUE(out.empty()) << "a sample before every axis has it";
    combiner.add(a, output(a, 7, variances[a]), &out);
  }
  ASSERT_EQ(out.size(), 1u);
  const TriadBodySample& s = out[0];
  EXPECT_EQ(s.stamp, kStart + 7 * kPeriod);
  EXPECT_EQ(s.dt, kDt);
  EXPECT_EQ(s.flags, 0);
  EXPECT_EQ(s.missing_axes, 0);
  const Eigen::Vector3d dalpha(dalphaOf(0, 7), dalphaOf(1, 7), dalphaOf(2, 7));
  const Eigen::Vector3d expected = triad->axis_to_body * dalpha - triad->bias * kDt;
  EXPECT_LT((s.delta_angle - expected).cwiseAbs().maxCoeff(), 1e-18);
  // omega_body = M omega_axis - bias, the file's equation, from the axes' rates
  const Eigen::Vector3d omega = triad->axis_to_body * (dalpha / kDt) - triad->bias;
  EXPECT_LT((s.angular_velocity - omega).cwiseAbs().maxCoeff(), 1e-15);
  const Eigen::Matrix3d covariance = triad->axis_to_body *
                                     Eigen::Vector3d(variances[0], variances[1], variances[2]).asDiagonal() *
                                     triad->axis_to_body.transpose();
  EXPECT_LT((s.covariance - covariance).cwiseAbs().maxCoeff(), 1e-20);
  EXPECT_EQ(s.covariance, s.covariance.transpose());
  EXPECT_GT(Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(s.covariance).eigenvalues().minCoeff(), 0.0);
  EXPECT_EQ(combiner.counters().integrated, 1u);
}

TEST(TriadCombinerTest, TheOrderOfArrivalDoesNotChangeABit) {
  // Three complete streams, one with a dropped sample, delivered in random interleavings: the
  // output is the same sample for sample.
  std::vector<std::vector<AxisOutput>> streams(3);
  for (std::size_t a = 0; a < 3; ++a) {
    for (std::int64_t i = 0; i < 400; ++i) {
      if (a == 1 && i == 150) continue;  // dropped
      AxisOutput o = output(a, i, 1e-6 * (1.0 + static_cast<double>(a)) * (1.0 + 1e-3 * static_cast<double>(i)));
      if (a == 1 && i == 151) o.dt = 2 * kDt;  // the processor's interval spans the dropped one
      streams[a].push_back(o);
    }
  }
  std::vector<TriadBodySample> reference;
  {
    TriadCombiner combiner(TriadCombinerSettings(), misalignedTriad());
    for (std::size_t i = 0; i < 400; ++i) {
      for (std::size_t a = 0; a < 3; ++a) {
        if (i < streams[a].size()) combiner.add(a, streams[a][i], &reference);
      }
    }
  }
  ASSERT_EQ(reference.size(), 400u);
  std::mt19937_64 rng(11);
  for (int trial = 0; trial < 20; ++trial) {
    TriadCombiner combiner(TriadCombinerSettings(), misalignedTriad());
    std::vector<TriadBodySample> out;
    std::array<std::size_t, 3> next{{0, 0, 0}};
    while (next[0] < streams[0].size() || next[1] < streams[1].size() || next[2] < streams[2].size()) {
      const std::size_t a = rng() % 3;
      // bursts, an axis up to 100 samples (0.5 s, half the wait) ahead of the slowest
      const std::size_t slowest = *std::min_element(next.begin(), next.end());
      for (std::size_t n = 1 + rng() % 50; n > 0 && next[a] < streams[a].size() && next[a] < slowest + 100; --n) {
        combiner.add(a, streams[a][next[a]++], &out);
      }
    }
    ASSERT_EQ(out.size(), reference.size()) << "trial " << trial;
    for (std::size_t i = 0; i < out.size(); ++i) ASSERT_TRUE(sameSample(out[i], reference[i])) << trial << " " << i;
    EXPECT_EQ(combiner.counters().timeouts, 0u);
  }
}

TEST(TriadCombinerTest, ADroppedAxisSampleIsAGapNeverAMix) {
  TriadCombiner combiner(TriadCombinerSettings(), misalignedTriad());
  std::vector<TriadBodySample> out;
  for (std::int64_t i = 0; i < 20; ++i) {
    for (std::size_t a = 0; a < 3; ++a) {
      if (a == 2 && i == 10) continue;  // z's sample at 10 lost
      AxisOutput o = output(a, i);
      if (a == 2 && i == 11) {
        o.dt = 2 * kDt;  // its next increment covers both intervals
        o.dalpha = dalphaOf(2, 10) + dalphaOf(2, 11);
      }
      combiner.add(a, o, &out);
    }
  }
  ASSERT_EQ(out.size(), 20u);
  for (std::int64_t i = 0; i < 20; ++i) {
    const TriadBodySample& s = out[static_cast<std::size_t>(i)];
    EXPECT_EQ(s.stamp, kStart + i * kPeriod);
    EXPECT_NEAR(s.dt, kDt, 1e-15) << i << ": a gap covers the time since the previous triad sample";
    if (i == 10 || i == 11) {
      EXPECT_EQ(s.flags, kTriadFlagGap) << i;
      EXPECT_EQ(s.delta_angle, Eigen::Vector3d::Zero()) << i;
      EXPECT_EQ(s.angular_velocity, Eigen::Vector3d::Zero()) << i;
      EXPECT_EQ(s.missing_axes, i == 10 ? 4 : 0) << i;
    } else {
      EXPECT_EQ(s.flags, 0) << i;
      EXPECT_NE(s.delta_angle, Eigen::Vector3d::Zero()) << i;
    }
  }
  EXPECT_EQ(combiner.counters().axes[2].missing, 1u);
  EXPECT_EQ(combiner.counters().axes[2].mismatched, 1u);
  EXPECT_EQ(combiner.counters().axes[0].mismatched, 0u);
  EXPECT_EQ(combiner.counters().gaps, 2u);
}

TEST(TriadCombinerTest, AnAxisFlagIsTheTriadsFlag) {
  TriadCombiner combiner(TriadCombinerSettings(), misalignedTriad());
  std::vector<TriadBodySample> out;
  const std::uint8_t flags[4] = {kFlagGap, kFlagReset, kFlagFrequencyUnknown, kFlagFrequencyOutOfRange};
  for (std::int64_t i = 0; i < 4; ++i) {
    for (std::size_t a = 0; a < 3; ++a) {
      AxisOutput o = output(a, i);
      if (a == 1) o.flags = flags[i];
      if (a == 1 && (flags[i] & (kFlagGap | kFlagReset))) o.dalpha = 0.0;
      combiner.add(a, o, &out);
    }
  }
  ASSERT_EQ(out.size(), 4u);
  EXPECT_EQ(out[0].flags, kTriadFlagGap);
  EXPECT_EQ(out[1].flags, kTriadFlagReset);
  EXPECT_FALSE(out[0].integrated());
  EXPECT_FALSE(out[1].integrated());
  EXPECT_EQ(out[1].delta_angle, Eigen::Vector3d::Zero());
  // A frequency flag: the model's end values were held; the values are combined and flagged.
  EXPECT_EQ(out[2].flags, kTriadFlagAxisFlagged);
  EXPECT_EQ(out[3].flags, kTriadFlagAxisFlagged);
  EXPECT_TRUE(out[2].integrated());
  EXPECT_NE(out[2].delta_angle, Eigen::Vector3d::Zero());
  EXPECT_EQ(combiner.counters().axes[1].flagged, 4u);
}

TEST(TriadCombinerTest, StampsWithinTheToleranceAreOneInstant) {
  // Auto tolerance: a quarter period. Stamps 1 ms apart at 200 Hz are one instant; 2 ms are not.
  TriadCombiner combiner(TriadCombinerSettings(), misalignedTriad());
  std::vector<TriadBodySample> out;
  for (std::size_t a = 0; a < 3; ++a) {
    AxisOutput o = output(a, 0);
    o.stamp += static_cast<Nanoseconds>(a) * 500000;
    combiner.add(a, o, &out);
  }
  ASSERT_EQ(out.size(), 1u);
  EXPECT_EQ(out[0].flags, 0);
  EXPECT_EQ(out[0].stamp, kStart);  // the first axis's
  for (std::size_t a = 0; a < 3; ++a) {
    AxisOutput o = output(a, 1);
    o.stamp += a == 2 ? 2000000 : 0;
    combiner.add(a, o, &out);
  }
  combiner.flush(&out);
  ASSERT_EQ(out.size(), 3u);
  EXPECT_EQ(out[1].missing_axes, 4);
  EXPECT_EQ(out[2].missing_axes, 3);
  EXPECT_EQ(out[2].stamp, kStart + kPeriod + 2000000);
  // An explicit tolerance wins: 3 ms makes them one instant again.
  TriadCombinerSettings wide;
  wide.stamp_tolerance = 0.003;
  TriadCombiner tolerant(wide, misalignedTriad());
  out.clear();
  for (std::size_t a = 0; a < 3; ++a) {
    AxisOutput o = output(a, 1);
    o.stamp += a == 2 ? 2000000 : 0;
    tolerant.add(a, o, &out);
  }
  ASSERT_EQ(out.size(), 1u);
  EXPECT_EQ(out[0].flags, 0);
}

TEST(TriadCombinerTest, AStoppedAxisCostsBoundedMemoryAndGivesGaps) {
  TriadCombinerSettings settings;
  settings.max_wait = 0.1;  // 20 samples at 200 Hz
  TriadCombiner combiner(settings, misalignedTriad());
  std::vector<TriadBodySample> out;
  for (std::int64_t i = 0; i < 1000; ++i) {
    for (std::size_t a = 0; a < 3; ++a) {
      if (a == 1 && i >= 100) continue;  // y stops
      combiner.add(a, output(a, i), &out);
    }
    ASSERT_LE(combiner.pending(0), 22u) << i;
  }
  // Every stamp came out once: combined while y ran, then a gap once waited for 0.1 s.
  ASSERT_GE(out.size(), 1000u - 22u);
  for (std::size_t i = 0; i < out.size(); ++i) {
    EXPECT_EQ(out[i].stamp, kStart + static_cast<Nanoseconds>(i) * kPeriod);
    EXPECT_EQ(out[i].flags, i < 100 ? 0 : kTriadFlagGap) << i;
    if (i >= 100) {
      EXPECT_EQ(out[i].missing_axes, 2) << i;
    }
  }
  EXPECT_GT(combiner.counters().timeouts, 800u);
  // max_pending bounds it whatever the stamps do.
  settings.max_wait = 1e9;
  settings.max_pending = 64;
  TriadCombiner bounded(settings, misalignedTriad());
  out.clear();
  for (std::int64_t i = 0; i < 10000; ++i) {
    bounded.add(0, output(0, i), &out);
    ASSERT_LE(bounded.pending(0), 64u);
  }
  EXPECT_GE(out.size(), 10000u - 64u);
  EXPECT_TRUE(std::all_of(out.begin(), out.end(), [](const TriadBodySample& s) { return s.missing_axes == 6; }));
  bounded.flush(&out);
  EXPECT_EQ(out.size(), 10000u);
  EXPECT_EQ(bounded.pending(0), 0u);
}

TEST(TriadCombinerTest, AReloadTakesEffectBetweenSamples) {
  TriadCombiner combiner(TriadCombinerSettings(), misalignedTriad());
  std::vector<TriadBodySample> out;
  auto add_stamp = [&](std::int64_t i) {
    for (std::size_t a = 0; a < 3; ++a) combiner.add(a, output(a, i), &out);
  };
  add_stamp(0);
  combiner.add(0, output(0, 1), &out);  // x of the next stamp is already in
  auto reloaded = std::make_shared<TriadParameters>(*misalignedTriad());
  reloaded->axis_to_body.setIdentity();
  reloaded->bias << 1e-3, 0.0, 0.0;
  combiner.setParameters(reloaded);
  combiner.add(1, output(1, 1), &out);
  combiner.add(2, output(2, 1), &out);
  ASSERT_EQ(out.size(), 2u);
  const Eigen::Vector3d dalpha(dalphaOf(0, 1), dalphaOf(1, 1), dalphaOf(2, 1));
  EXPECT_EQ(out[1].delta_angle, dalpha - reloaded->bias * kDt);
  EXPECT_EQ(&combiner.parameters(), reloaded.get());
  auto bad = std::make_shared<TriadParameters>(*reloaded);
  bad->bias(1) = NAN;
  EXPECT_THROW(combiner.setParameters(bad), std::invalid_argument);
  EXPECT_EQ(&combiner.parameters(), reloaded.get()) << "a refused reload keeps the previous triad";
}

TEST(TriadCombinerTest, ABagLoopStartsANewEpochOnEveryAxis) {
  // Two passes of the same 50 stamps, the axes skewed by up to 7 samples at the loop; the first
  // sample after the loop carries the processor's reset flag.
  std::vector<std::vector<AxisOutput>> streams(3);
  for (std::size_t a = 0; a < 3; ++a) {
    for (int pass = 0; pass < 2; ++pass) {
      for (std::int64_t i = 0; i < 50; ++i) {
        AxisOutput o = output(a, i);
        if (pass == 1 && i == 0) o.flags = kFlagReset;
        streams[a].push_back(o);
      }
    }
  }
  TriadCombiner combiner(TriadCombinerSettings(), misalignedTriad());
  std::vector<TriadBodySample> out;
  const std::size_t skew[3] = {7, 0, 3};
  for (std::size_t k = 0; k < 107; ++k) {
    for (std::size_t a = 0; a < 3; ++a) {
      if (k >= skew[a] && k - skew[a] < 100) combiner.add(a, streams[a][k - skew[a]], &out);
    }
  }
  ASSERT_EQ(out.size(), 100u);
  for (std::size_t i = 0; i < 100; ++i) {
    EXPECT_EQ(out[i].stamp, kStart + static_cast<Nanoseconds>(i % 50) * kPeriod) << i;
    EXPECT_EQ(out[i].flags, i == 50 ? kTriadFlagReset : 0) << i;
  }
  EXPECT_EQ(combiner.counters().axes[0].epochs, 1u);
  EXPECT_EQ(combiner.counters().resets, 1u);
}

TEST(TriadCombinerTest, AVarianceStandsUntilTheNextOne) {
  TriadCombinerSettings settings;
  settings.initial_rate_variance = 2e-3;
  const auto identity = std::make_shared<TriadParameters>();
  TriadCombiner combiner(settings, identity);
  std::vector<TriadBodySample> out;
  const double given[4] = {NAN, 5e-6, -1.0, INFINITY};  // none, one, then two that are not variances
  for (std::int64_t i = 0; i < 4; ++i) {
    combiner.add(0, output(0, i, given[i]), &out);
    combiner.add(1, output(1, i), &out);
    combiner.add(2, output(2, i, 7e-6), &out);
  }
  ASSERT_EQ(out.size(), 4u);
  EXPECT_EQ(out[0].covariance.diagonal(), Eigen::Vector3d(2e-3, 2e-3, 7e-6));
  for (std::size_t i = 1; i < 4; ++i) EXPECT_EQ(out[i].covariance.diagonal(), Eigen::Vector3d(5e-6, 2e-3, 7e-6));
  EXPECT_EQ(combiner.rateVariance(0), 5e-6);
}

TEST(TriadCombinerTest, BadSettingsNameTheirParameter) {
  auto key = [](TriadCombinerSettings s) {
    try {
      s.validate();
    } catch (const ConfigError& e) {
      return e.key();
    }
    return std::string();
  };
  TriadCombinerSettings s;
  EXPECT_EQ(key(s), "");
  s.stamp_tolerance = -1e-3;
  EXPECT_EQ(key(s), "stamp_tolerance");
  s = TriadCombinerSettings();
  s.max_wait = 0.0;
  EXPECT_EQ(key(s), "max_wait");
  s = TriadCombinerSettings();
  s.max_pending = 0;
  EXPECT_EQ(key(s), "max_pending");
  s = TriadCombinerSettings();
  s.initial_rate_variance = NAN;
  EXPECT_EQ(key(s), "initial_angular_velocity_variance");
  EXPECT_THROW(TriadCombiner(s, misalignedTriad()), std::invalid_argument);
}

// A value from a menu that a broken stream, a bad clock and a fuzzer would send.
double wild(std::mt19937_64& rng, double typical) {
  switch (rng() % 12) {
    case 0:
      return NAN;
    case 1:
      return INFINITY;
    case 2:
      return -INFINITY;
    case 3:
      return 0.0;
    case 4:
      return -typical;
    case 5:
      return std::numeric_limits<double>::max();
    case 6:
      return std::numeric_limits<double>::denorm_min();
    case 7:
      return 1e300;
    default:
      return typical * (1.0 + 0.01 * static_cast<double>(rng() % 100));
  }
}

TEST(TriadCombinerTest, NothingNonFiniteComesOutOfAnyInput) {
  std::mt19937_64 rng(2024);
  for (int run = 0; run < 40; ++run) {
    TriadCombinerSettings settings;
    settings.max_wait = run % 2 ? 0.02 : 5.0;
    settings.max_pending = 1 + rng() % 200;
    settings.stamp_tolerance = run % 3 ? 0.0 : 1e-3;
    TriadCombiner combiner(settings, misalignedTriad());
    std::vector<TriadBodySample> out;
    std::array<Nanoseconds, 3> stamp{{kStart, kStart, kStart}};
    for (int k = 0; k < 3000; ++k) {
      const std::size_t a = rng() % 3;
      AxisOutput o;
      switch (rng() % 10) {
        case 0:
          stamp[a] = static_cast<Nanoseconds>(rng());  // anywhere, negative included
          break;
        case 1:  // backwards or repeated (wrapping: no overflow in the test itself)
          stamp[a] = static_cast<Nanoseconds>(static_cast<std::uint64_t>(stamp[a]) - (rng() % 10) * kPeriod);
          break;
        default:
          stamp[a] = static_cast<Nanoseconds>(static_cast<std::uint64_t>(stamp[a]) + kPeriod + (rng() % 3) * 1000);
      }
      o.stamp = stamp[a];
      o.dt = rng() % 4 ? kDt : wild(rng, kDt);
      o.dalpha = rng() % 4 ? 1e-3 : wild(rng, 1e-3);
      o.flags = static_cast<std::uint8_t>(rng() % 5 ? 0 : rng() % 256);
      o.rate_variance = rng() % 2 ? 1e-6 : wild(rng, 1e-6);
      combiner.add(a, o, &out);
      if (k % 500 == 0) {
        auto t = std::make_shared<TriadParameters>(*misalignedTriad());
        t->bias(0) = 1e-4 * static_cast<double>(rng() % 3);
        combiner.setParameters(t);
      }
      for (std::size_t b = 0; b < 3; ++b) ASSERT_LE(combiner.pending(b), settings.max_pending);
    }
    combiner.flush(&out);
    for (const TriadBodySample& s : out) {
      expectFiniteAndSymmetric(s);
      ASSERT_GT(s.covariance.diagonal().minCoeff(), 0.0);
      ASSERT_GE(s.dt, 0.0);
      if (s.integrated()) {
        ASSERT_EQ(s.missing_axes, 0);
        ASSERT_GT(s.dt, 0.0);
      } else {
        ASSERT_EQ(s.delta_angle, Eigen::Vector3d::Zero());
      }
    }
    const TriadCounters& c = combiner.counters();
    EXPECT_EQ(c.samples, out.size());
    EXPECT_EQ(combiner.pending(0) + combiner.pending(1) + combiner.pending(2), 0u);
  }
}

}  // namespace
}  // namespace core
}  // namespace hrg_gyro

// The triad combiner: three axes' outputs of one stamp through M and the bias into one body-frame
// sample with the covariance M diag(sigma^2) M^T; a missing, flagged or mismatched axis gives a
// gap and never a mix; the result does not depend on the order the axes arrive in; a stopped
// axis costs bounded memory; a reload takes effect between samples; a stray sample (stamp far ahead,
// back, zero; an interval of 1e-300 s) costs that sample only; nothing non-finite, no stamp 0 and
// no stamp going back without FLAG_RESET comes out of any input (a fuzz-like random test).
#include "hrg_gyro/core/processing/triad_combiner.h"

#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <cstring>
#include <functional>
#include <limits>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include "core/testing/refusal.h"
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
  // Three complete streams, one with a dropped sample (its stamp carried into the next), delivered
  // in random interleavings: the output is the same sample for sample.
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
  ASSERT_EQ(reference.size(), 399u);
  EXPECT_EQ(reference[150].stamp, kStart + 151 * kPeriod);
  EXPECT_EQ(reference[150].flags, 0);
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

TEST(TriadCombinerTest, AnAxisThatSkippedAStampIsCombinedOverBothIntervals) {
  // z's processor dropped its sample at 10 (a bad value, a glitched stamp): its output at 11 spans
  // both intervals. Stamp 10 is not emitted; 11 is combined over 2 dt, nothing lost, never a mix.
  // Every delivery order gives the same.
  for (int order = 0; order < 2; ++order) {
    TriadCombiner combiner(TriadCombinerSettings(), misalignedTriad());
    std::vector<TriadBodySample> out;
    for (std::int64_t i = 0; i < 20; ++i) {
      for (std::size_t k = 0; k < 3; ++k) {
        const std::size_t a = order == 0 ? k : 2 - k;
        if (a == 2 && i == 10) continue;  // z's sample at 10 lost
        AxisOutput o = output(a, i);
        if (a == 2 && i == 11) {
          o.dt = 2 * kDt;  // its next increment covers both intervals
          o.dalpha = dalphaOf(2, 10) + dalphaOf(2, 11);
        }
        combiner.add(a, o, &out);
      }
    }
    ASSERT_EQ(out.size(), 19u);
    const auto triad = misalignedTriad();
    for (std::size_t n = 0; n < out.size(); ++n) {
      const std::int64_t i = n < 10 ? static_cast<std::int64_t>(n) : static_cast<std::int64_t>(n) + 1;
      const TriadBodySample& s = out[n];
      EXPECT_EQ(s.stamp, kStart + i * kPeriod);
      EXPECT_EQ(s.flags, 0) << i;
      const double dt = i == 11 ? 2 * kDt : kDt;
      EXPECT_NEAR(s.dt, dt, 1e-15) << i;
      Eigen::Vector3d dalpha(dalphaOf(0, i), dalphaOf(1, i), dalphaOf(2, i));
      if (i == 11) dalpha += Eigen::Vector3d(dalphaOf(0, 10), dalphaOf(1, 10), dalphaOf(2, 10));
      const Eigen::Vector3d expected = triad->axis_to_body * dalpha - triad->bias * dt;
      EXPECT_LT((s.delta_angle - expected).cwiseAbs().maxCoeff(), 1e-15) << i;
    }
    EXPECT_EQ(combiner.counters().carried, 1u);
    EXPECT_EQ(combiner.counters().gaps, 0u);
  }
}

TEST(TriadCombinerTest, AnAxisWhoseIntervalDoesNotMatchIsAGapNeverAMix) {
  // z lost its sample at 10, and its next increment does not say so (dt of one interval): the
  // stamp 10 is a gap, and so is 11 when the others' carried intervals and z's do not agree.
  TriadCombiner combiner(TriadCombinerSettings(), misalignedTriad());
  std::vector<TriadBodySample> out;
  for (std::int64_t i = 0; i < 20; ++i) {
    for (std::size_t a = 0; a < 3; ++a) {
      if (a == 2 && i == 10) continue;
      combiner.add(a, output(a, i), &out);
    }
  }
  ASSERT_EQ(out.size(), 20u);
  for (std::int64_t i = 0; i < 20; ++i) {
    const TriadBodySample& s = out[static_cast<std::size_t>(i)];
    EXPECT_EQ(s.stamp, kStart + i * kPeriod);
    EXPECT_NEAR(s.dt, kDt, 1e-15) << i << ": a gap covers the time since the previous triad sample";
    if (i == 10) {
      EXPECT_EQ(s.flags, kTriadFlagGap) << i;
      EXPECT_EQ(s.delta_angle, Eigen::Vector3d::Zero()) << i;
      EXPECT_EQ(s.missing_axes, 4) << i;
    } else {
      EXPECT_EQ(s.flags, 0) << i;
      EXPECT_NE(s.delta_angle, Eigen::Vector3d::Zero()) << i;
    }
  }
  EXPECT_EQ(combiner.counters().axes[2].missing, 1u);
  EXPECT_EQ(combiner.counters().gaps, 1u);
}

TEST(TriadCombinerTest, AnAxisFlagIsTheTriadsFlag) {
  TriadCombiner combiner(TriadCombinerSettings(), misalignedTriad());
  std::vector<TriadBodySample> out;
  const std::uint8_t flags[5] = {kFlagGap, kFlagReset, kFlagFrequencyUnknown, kFlagFrequencyOutOfRange,
                                 kFlagPrecessing};
  for (std::int64_t i = 0; i < 5; ++i) {
    for (std::size_t a = 0; a < 3; ++a) {
      AxisOutput o = output(a, i);
      if (a == 1) o.flags = flags[i];
      if (a == 1 && (flags[i] & (kFlagGap | kFlagReset))) o.dalpha = 0.0;
      combiner.add(a, o, &out);
    }
  }
  ASSERT_EQ(out.size(), 5u);
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
  // A wave turned on command: combined as measured and flagged (its axis's variance says the rest).
  EXPECT_EQ(out[4].flags, kTriadFlagPrecessing);
  EXPECT_TRUE(out[4].integrated());
  EXPECT_EQ(combiner.counters().precessing, 1u);
  EXPECT_EQ(combiner.counters().axes[1].flagged, 5u);
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
  // Two passes of the same 150 stamps (0.75 s: further back than backward_reset), the axes skewed
  // by up to 7 samples at the loop; the first sample after the loop carries the processor's reset
  // flag. Each axis's first jump_persist - 1 samples of the second pass are dropped as jumps; the
  // first triad sample of the new epoch carries FLAG_RESET.
  constexpr std::size_t kPass = 150;
  std::vector<std::vector<AxisOutput>> streams(3);
  for (std::size_t a = 0; a < 3; ++a) {
    for (int pass = 0; pass < 2; ++pass) {
      for (std::int64_t i = 0; i < static_cast<std::int64_t>(kPass); ++i) {
        AxisOutput o = output(a, i);
        if (pass == 1 && i == 0) o.flags = kFlagReset;
        streams[a].push_back(o);
      }
    }
  }
  TriadCombiner combiner(TriadCombinerSettings(), misalignedTriad());
  std::vector<TriadBodySample> out;
  const std::size_t skew[3] = {7, 0, 3};
  for (std::size_t k = 0; k < 2 * kPass + 7; ++k) {
    for (std::size_t a = 0; a < 3; ++a) {
      if (k >= skew[a] && k - skew[a] < 2 * kPass) combiner.add(a, streams[a][k - skew[a]], &out);
    }
  }
  const std::size_t dropped = static_cast<std::size_t>(TriadCombinerSettings().jump_persist - 1);
  ASSERT_EQ(out.size(), 2 * kPass - dropped);
  for (std::size_t i = 0; i < out.size(); ++i) {
    const std::size_t k = i < kPass ? i : i - kPass + dropped;
    EXPECT_EQ(out[i].stamp, kStart + static_cast<Nanoseconds>(k) * kPeriod) << i;
    EXPECT_EQ(out[i].flags, i == kPass ? kTriadFlagReset : 0) << i;
  }
  for (std::size_t a = 0; a < 3; ++a) {
    EXPECT_EQ(combiner.counters().axes[a].epochs, 1u);
    EXPECT_EQ(combiner.counters().axes[a].stamp_jumps, dropped);
  }
  EXPECT_EQ(combiner.counters().resets, 1u);
}

TEST(TriadCombinerTest, OneStraySampleCostsThatSampleOnly) {
  // A stray output on one axis (1000 s ahead, two periods back, stamp 0, an interval of 1e-300 s or
  // a rate of 1e6 rad/s), one on each of the others: every stamp is still combined, bit for bit as
  // without them.
  TriadCombiner clean(TriadCombinerSettings(), misalignedTriad()), glitched(TriadCombinerSettings(), misalignedTriad());
  std::vector<TriadBodySample> a, b;
  for (std::int64_t i = 0; i < 400; ++i) {
    for (std::size_t axis = 0; axis < 3; ++axis) {
      clean.add(axis, output(axis, i), &a);
      if (i % 50 == 10) {
        AxisOutput stray = output(axis, i);
        switch ((i / 50 + static_cast<std::int64_t>(axis)) % 5) {
          case 0:
            stray.stamp += 1000LL * 1000000000LL;
            break;
          case 1:
            stray.stamp -= 2 * kPeriod;
            break;
          case 2:
            stray.stamp = 0;
            break;
          case 3:
            stray.dt = 1e-300;
            break;
          default:
            stray.dalpha = 1e6 * kDt;
        }
        glitched.add(axis, stray, &b);
      }
      glitched.add(axis, output(axis, i), &b);
    }
  }
  ASSERT_EQ(a.size(), 400u);
  ASSERT_EQ(b.size(), a.size());
  for (std::size_t i = 0; i < a.size(); ++i) ASSERT_TRUE(sameSample(a[i], b[i])) << i;
  std::uint64_t dropped = 0;
  for (const TriadAxisCounters& c : glitched.counters().axes) {
    dropped += c.stamp_jumps + c.out_of_order + c.bad_stamp + c.invalid;
    EXPECT_EQ(c.epochs, 0u);
  }
  EXPECT_EQ(dropped, 3u * 8u);
  EXPECT_EQ(glitched.counters().integrated, 400u);
}

TEST(TriadCombinerTest, AVarianceThatIsNoGyrosIsNotTaken) {
  const auto identity = std::make_shared<TriadParameters>();
  TriadCombiner combiner(TriadCombinerSettings(), identity);
  std::vector<TriadBodySample> out;
  combiner.add(0, output(0, 0, 4e-6), &out);
  combiner.add(1, output(1, 0), &out);
  combiner.add(2, output(2, 0), &out);
  combiner.add(0, output(0, 1, std::numeric_limits<double>::denorm_min()), &out);
  combiner.add(1, output(1, 1, 1e-30), &out);
  combiner.add(2, output(2, 1), &out);
  ASSERT_EQ(out.size(), 2u);
  EXPECT_EQ(out[1].covariance(0, 0), 4e-6);
  EXPECT_EQ(out[1].covariance(1, 1), TriadCombinerSettings().initial_rate_variance);
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
  EXPECT_EQ(refusedKey([] { TriadCombinerSettings().validate(); }), "accepted");
  // Each setting spoiled alone in otherwise default settings, and the key the refusal must name.
  const std::vector<std::pair<std::function<void(TriadCombinerSettings*)>, std::string>> spoiled = {
      {[](TriadCombinerSettings* s) { s->stamp_tolerance = -1e-3; }, "stamp_tolerance"},
      {[](TriadCombinerSettings* s) { s->max_wait = 0.0; }, "max_wait"},
      {[](TriadCombinerSettings* s) { s->max_pending = 0; }, "max_pending"},
      {[](TriadCombinerSettings* s) { s->initial_rate_variance = NAN; }, "initial_angular_velocity_variance"},
      {[](TriadCombinerSettings* s) { s->initial_rate_variance = 5e-324; }, "initial_angular_velocity_variance"},
      {[](TriadCombinerSettings* s) { s->max_rate = INFINITY; }, "max_rate"},
      {[](TriadCombinerSettings* s) { s->backward_reset = NAN; }, "backward_reset"},
      {[](TriadCombinerSettings* s) { s->forward_jump = 0.0; }, "forward_jump"},
      {[](TriadCombinerSettings* s) { s->jump_persist = 0; }, "jump_persist"}};
  for (const auto& [spoil, key] : spoiled) {
    TriadCombinerSettings s;
    spoil(&s);
    EXPECT_EQ(refusedKey([&] { s.validate(); }), key);
    EXPECT_THROW(TriadCombiner(s, misalignedTriad()), std::invalid_argument) << key;
  }
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
    const double largest_rate =
        settings.max_rate * misalignedTriad()->axis_to_body.cwiseAbs().rowwise().sum().maxCoeff();
    for (std::size_t i = 0; i < out.size(); ++i) {
      const TriadBodySample& s = out[i];
      expectFiniteAndSymmetric(s);
      ASSERT_GT(s.stamp, 0);
      // Stamps go back only with FLAG_RESET (a new epoch), never in one.
      if (i > 0 && s.stamp <= out[i - 1].stamp) ASSERT_TRUE(s.flags & kTriadFlagReset) << i;
      ASSERT_LE(s.angular_velocity.cwiseAbs().maxCoeff(), largest_rate + 1e-3);
      ASSERT_GE(s.covariance.diagonal().minCoeff(), 1e-20 * 0.5);
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

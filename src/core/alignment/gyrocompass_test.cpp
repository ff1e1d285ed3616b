// The gyrocompass on the angle-level mount generator (src/core/testing/angle_level_mount.h): without
// noise each mode finds the true attitude; the impossible designs (one gyro at two positions, one
// position, a sweep that does not turn both ways) and the unusable inputs (latitude beyond the limit, a
// base that moves, a wave turned on command outside the sweep, an accelerometer that does not read g,
// a bias far beyond the Earth's rate) are refused naming the gate; the result's YAML reads back.
#include "hrg_gyro/core/alignment/gyrocompass.h"

#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include <cmath>

#include "core/testing/angle_level_mount.h"
#include "core/testing/refusal.h"

namespace hrg_gyro {
namespace core {
namespace {

using testing::MountScenario;

AlignmentSettings settingsFor(const MountScenario& s, AlignmentMode mode) {
  AlignmentSettings a;
  a.mode = mode;
  a.latitude = s.latitude;
  a.duration = s.length() - 1.0 / s.rate_hz;  // the last sample closes the window
  a.single_gyro = s.single_gyro;
  a.indexer.continuous = s.continuous;
  a.indexer.body_to_platform = s.body_to_platform;
  a.indexer.gyro_axis = s.gyro_axis;
  testing::setUnsetTermsToNone(&a);
  return a;
}

MountScenario noiseless() {
  MountScenario s;
  s.white_noise = 1e-12;
  s.accelerometer_noise = 1e-9;
  s.encoder_noise = 0.0;
  return s;
}

// A scenario aligned in `mode` and refused by `gate`, its reason naming `words`.
void expectRefused(const MountScenario& s, AlignmentMode mode, const std::string& gate, const std::string& words) {
  const AlignmentResult r = testing::alignScenario(settingsFor(s, mode), s);
  EXPECT_FALSE(r.accepted);
  EXPECT_EQ(r.gate, gate) << r.reason;
  EXPECT_NE(r.reason.find(words), std::string::npos) << r.reason;
}

TEST(GyrocompassTest, EachModeFindsTheTrueAttitudeWithoutNoise) {
  for (double yaw : {0.3, -2.0, 3.1, kPi / 2}) {
    MountScenario s = noiseless();
    s.mount = EulerAngles{0.01, -0.02, yaw};
    s.duration = 30.0;
    const AlignmentResult st = testing::alignScenario(settingsFor(s, AlignmentMode::kStatic), s);
    ASSERT_TRUE(st.accepted) << st.reason;
    EXPECT_NEAR(testing::yawError(st, s), 0.0, 1e-7) << yaw;
    EXPECT_NEAR(st.attitude.roll, 0.01, 1e-9);
    EXPECT_NEAR(st.attitude.pitch, -0.02, 1e-9);
    // Compared on the circle: at yaw pi/2 (true North) the heading may read 359.9999999995.
    EXPECT_NEAR(std::remainder(st.heading - trueHeadingDegrees(yaw), 360.0), 0.0, 1e-5);
    EXPECT_EQ(st.frame, "body");

    MountScenario x = s;
    x.indexed = true;
    x.stops = testing::twoPositions(20.0);
    const AlignmentResult ix = testing::alignScenario(settingsFor(x, AlignmentMode::kIndexed), x);
    ASSERT_TRUE(ix.accepted) << ix.reason;
    EXPECT_NEAR(testing::yawError(ix, x), 0.0, 1e-7) << yaw;
    EXPECT_EQ(ix.frame, "indexer");
    EXPECT_EQ(ix.segments.size(), 2u);
    // The body rests at the second position at the end: turned by 180 deg about the platform's z.
    const Eigen::Quaterniond body = orientationFromEuler(x.mount) * Eigen::AngleAxisd(kPi, Eigen::Vector3d::UnitZ());
    EXPECT_LT(ix.body_orientation.angularDistance(body), 1e-6);

    MountScenario sw = s;
    sw.sweep = true;
    sw.sweep_turns = 1.0;
    const AlignmentResult swr = testing::alignScenario(settingsFor(sw, AlignmentMode::kSweep), sw);
    ASSERT_TRUE(swr.accepted) << swr.reason;
    EXPECT_NEAR(testing::yawError(swr, sw), 0.0, 1e-6) << yaw;
  }
}

TEST(GyrocompassTest, OneGyroNeedsFourPositionsOrRotation) {
  MountScenario s = noiseless();
  s.indexed = true;
  s.single_gyro = true;
  s.stops = testing::twoPositions(20.0);
  const AlignmentResult two = testing::alignScenario(settingsFor(s, AlignmentMode::kIndexed), s);
  EXPECT_FALSE(two.accepted);
  EXPECT_EQ(two.gate, "design");
  EXPECT_NE(two.reason.find("ambiguous"), std::string::npos) << two.reason;
  std::printf("[ measured ] one gyro, two positions: %s\n", two.summary().c_str());

  s.stops = testing::fourPositions(20.0);
  const AlignmentResult four = testing::alignScenario(settingsFor(s, AlignmentMode::kIndexed), s);
  ASSERT_TRUE(four.accepted) << four.reason;
  EXPECT_NEAR(testing::yawError(four, s), 0.0, 1e-7);

  s.continuous = true;
  s.duration = 130.0;
  const AlignmentResult turning = testing::alignScenario(settingsFor(s, AlignmentMode::kIndexed), s);
  ASSERT_TRUE(turning.accepted) << turning.reason;
  EXPECT_NEAR(testing::yawError(turning, s), 0.0, 1e-6);

  // The triad at one position cannot tell its biases from the Earth's rate.
  MountScenario one = noiseless();
  one.indexed = true;
  one.stops = {{0.0, 0.0, 30.0}};
  expectRefused(one, AlignmentMode::kIndexed, "design", "one indexer position");
}

TEST(GyrocompassTest, UnusableInputsAreRefusedNamingTheGate) {
  MountScenario s;
  s.duration = 20.0;
  // Beyond the latitude limit: refused at once.
  {
    AlignmentSettings a = settingsFor(s, AlignmentMode::kStatic);
    a.latitude = 1.45;
    Gyrocompass g(a);
    EXPECT_TRUE(g.complete());
    EXPECT_TRUE(g.progress().refused);
    const AlignmentResult r = g.finish();
    EXPECT_EQ(r.gate, "latitude");
    std::printf("[ measured ] %s\n", r.summary().c_str());
  }
  // An accelerometer in g instead of m/s^2.
  {
    MountScenario wrong = s;
    wrong.accelerometer_to_body = Eigen::Quaterniond::Identity();
    Gyrocompass g(settingsFor(wrong, AlignmentMode::kStatic));
    testing::MountSinks sinks = testing::gyrocompassSinks(&g);
    const auto plain = sinks.accelerometer;
    sinks.accelerometer = [&](const AccelerometerRecord& r) {
      AccelerometerRecord in_g = r;
      in_g.specific_force /= kStandardGravity;
      plain(in_g);
    };
    testing::runMountScenario(wrong, sinks);
    const AlignmentResult r = g.finish();
    EXPECT_EQ(r.gate, "level");
    EXPECT_NE(r.reason.find("not gravity"), std::string::npos) << r.reason;
  }
  // A body bias of 2e-5 rad/s (an uncalibrated gyro) along the horizontal Earth rate: the horizontal
  // rate is not the Earth's. (The gate judges the rate's length only: a bias across it that keeps the
  // length, such as (2e-5, -1e-5, 0) at this yaw, turns the heading unseen by it.)
  {
    MountScenario biased = s;
    biased.residual_bias = 2e-5 * Eigen::Vector3d(std::sin(s.mount.yaw), std::cos(s.mount.yaw), 0.0);
    const AlignmentResult r = testing::alignScenario(settingsFor(biased, AlignmentMode::kStatic), biased);
    EXPECT_EQ(r.gate, "earth_rate") << r.summary();
  }
  // The wrong input for the mode is a programming error.
  {
    Gyrocompass g(settingsFor(s, AlignmentMode::kSweep));
    EXPECT_THROW(g.addTriad(TriadBodySample()), std::invalid_argument);
    EXPECT_THROW(g.addAxis(AxisOutput()), std::invalid_argument);
  }
  // No data at all.
  {
    Gyrocompass g(settingsFor(s, AlignmentMode::kStatic));
    EXPECT_EQ(g.finish().gate, "input");
  }
}

TEST(GyrocompassTest, AMovingBaseIsTrackedWithAnAccelerometerAndRefusedWithout) {
  MountScenario s;
  s.duration = 60.0;
  // A base that rocks: 1.6e-4 rad about East at 0.2 Hz. With a declared level the gyros alone cannot
  // tell it from the Earth's rate: refused, saying what would follow it.
  MountScenario rocking = s;
  rocking.base_motion.sways.push_back({1.6e-4, 5.0, Eigen::Vector3d::UnitX(), 0.0});
  {
    AlignmentSettings a = settingsFor(rocking, AlignmentMode::kStatic);
    a.level.source = LevelSource::kDeclared;
    a.level.roll = rocking.mount.roll;
    a.level.pitch = rocking.mount.pitch;
    const AlignmentResult r = testing::alignScenario(a, rocking);
    EXPECT_FALSE(r.accepted);
    EXPECT_TRUE(r.gate == "stillness" || r.gate == "motion") << r.summary();
    EXPECT_NE(r.reason.find("accelerometer"), std::string::npos) << r.reason;
    std::printf("[ measured ] a rocking base, level declared: %s\n", r.summary().c_str());
  }
  // With the accelerometer the gyros track it and gravity is followed in the inertial frame.
  {
    const AlignmentResult r = testing::alignScenario(settingsFor(rocking, AlignmentMode::kStatic), rocking);
    ASSERT_TRUE(r.accepted) << r.summary();
    EXPECT_EQ(r.estimator, "tracking");
    EXPECT_NE(r.estimator_reason.find("not still"), std::string::npos) << r.estimator_reason;
    EXPECT_LT(std::abs(testing::yawError(r, rocking)), 4.0 * r.budget.total) << r.summary();
    std::printf("[ measured ] a rocking base, accelerometer: error %+.3f mrad, %s\n",
                1e3 * testing::yawError(r, rocking), r.summary().c_str());
  }
  // A slow sway of 5e-5 rad (0.05 Hz), the level declared: the block means show it.
  {
    MountScenario swaying = s;
    swaying.base_motion.sways.push_back({5e-5, 20.0, Eigen::Vector3d::UnitY(), 0.0});
    AlignmentSettings a = settingsFor(swaying, AlignmentMode::kStatic);
    a.level.source = LevelSource::kDeclared;
    const AlignmentResult r = testing::alignScenario(a, swaying);
    EXPECT_FALSE(r.accepted) << r.summary();
    EXPECT_TRUE(r.gate == "stillness" || r.gate == "motion") << r.summary();
  }
  // A wave turned on command outside the sweep mode.
  {
    Gyrocompass g(settingsFor(s, AlignmentMode::kStatic));
    TriadBodySample x;
    x.stamp = toNanoseconds(10.0);
    x.dt = 0.005;
    x.flags = kTriadFlagPrecessing;
    g.addTriad(x);
    EXPECT_EQ(g.finish().gate, "motion");
  }
}

// Feeds a scenario into a gyrocompass with `change` applied to the k-th triad sample (1-based) and
// `accel_change` to the k-th accelerometer record.
AlignmentResult alignWith(const MountScenario& s, const AlignmentSettings& a,
                          const std::function<void(long, TriadBodySample*)>& change,
                          const std::function<void(long, AccelerometerRecord*)>& accel_change, AlignmentProgress* p) {
  Gyrocompass g(a);
  testing::MountSinks sinks = testing::gyrocompassSinks(&g);
  long k = 0, j = 0;
  const auto plain = sinks.triad;
  sinks.triad = [&](const TriadBodySample& x) {
    TriadBodySample y = x;
    change(++k, &y);
    plain(y);
  };
  const auto accel = sinks.accelerometer;
  sinks.accelerometer = [&](const AccelerometerRecord& r) {
    AccelerometerRecord y = r;
    accel_change(++j, &y);
    accel(y);
  };
  testing::runMountScenario(s, sinks);
  *p = g.progress();
  return g.finish();
}

TEST(GyrocompassTest, OneBadStampCostsItsSampleNeverTheWindow) {
  MountScenario s;
  s.duration = 40.0;
  AlignmentSettings a = settingsFor(s, AlignmentMode::kStatic);
  a.duration = 30.0;
  const auto none = [](long, AccelerometerRecord*) {};
  const auto keep = [](long, TriadBodySample*) {};
  AlignmentProgress clean_p;
  const AlignmentResult clean = alignWith(s, a, keep, none, &clean_p);
  ASSERT_TRUE(clean.accepted) << clean.summary();
  struct Case {
    const char* what;
    std::function<void(long, TriadBodySample*)> change;
    std::function<void(long, AccelerometerRecord*)> accel;
    std::uint64_t dropped, restarts;  // at most: a timeline that goes back costs jump_persist - 1 records
  };
  const Case cases[] = {
      {"the first sample stamped 1e6 s ahead",
       [](long k, TriadBodySample* x) {
         if (k == 1) x->stamp += toNanoseconds(1e6);
       },
       none, 4, 1},
      {"one sample 1000 s ahead",
       [](long k, TriadBodySample* x) {
         if (k == 2000) x->stamp += toNanoseconds(1000.0);
       },
       none, 1, 0},
      {"one sample with dt = 1e6 s",
       [](long k, TriadBodySample* x) {
         if (k == 2000) x->dt = 1e6;
       },
       none, 1, 0},
      {"stamps jittered by 0.1 ms", [](long k, TriadBodySample* x) { x->stamp += (k % 3 - 1) * 100000; }, none, 0, 0},
      {"the first accelerometer record 1000 s ahead", keep,
       [](long j, AccelerometerRecord* r) {
         if (j == 1) r->stamp += toNanoseconds(1000.0);
       },
       4, 0},
  };
  for (const Case& c : cases) {
    AlignmentProgress p;
    const AlignmentResult r = alignWith(s, a, c.change, c.accel, &p);
    std::printf("[ measured ] %s: %llu dropped, %llu restarts; %s (%s; lf %.3f, steps %zu, clean lf %.3f)\n", c.what,
                static_cast<unsigned long long>(p.dropped), static_cast<unsigned long long>(p.restarts),
                r.summary().c_str(), r.estimator_reason.c_str(), r.low_frequency_scatter, r.base_steps.size(),
                clean.low_frequency_scatter);
    EXPECT_TRUE(r.accepted) << c.what << ": " << r.summary();
    EXPECT_NEAR(r.seconds, clean.seconds, 0.1) << c.what;  // the window full, not cut
    EXPECT_EQ(p.restarts, c.restarts) << c.what;
    EXPECT_EQ(p.dropped, c.dropped) << c.what;
    EXPECT_EQ(r.estimator, clean.estimator) << c.what;
    // The same data less a sample: the two estimates differ by what the smaller loses (nested
    // estimators: the variance of their difference is the difference of their variances).
    // A restarted window is the same one shifted by a few samples: a tenth of its noise at most.
    const double lost =
        std::sqrt(std::max(r.budget.noise * r.budget.noise - clean.budget.noise * clean.budget.noise, 0.0));
    EXPECT_LT(std::abs(wrapToPi(r.attitude.yaw - clean.attitude.yaw)), 3.0 * lost + 0.1 * clean.budget.noise) << c.what;
  }
  // Stamps that step back 100 s for good mid-window: the window restarts on the new timeline and fills.
  MountScenario longer = s;
  longer.duration = 80.0;
  AlignmentProgress p;
  const AlignmentResult r = alignWith(
      longer, a,
      [](long k, TriadBodySample* x) {
        if (k > 1000) x->stamp -= toNanoseconds(100.0);
      },
      [](long j, AccelerometerRecord* r) {
        if (j > 1000) r->stamp -= toNanoseconds(100.0);
      },
      &p);
  EXPECT_TRUE(r.accepted) << r.summary();
  EXPECT_EQ(p.restarts, 1u);
  EXPECT_NEAR(r.seconds, a.duration, 0.1);
}

TEST(GyrocompassTest, RecordsBeforeTheWindowKeepMemoryFlat) {
  // hrg_bag align --start 5000: an hour and a half of accelerometer (and indexer) records before the
  // window's first gyro sample. Only the last window's length and one to two minutes of each stream are kept.
  MountScenario s;
  AlignmentSettings a = settingsFor(s, AlignmentMode::kStatic);
  a.level.source = LevelSource::kAccelerometer;
  a.level.accelerometer_bias_sigma = 5e-4;
  Gyrocompass g(a);
  std::uint64_t most = 0;
  for (long k = 1; k <= 500000; ++k) {
    AccelerometerRecord r;
    r.stamp = toNanoseconds(1000.0 + 0.01 * k);
    r.specific_force = Eigen::Vector3d(0.0, 0.0, 9.81);
    g.addAccelerometer(r);
    IndexerRecord x;
    x.stamp = r.stamp;
    g.addIndexer(x);
    most = std::max(most, g.progress().held);
  }
  std::printf("[ measured ] 500000 accelerometer and indexer records before the window: at most %llu held\n",
              static_cast<unsigned long long>(most));
  EXPECT_LE(most, 2u * static_cast<std::uint64_t>((a.duration + 120.0) * 100.0 + 2.0));
  EXPECT_EQ(g.progress().dropped, 0u);
}

TEST(GyrocompassTest, AnAllanFileOfAnotherRateIsRefused) {
  // Its Q is per sample of the rate it was measured at: a window sampled otherwise cannot use it.
  MountScenario s;
  s.duration = 20.0;
  AlignmentSettings a = settingsFor(s, AlignmentMode::kStatic);
  a.allan_tau0 = 1.0 / s.rate_hz;
  const AlignmentResult same = testing::alignScenario(a, s);
  EXPECT_TRUE(same.accepted) << same.summary();
  a.allan_tau0 = 2.0 / s.rate_hz;
  const AlignmentResult other = testing::alignScenario(a, s);
  std::printf("[ measured ] %s\n", other.reason.c_str());
  EXPECT_FALSE(other.accepted);
  EXPECT_EQ(other.gate, "noise");
}

TEST(GyrocompassTest, WithoutANoiseModelItDoesNotStart) {
  AlignmentSettings a;
  a.latitude = 0.9;
  EXPECT_EQ(refusedKey([&] { Gyrocompass g(a); }), "noise/angle_random_walk");
  a.noise.angle_random_walk = a.noise.rate_random_walk = a.noise.residual_drift_harmonics = 0.0;
  EXPECT_EQ(refusedKey([&] { Gyrocompass g(a); }), "noise/residual_bias");
  // A calibrated triad file gives the residual bias (its largest bias_std); an uncalibrated one (0) does not.
  TriadParameters triad;
  EXPECT_EQ(refusedKey([&] { Gyrocompass g(a, triad); }), "noise/residual_bias");
  triad.bias_std = Eigen::Vector3d(0.9e-8, 1.3e-8, 1.1e-8);
  a.level.accelerometer_bias_sigma = a.level.accelerometer_mounting_sigma = 0.0;
  Gyrocompass g(a, triad);
  EXPECT_EQ(g.settings().noise.residual_bias, 1.3e-8);
  EXPECT_NE(g.settings().noise_sources.residual_bias.find("triad_file"), std::string::npos);
  // The level's sigmas too.
  a.noise.residual_bias = 1e-8;
  a.level.accelerometer_mounting_sigma = NAN;
  EXPECT_EQ(refusedKey([&] { Gyrocompass h(a); }), "level/accelerometer_mounting_sigma");
  a.level.source = LevelSource::kDeclared;
  EXPECT_EQ(refusedKey([&] { Gyrocompass h(a); }), "level/roll_sigma");
}

TEST(GyrocompassTest, ASweepThatDoesNotTurnBothWaysIsRefused) {
  MountScenario s = noiseless();
  s.sweep = true;
  s.sweep_turns = 1.0;
  s.sweep_directions = {1, 1};
  expectRefused(s, AlignmentMode::kSweep, "design", "turns up");
}

TEST(GyrocompassTest, StreamsOutOfOrderAreDroppedAndCounted) {
  MountScenario s;
  s.duration = 10.0;
  Gyrocompass g(settingsFor(s, AlignmentMode::kStatic));
  testing::MountSinks sinks = testing::gyrocompassSinks(&g);
  TriadBodySample held;
  int n = 0;
  const auto plain = sinks.triad;
  sinks.triad = [&](const TriadBodySample& x) {
    plain(x);
    if (++n == 100) held = x;
    if (n == 200) plain(held);  // a stale sample again
  };
  const auto accel = sinks.accelerometer;
  sinks.accelerometer = [&](const AccelerometerRecord& r) {
    accel(r);
    accel(r);  // every record twice
  };
  testing::runMountScenario(s, sinks);
  const AlignmentProgress p = g.progress();
  EXPECT_EQ(p.dropped, 1u + p.accelerometer);
  const AlignmentResult r = g.finish();
  EXPECT_TRUE(r.accepted) << r.summary();
}

TEST(GyrocompassTest, TheResultReadsBackAsYaml) {
  MountScenario s;
  s.duration = 20.0;
  const AlignmentResult r = testing::alignScenario(settingsFor(s, AlignmentMode::kStatic), s);
  ASSERT_TRUE(r.accepted) << r.reason;
  const YAML::Node y = YAML::Load(emitAlignmentResult(r));
  EXPECT_TRUE(y["accepted"].as<bool>());
  EXPECT_EQ(y["mode"].as<std::string>(), "static");
  EXPECT_NEAR(y["heading_deg"].as<double>(), r.heading, 1e-9);
  EXPECT_NEAR(y["heading_sigma_deg"].as<double>(), r.heading_sigma, 1e-12);
  EXPECT_EQ(y["orientation"].size(), 4u);
  EXPECT_EQ(y["segments"].size(), r.segments.size());
  EXPECT_NEAR(y["budget_rad"]["total"].as<double>(), r.budget.total, 1e-15);
  const AlignmentResult refused = testing::alignScenario(
      [&] {
        AlignmentSettings a = settingsFor(s, AlignmentMode::kStatic);
        a.latitude = -1.5;
        return a;
      }(),
      s);
  const YAML::Node n = YAML::Load(emitAlignmentResult(refused));
  EXPECT_FALSE(n["accepted"].as<bool>());
  EXPECT_EQ(n["gate"].as<std::string>(), "latitude");
}

}  // namespace
}  // namespace core
}  // namespace hrg_gyro

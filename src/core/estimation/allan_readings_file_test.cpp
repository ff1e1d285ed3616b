// The Allan readings file: what allanReadingsYaml writes, loadAllanReadings reads back bit for bit;
// a missing or mistyped entry, an unknown key, a negative value, a positive-less identified reading
// and a bad tau0 are refused naming the key and the file.
#include "hrg_gyro/core/estimation/allan_readings_file.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>

#include "core/testing/refusal.h"
#include "core/testing/temporary_file.h"
#include "hrg_gyro/core/common/yaml_field.h"

namespace hrg_gyro {
namespace core {
namespace {

AllanReadings example() {
  AllanReadings r;
  r.samples = 120001;
  r.tau0 = 0.005000000000000001;
  r.result.angle_white_noise = {true, 4.912345678901234e-6, 0.005, 0.0631};
  r.result.angle_random_walk = {false, 0.0, 0.0, 0.0};
  r.result.bias_instability = {true, 3.1e-9, 20.0, 63.1};
  r.result.rate_random_walk = {true, 5.123456789e-10, 100.0, 316.2};
  return r;
}

TEST(AllanReadingsFileTest, WhatIsWrittenIsReadBackExactly) {
  const AllanReadings w = example();
  const TemporaryFile file("hrg_allan_readings", allanReadingsYaml(w));
  const AllanReadings r = loadAllanReadings(file.path());
  EXPECT_EQ(r.samples, w.samples);
  EXPECT_EQ(r.tau0, w.tau0);
  EXPECT_TRUE(r.result.curve.empty());
  const NoiseReading AllanResult::*terms[] = {&AllanResult::angle_white_noise, &AllanResult::angle_random_walk,
                                              &AllanResult::bias_instability, &AllanResult::rate_random_walk};
  for (const auto term : terms) {
    EXPECT_EQ((r.result.*term).identified, (w.result.*term).identified);
    EXPECT_EQ((r.result.*term).value, (w.result.*term).value);
    EXPECT_EQ((r.result.*term).tau_min, (w.result.*term).tau_min);
    EXPECT_EQ((r.result.*term).tau_max, (w.result.*term).tau_max);
  }
  EXPECT_EQ(allanReadingsYaml(w).rfind("# hrg_bag allan readings, SI", 0), 0u);
}

TEST(AllanReadingsFileTest, EachAxisIsKeptAndTheTopLevelIsTheWorstAxis) {
  AllanReadings w = example();
  AllanResult x = w.result, y = w.result, z = w.result;
  y.angle_white_noise.value = 6e-6;               // the largest Q
  z.angle_random_walk = {true, 2e-7, 1.0, 10.0};  // the only axis that shows an N
  x.rate_random_walk.value = 9e-10;               // the largest K
  w.axes = {{"x", x}, {"y", y}, {"z", z}};
  w.result = worstOfAxes(w.axes);
  EXPECT_EQ(w.result.angle_white_noise.value, 6e-6);
  EXPECT_TRUE(w.result.angle_random_walk.identified);
  EXPECT_EQ(w.result.angle_random_walk.value, 2e-7);
  EXPECT_EQ(w.result.angle_random_walk.tau_max, 10.0) << "with its axis's tau range";
  EXPECT_EQ(w.result.rate_random_walk.value, 9e-10);
  const TemporaryFile file("hrg_allan_readings_axes", allanReadingsYaml(w));
  const AllanReadings r = loadAllanReadings(file.path());
  ASSERT_EQ(r.axes.size(), 3u);
  EXPECT_EQ(r.axes[1].axis, "y");
  EXPECT_EQ(r.axes[1].result.angle_white_noise.value, 6e-6);
  EXPECT_EQ(r.axes[2].result.angle_random_walk.value, 2e-7);
  EXPECT_EQ(r.result.angle_random_walk.value, 2e-7);
  EXPECT_EQ(refusedKey([] {
              const TemporaryFile bad("hrg_allan_readings_axes_bad", allanReadingsYaml(example()) + "axes: {w: {}}\n");
              loadAllanReadings(bad.path());
            }),
            "axes.w");
}

TEST(AllanReadingsFileTest, ABadEntryIsRefusedNamingTheKeyAndTheFile) {
  const std::string good = allanReadingsYaml(example());
  auto refused = [](const std::string& text) {
    const TemporaryFile file("hrg_allan_readings_bad", text);
    try {
      loadAllanReadings(file.path());
    } catch (const ConfigError& e) {
      EXPECT_NE(std::string(e.what()).find(file.path()), std::string::npos) << e.what();
      return e.key();
    }
    return std::string("(accepted)");
  };
  EXPECT_EQ(refused(good), "(accepted)");
  EXPECT_EQ(refused("samples: 10\ntau0: 0.005\n"), "angle_white_noise");
  EXPECT_EQ(refused(good + "extra: 1\n"), "extra");
  std::string negative = good;
  negative.replace(negative.find("value: 5.123456789"), 9, "value: -5.");
  EXPECT_EQ(refused(negative), "rate_random_walk.value");
  std::string zero = "samples: 10\ntau0: 0.005\n";
  for (const char* k : {"angle_white_noise", "angle_random_walk", "bias_instability"}) {
    zero += std::string(k) + ": {identified: false, value: 0, tau_min: 0, tau_max: 0}\n";
  }
  EXPECT_EQ(refused(zero + "rate_random_walk: {identified: true, value: 0, tau_min: 1, tau_max: 2}\n"),
            "rate_random_walk.value");
  std::string tau = good;
  tau.replace(tau.find("tau0: "), 6, "tau0: -");
  EXPECT_EQ(refused(tau), "tau0");
  try {
    loadAllanReadings("/nonexistent/allan.yaml");
    FAIL();
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("/nonexistent/allan.yaml"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace core
}  // namespace hrg_gyro

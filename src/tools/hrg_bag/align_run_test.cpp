#include "align_run.h"

#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <set>
#include <string>
#include <vector>

#include "core/testing/angle_level_mount.h"
#include "core/testing/output_directory_test_base.h"

namespace hrg_gyro {
namespace bag_tools {
namespace {

using core::testing::MountScenario;

/// Parses `args` (after "align") into options; the CLI11 error's text, or "" when accepted.
std::string parse(std::vector<std::string> args, AlignOptions* o) {
  CLI::App app("test", "hrg_bag");
  CLI::App* cmd = app.add_subcommand("align", "");
  addAlignOptions(*cmd, o);
  args.insert(args.begin(), "align");
  std::vector<std::string> reversed(args.rbegin(), args.rend());
  try {
    app.parse(reversed);
  } catch (const CLI::ParseError& e) {
    return e.what();
  }
  return "";
}

TEST(AlignOptions, ReadsEveryOption) {
  AlignOptions o;
  ASSERT_EQ(parse({"s.bag",
                   "--settings",
                   "a.yaml",
                   "--duration",
                   "90",
                   "--start",
                   "5",
                   "--output",
                   "r.yaml",
                   "--windows",
                   "30,60",
                   "--triad-topic",
                   "/t/triad/output",
                   "--gyro-topic",
                   "/g/output",
                   "--turntable-topic",
                   "/tt",
                   "--accelerometer-topic",
                   "/accel/data_raw",
                   "--imu-topic",
                   "/imu/data_raw",
                   "--scan",
                   "300"},
                  &o),
            "");
  EXPECT_EQ(o.bag, "s.bag");
  EXPECT_EQ(o.settings, "a.yaml");
  EXPECT_EQ(o.duration, 90.0);
  EXPECT_EQ(o.start, 5.0);
  EXPECT_EQ(o.output, "r.yaml");
  EXPECT_EQ(o.windows, "30,60");
  EXPECT_EQ(o.triad_topic, "/t/triad/output");
  EXPECT_EQ(o.gyro_topic, "/g/output");
  EXPECT_EQ(o.turntable_topic, "/tt");
  EXPECT_EQ(o.accelerometer_topic, "/accel/data_raw");
  EXPECT_EQ(o.imu_topic, "/imu/data_raw");
  EXPECT_EQ(o.scan, 300.0);
  AlignOptions defaults;
  ASSERT_EQ(parse({"s.bag", "--settings", "a.yaml"}, &defaults), "");
  EXPECT_EQ(defaults.duration, 0.0);  // the settings' own
  EXPECT_EQ(defaults.start, 0.0);
}

TEST(AlignOptions, RefusesByName) {
  struct Case {
    std::vector<std::string> args;
    const char* option;
  };
  const std::vector<Case> cases = {
      {{"s.bag"}, "--settings"},
      {{"--settings", "a.yaml"}, "BAG"},
      {{"s.bag", "--settings", ""}, "--settings"},
      {{"s.bag", "--settings", "a.yaml", "--duration", "0"}, "--duration"},
      {{"s.bag", "--settings", "a.yaml", "--duration", "-5"}, "--duration"},
      {{"s.bag", "--settings", "a.yaml", "--duration", "nan"}, "--duration"},
      {{"s.bag", "--settings", "a.yaml", "--duration", "12x"}, "--duration"},
      {{"s.bag", "--settings", "a.yaml", "--start", "-1"}, "--start"},
      {{"s.bag", "--settings", "a.yaml", "--output", ""}, "--output"},
      {{"s.bag", "--settings", "a.yaml", "--windows", ""}, "--windows"},
      {{"s.bag", "--settings", "a.yaml", "--heading", "3"}, "--heading"},
  };
  for (const Case& c : cases) {
    AlignOptions o;
    const std::string error = parse(c.args, &o);
    EXPECT_NE(error.find(c.option), std::string::npos) << c.option << ": " << error;
  }
}

TEST(AlignOptions, WindowsAreAscendingLengthsWithinTheWindow) {
  EXPECT_EQ(parseWindows("", 120.0), std::vector<double>());
  EXPECT_EQ(parseWindows("30,60,120", 120.0), (std::vector<double>{30.0, 60.0, 120.0}));
  EXPECT_EQ(parseWindows("7.5", 120.0), std::vector<double>{7.5});
  const std::vector<std::pair<const char*, const char*>> refused = {
      {"60,30", "ascending"},
      {"30,30", "ascending"},
      {"30,abc", "'abc'"},
      {"30,,60", "''"},
      {"0", "longer than 0"},
      {"-30", "longer than 0"},
      {"121", "longer than the window"},
      {"30,", "comma"},
      {"nan", "'nan'"},
  };
  for (const auto& r : refused) {
    try {
      parseWindows(r.first, 120.0);
      ADD_FAILURE() << r.first << " accepted";
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find(r.second), std::string::npos) << r.first << ": " << e.what();
    }
  }
}

/// A static triad at latitude 0.9 on the angle-level generator, the settings the accuracy tests use.
core::AlignmentSettings staticSettings(const MountScenario& s) {
  core::AlignmentSettings a;
  a.mode = core::AlignmentMode::kStatic;
  a.latitude = s.latitude;
  a.duration = s.duration;
  a.noise.residual_bias = 1e-8;
  a.level.source = core::LevelSource::kDeclared;
  core::testing::setUnsetTermsToNone(&a);
  return a;
}

core::testing::MountSinks runSinks(AlignmentRun* run) {
  core::testing::MountSinks k;
  k.triad = [run](const core::TriadBodySample& x) { run->addTriad(x); };
  k.indexer = [run](const core::IndexerRecord& x) { run->addIndexer(x); };
  k.accelerometer = [run](const core::AccelerometerRecord& x) { run->addAccelerometer(x); };
  return k;
}

TEST(AlignmentRun, TheWindowIsALoneGyrocompassAndShorterWindowsHaveWiderSigmas) {
  MountScenario s;
  s.duration = 120.0;
  s.mount.yaw = 0.3;
  const core::AlignmentSettings settings = staticSettings(s);
  AlignmentRun run(settings, {15.0, 30.0, 60.0, 120.0});
  core::testing::runMountScenario(s, runSinks(&run));
  ASSERT_TRUE(run.complete());
  const core::AlignmentResult result = run.finish();
  const core::AlignmentResult lone = core::testing::alignScenario(settings, s);
  ASSERT_TRUE(result.accepted) << result.summary();
  EXPECT_EQ(result.heading, lone.heading);  // the same records, the same result, bit for bit
  EXPECT_EQ(result.heading_sigma, lone.heading_sigma);
  const std::vector<WindowResult> windows = run.finishWindows();
  ASSERT_EQ(windows.size(), 4u);
  for (std::size_t i = 0; i < windows.size(); ++i) {
    const core::AlignmentResult& w = windows[i].result;
    ASSERT_TRUE(w.accepted) << w.summary();
    EXPECT_NEAR(w.seconds, windows[i].seconds, 0.01);
    EXPECT_LT(std::abs(core::testing::yawError(w, s)), 4.0 * w.budget.total) << windows[i].seconds;
    if (i > 0) {
      EXPECT_LT(w.budget.noise, windows[i - 1].result.budget.noise) << windows[i].seconds;
    }
    std::printf("[ measured ] first %.0f s: heading error %.4f mrad, sigma %.4f mrad (noise %.4f mrad)\n",
                windows[i].seconds, 1e3 * core::testing::yawError(w, s), 1e3 * w.budget.total, 1e3 * w.budget.noise);
  }
  EXPECT_EQ(windows.back().result.heading, result.heading);  // the full length: the window itself
  // White angle noise falls as T^-3/2 while it dominates: from 15 s to 30 s by 2^1.5 = 2.83.
  EXPECT_NEAR(windows[0].result.budget.noise / windows[1].result.budget.noise, 2.83, 0.3);
}

TEST(AlignmentRun, AnInputShortOfTheWindowIsRefusedSayingHowFarItGot) {
  MountScenario s;
  s.duration = 40.0;
  core::AlignmentSettings settings = staticSettings(s);
  settings.duration = 120.0;
  AlignmentRun run(settings, {30.0, 60.0});
  core::testing::runMountScenario(s, runSinks(&run));
  EXPECT_FALSE(run.complete());
  run.inputEnded("the bag");
  const core::AlignmentResult r = run.finish();
  EXPECT_FALSE(r.accepted);
  EXPECT_EQ(r.gate, "aborted");
  EXPECT_NE(r.reason.find("the bag ended after 40.000 s of gyro stamps, short of the 120.000 s window"),
            std::string::npos)
      << r.reason;
  const std::vector<WindowResult> windows = run.finishWindows();
  EXPECT_TRUE(windows[0].result.accepted) << windows[0].result.summary();  // 30 s were there
  EXPECT_EQ(windows[1].result.gate, "aborted");
}

class AlignmentRunFile : public core::OutputDirectoryTestBase {};

TEST_F(AlignmentRunFile, TheResultFileReadsBackWithItsWindows) {
  MountScenario s;
  s.duration = 60.0;
  AlignmentRun run(staticSettings(s), {20.0, 40.0});
  core::testing::runMountScenario(s, runSinks(&run));
  const core::AlignmentResult r = run.finish();
  const std::vector<WindowResult> windows = run.finishWindows();
  const std::string path = at("result.yaml");
  writeAlignmentFile(path, emitAlignmentRun(r, windows, "a \"bag\".bag", "s.yaml"), r, windows);
  const YAML::Node doc = YAML::LoadFile(path);
  EXPECT_TRUE(doc["accepted"].as<bool>());
  EXPECT_NEAR(doc["heading_deg"].as<double>(), r.heading, 1e-9);
  EXPECT_EQ(doc["input"]["bag"].as<std::string>(), "a \"bag\".bag");
  ASSERT_EQ(doc["windows"].size(), 2u);
  EXPECT_EQ(doc["windows"][1]["window_s"].as<double>(), 40.0);
  EXPECT_NEAR(doc["windows"][0]["heading_sigma_deg"].as<double>(), windows[0].result.heading_sigma, 1e-9);
  EXPECT_GT(doc["segments"].size(), 0u);
  // A text that does not say what the result says is not written; the file stays as it was.
  EXPECT_THROW(writeAlignmentFile(path, "accepted: false\n", r, windows), std::runtime_error);
  EXPECT_TRUE(YAML::LoadFile(path)["accepted"].as<bool>());
  // Over a directory: refused, nothing written.
  EXPECT_THROW(writeAlignmentFile(dir_, emitAlignmentRun(r, windows, "b", "s"), r, windows), std::runtime_error);
  // Neither refusal left a temporary file beside the result.
  EXPECT_EQ(listing(), std::set<std::string>{"result.yaml"});
}

TEST_F(AlignmentRunFile, AScanSaysHowItsWindowsAgreeAndReadsBack) {
  std::vector<ScanWindow> scan(4);
  const double headings[] = {359.99, 0.0, 0.03, 0.0};
  for (std::size_t i = 0; i < scan.size(); ++i) {
    scan[i].start = 300.0 * static_cast<double>(i);
    scan[i].result.accepted = i != 3;
    scan[i].result.heading = headings[i];
    scan[i].result.gate = i == 3 ? "stillness" : "";
  }
  // On the circle: 359.99 and 0.03 are 0.04 apart, not 359.96; the refused window counts for nothing.
  const ScanAgreement a = scanAgreement(scan);
  EXPECT_EQ(a.accepted, 3u);
  EXPECT_NEAR(a.spread, 0.04, 1e-9);
  EXPECT_NEAR(a.largest_consecutive, 0.03, 1e-9);
  const std::string path = at("scan.yaml");
  writeScanFile(path, emitScan(scan, "b.bag", "s.yaml"), scan);
  const YAML::Node doc = YAML::LoadFile(path);
  ASSERT_EQ(doc["windows"].size(), 4u);
  EXPECT_EQ(doc["windows"][3]["gate"].as<std::string>(), "stillness");
  EXPECT_NEAR(doc["accepted_spread_deg"].as<double>(), 0.04, 1e-9);
  // A text that does not say what the scan says is not written; the file stays as it was.
  std::vector<ScanWindow> other = scan;
  other[1].result.heading = 1.0;
  EXPECT_THROW(writeScanFile(path, emitScan(other, "b.bag", "s.yaml"), scan), std::runtime_error);
  EXPECT_EQ(YAML::LoadFile(path)["windows"][1]["heading_deg"].as<double>(), 0.0);
  EXPECT_EQ(listing(), std::set<std::string>{"scan.yaml"});
}

}  // namespace
}  // namespace bag_tools
}  // namespace hrg_gyro

// The calibration method as a type (its one list, names, traits, the parameter file's provenance),
// the pieces of calibration logic every front-end shares (generator pairing, B/A, staged runs), and
// the texts users read the method list from, checked against that one list.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <regex>
#include <set>
#include <sstream>
#include <stdexcept>
#include <vector>

#include "hrg_gyro/core/calibration_method_kind.h"
#include "hrg_gyro/core/calibration_settings.h"
#include "hrg_gyro/core/generator_pairing.h"
#include "hrg_gyro/core/parameter_file.h"
#include "hrg_gyro/core/staged_calibration.h"

namespace hrg_gyro {
namespace core {
namespace {

std::string readSourceFile(const std::string& relative) {
  std::ifstream in(std::string(HRG_GYRO_SOURCE_DIR) + "/" + relative);
  EXPECT_TRUE(in.good()) << relative;
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

void expectEveryMethodNamed(const std::string& text, const std::string& where) {
  for (CalibrationMethodKind m : allCalibrationMethods()) {
    EXPECT_NE(text.find(nameOf(m)), std::string::npos) << where << " does not name the method " << nameOf(m);
  }
}

TEST(CalibrationMethodKind, EveryMethodHasOneDistinctNameThatParsesBack) {
  std::set<std::string> names;
  for (CalibrationMethodKind m : allCalibrationMethods()) {
    names.insert(nameOf(m));
    EXPECT_EQ(parseCalibrationMethod(nameOf(m)), m);
    ASSERT_TRUE(findCalibrationMethod(nameOf(m)).has_value());
  }
  EXPECT_EQ(names.size(), 5u);
  EXPECT_EQ(allCalibrationMethods().front(), CalibrationSettings().method);  // the default comes first
  EXPECT_EQ(calibrationMethodNames("|"), "dual_rate|constant_rate|step|correction_matrix|thermal");
}

TEST(CalibrationMethodKind, UnknownNameIsRefusedWithTheList) {
  EXPECT_FALSE(findCalibrationMethod("dualrate").has_value());
  EXPECT_FALSE(findCalibrationMethod("").has_value());
  try {
    parseCalibrationMethod("Dual_Rate");
    FAIL() << "accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("'Dual_Rate'"), std::string::npos) << e.what();
    expectEveryMethodNamed(e.what(), "the refusal");
  }
}

TEST(CalibrationMethodKind, TraitsSayWhatEachMethodNeedsAndGives) {
  for (CalibrationMethodKind m : allCalibrationMethods()) {
    const CalibrationMethodTraits& t = traitsOf(m);
    // A method estimates K and D on the turntable, or P from the generator sweep, never both.
    EXPECT_NE(t.estimates_k_and_d, t.estimates_correction) << t.name;
    EXPECT_EQ(t.uses_generator_pairs, t.estimates_correction) << t.name;
    EXPECT_EQ(t.needs_turntable, !t.uses_generator_pairs) << t.name;
    EXPECT_GT(std::string(t.description).size(), 10u) << t.name;
  }
  EXPECT_TRUE(traitsOf(CalibrationMethodKind::kCorrectionMatrix).uses_generator_pairs);
  EXPECT_TRUE(traitsOf(CalibrationMethodKind::kThermal).frequency_dependent);
  EXPECT_FALSE(traitsOf(CalibrationMethodKind::kDualRate).frequency_dependent);
}

TEST(ParameterOrigin, NoneManualAndEveryMethodRoundTripThroughText) {
  EXPECT_TRUE(ParameterOrigin().isNone());
  EXPECT_EQ(ParameterOrigin().name(), "none");
  EXPECT_TRUE(ParameterOrigin::parse("none").isNone());
  EXPECT_TRUE(ParameterOrigin::parse("manual").isManual());
  EXPECT_FALSE(ParameterOrigin::parse("manual").method().has_value());
  for (CalibrationMethodKind m : allCalibrationMethods()) {
    const ParameterOrigin o = ParameterOrigin::parse(nameOf(m));
    ASSERT_TRUE(o.method().has_value());
    EXPECT_EQ(*o.method(), m);
    EXPECT_EQ(o.name(), nameOf(m));
    EXPECT_EQ(o, ParameterOrigin::calibratedBy(m));
  }
  EXPECT_NE(ParameterOrigin::none(), ParameterOrigin::manual());
  try {
    ParameterOrigin::parse("calibrated");
    FAIL() << "accepted";
  } catch (const std::invalid_argument& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("none, manual"), std::string::npos) << what;
    expectEveryMethodNamed(what, "the refusal");
  }
}

TEST(ParameterOrigin, ParameterFileRefusesAnUnknownMethodNamingTheKey) {
  std::string text = emitParameters(GyroParameters());
  const std::string line = "method: none";
  const std::size_t at = text.find(line);
  ASSERT_NE(at, std::string::npos) << text;
  text.replace(at, line.size(), "method: dual-rate");
  try {
    parseParameterText(text);
    FAIL() << "accepted";
  } catch (const ConfigError& e) {
    EXPECT_EQ(e.key(), "calibration.method");
    EXPECT_NE(std::string(e.what()).find("manual"), std::string::npos) << e.what();
  }
}

TEST(CalibrationMethodKind, SettingsParserRefusesAnUnknownMethodNamingTheKey) {
  YAML::Node n;
  n["method"] = "steps";
  try {
    CalibrationSettings::parse(YamlField(n, ""));
    FAIL() << "accepted";
  } catch (const ConfigError& e) {
    EXPECT_EQ(e.key(), "method");
    expectEveryMethodNamed(e.what(), "the refusal");
  }
  n["method"] = "thermal";
  EXPECT_EQ(CalibrationSettings::parse(YamlField(n, "")).method, CalibrationMethodKind::kThermal);
}

// ---- the texts users read the list from ----------------------------------------------------------

TEST(CalibrationMethodKind, EveryLaunchFileMethodArgumentListsEveryMethod) {
  const std::vector<std::string> launch_files = {"launch/calibrator.launch", "launch/calibration_session.launch",
                                                 "launch/playback.launch"};
  const std::regex method_arg(R"re(<arg\s+name="method"[^>]*doc="([^"]*)")re");
  for (const std::string& file : launch_files) {
    const std::string text = readSourceFile(file);
    std::smatch m;
    ASSERT_TRUE(std::regex_search(text, m, method_arg)) << file << ": no documented <arg name=\"method\">";
    expectEveryMethodNamed(m[1].str(), file + " (method doc string)");
  }
}

TEST(CalibrationMethodKind, ParameterTemplateAndDocsListEveryMethod) {
  const std::string yaml = readSourceFile("config/calibrator.yaml");
  std::smatch m;
  ASSERT_TRUE(std::regex_search(yaml, m, std::regex(R"(\nmethod:[^#\n]*#([^\n]*))")));
  expectEveryMethodNamed(m[1].str(), "config/calibrator.yaml (method comment)");
  // The calibrator's parameter table and the command lines of the offline tools.
  const std::string ros_api = readSourceFile("docs/ros_api.md");
  ASSERT_TRUE(std::regex_search(ros_api, m, std::regex(R"(\n\| `method` \|[^\n]*)")));
  expectEveryMethodNamed(m[0].str(), "docs/ros_api.md (method parameter)");
  const std::string sessions = readSourceFile("docs/recorded_sessions.md");
  for (const char* tool : {"hrg_bag calibrate BAG --method", "[--method "}) {
    const std::size_t at = sessions.find(tool);
    ASSERT_NE(at, std::string::npos) << tool;
    expectEveryMethodNamed(sessions.substr(at, sessions.find('\n', at) - at),
                           std::string("docs/recorded_sessions.md: ") + tool);
  }
  // docs/calibration.md: one row of the method table per method.
  const std::string doc = readSourceFile("docs/calibration.md");
  for (CalibrationMethodKind k : allCalibrationMethods()) {
    EXPECT_NE(doc.find("\n| `" + nameOf(k) + "`"), std::string::npos) << "docs/calibration.md: no table row for "
                                                                        << nameOf(k);
  }
}

// ---- generator pairing -----------------------------------------------------------------------------

struct Pair {
  Nanoseconds stamp;
  ChannelVector raw, reference;
};

TEST(GeneratorPairing, PairsEqualStampsWhicheverStreamComesFirst) {
  std::vector<Pair> pairs;
  GeneratorPairing pairing([&](Nanoseconds t, const ChannelVector& raw, const ChannelVector& reference) {
    pairs.push_back({t, raw, reference});
  });
  const WaveParameters wave{1.0, 0.01, 0.3, 0.2};
  // Raw channels outside the sweep (no reference will come), then the raw stream ahead by two.
  pairing.addRaw(1, ChannelVector::Constant(1.0));
  pairing.addRaw(10, ChannelVector::Constant(10.0));
  pairing.addRaw(20, ChannelVector::Constant(20.0));
  pairing.addReference(10, wave);
  pairing.addReference(20, wave);
  // Then the reference stream ahead, with one reference whose channels were lost (30).
  pairing.addReference(30, wave);
  pairing.addReference(40, wave);
  pairing.addRaw(40, ChannelVector::Constant(40.0));
  ASSERT_EQ(pairs.size(), 3u);
  EXPECT_EQ(pairs[0].stamp, 10);
  EXPECT_EQ(pairs[1].stamp, 20);
  EXPECT_EQ(pairs[2].stamp, 40);
  EXPECT_EQ(pairs[2].raw, ChannelVector::Constant(40.0));
  EXPECT_TRUE(pairs[0].reference.isApprox(idealChannels(wave)));
  EXPECT_EQ(pairing.waitingRaw() + pairing.waitingReferences(), 0u);
}

TEST(GeneratorPairing, WaitingListsStayBounded) {
  int pairs = 0;
  GeneratorPairing pairing([&](Nanoseconds, const ChannelVector&, const ChannelVector&) { ++pairs; }, 100);
  for (Nanoseconds t = 1; t <= 1000; ++t) pairing.addRaw(t, ChannelVector::Zero());
  EXPECT_EQ(pairing.waitingRaw(), 100u);
  pairing.addReference(1000, WaveParameters());  // still waiting: pairs
  pairing.addReference(5, WaveParameters());     // long gone: dropped
  EXPECT_EQ(pairs, 1);
  pairing.clear();
  EXPECT_EQ(pairing.waitingRaw() + pairing.waitingReferences(), 0u);
}

TEST(QuadratureRatio, IsBOverAAndNaNWithoutAPositiveAmplitude) {
  EXPECT_DOUBLE_EQ(quadratureRatio(0.02, 0.5), 0.04);
  EXPECT_TRUE(std::isnan(quadratureRatio(0.02, 0.0)));
  EXPECT_TRUE(std::isnan(quadratureRatio(0.02, -1.0)));
  EXPECT_TRUE(std::isnan(quadratureRatio(NAN, 1.0)));
  EXPECT_TRUE(std::isnan(quadratureRatio(0.0, INFINITY)));
}

// ---- staged calibration ----------------------------------------------------------------------------

TEST(StagedCalibration, OneStageOfTheSettingsMethodByDefault) {
  CalibrationSettings base;
  base.method = CalibrationMethodKind::kStep;
  StagedCalibration staged(base);
  ASSERT_EQ(staged.stages().size(), 1u);
  EXPECT_FALSE(staged.usesGeneratorPairs());
  EXPECT_EQ(staged.session(), nullptr);
  EXPECT_EQ(staged.startNextStage(GyroParameters()).settings().method, CalibrationMethodKind::kStep);
  EXPECT_FALSE(staged.hasNextStage());
  EXPECT_THROW(staged.startNextStage(GyroParameters()), std::logic_error);
}

TEST(StagedCalibration, RunsTheStagesInOrderEachOnItsPrior) {
  StagedCalibration staged(CalibrationSettings(),
                           {CalibrationMethodKind::kCorrectionMatrix, CalibrationMethodKind::kDualRate});
  EXPECT_TRUE(staged.usesGeneratorPairs());
  GyroParameters first;
  EXPECT_EQ(staged.startNextStage(first).settings().method, CalibrationMethodKind::kCorrectionMatrix);
  ASSERT_NE(staged.session(), nullptr);
  const CalibrationOutcome o = staged.finishStage();  // no data: refused, but an outcome of that method
  EXPECT_EQ(o.method, CalibrationMethodKind::kCorrectionMatrix);
  EXPECT_FALSE(o.accepted);
  EXPECT_EQ(staged.session(), nullptr);
  EXPECT_THROW(staged.finishStage(), std::logic_error);
  ASSERT_TRUE(staged.hasNextStage());
  GyroParameters second;
  second.correction.p[0] = 1e-3;
  EXPECT_EQ(staged.startNextStage(second).prior().correction.p[0], 1e-3);
  EXPECT_EQ(staged.session()->settings().method, CalibrationMethodKind::kDualRate);
  // A bag loop restarts the stage in progress, not the sequence.
  EXPECT_EQ(staged.restartStage(first).settings().method, CalibrationMethodKind::kDualRate);
  EXPECT_FALSE(staged.hasNextStage());
  staged.rewind();
  EXPECT_TRUE(staged.hasNextStage());
  staged.abort();
  EXPECT_EQ(staged.session(), nullptr);
  EXPECT_FALSE(staged.hasNextStage());
  staged.rewind({CalibrationMethodKind::kThermal});
  EXPECT_FALSE(staged.usesGeneratorPairs());
  EXPECT_EQ(staged.startNextStage(first).settings().method, CalibrationMethodKind::kThermal);
}

TEST(StagedCalibration, NamesOneReportPerStage) {
  EXPECT_EQ(StagedCalibration::defaultReportPath("/w/params.yaml"), "/w/params.report.yaml");
  EXPECT_EQ(StagedCalibration::defaultReportPath("/w/params"), "/w/params.report.yaml");
  EXPECT_EQ(StagedCalibration::stageReportPath("/w/params.report.yaml", CalibrationMethodKind::kCorrectionMatrix),
            "/w/params.correction_matrix.report.yaml");
  EXPECT_EQ(StagedCalibration::stageReportPath("/w/mine.txt", CalibrationMethodKind::kDualRate), "/w/mine.txt");
}

}  // namespace
}  // namespace core
}  // namespace hrg_gyro

// The calibration method as a type (its one list, names, traits, the parameter file's provenance),
// and the texts users read the method list from, checked against that one list.
#include "hrg_gyro/core/model/calibration_method_kind.h"

#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <regex>
#include <set>
#include <sstream>
#include <stdexcept>
#include <vector>

#include "hrg_gyro/core/calibration/calibration_settings.h"
#include "hrg_gyro/core/model/parameter_file.h"

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

TEST(CalibrationMethodKindTest, EveryMethodHasOneDistinctNameThatParsesBack) {
  std::set<std::string> names;
  for (CalibrationMethodKind m : allCalibrationMethods()) {
    names.insert(nameOf(m));
    EXPECT_EQ(parseCalibrationMethod(nameOf(m)), m);
    ASSERT_TRUE(findCalibrationMethod(nameOf(m)).has_value());
  }
  EXPECT_EQ(names.size(), 7u);
  EXPECT_EQ(allCalibrationMethods().front(), CalibrationSettings().method);  // the default comes first
  EXPECT_EQ(calibrationMethodNames("|"), "dual_rate|constant_rate|step|correction_matrix|thermal|triad|field");
}

TEST(CalibrationMethodKindTest, UnknownNameIsRefusedWithTheList) {
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

TEST(CalibrationMethodKindTest, TraitsSayWhatEachMethodNeedsAndGives) {
  for (CalibrationMethodKind m : allCalibrationMethods()) {
    const CalibrationMethodTraits& t = traitsOf(m);
    // A method estimates K and D on the turntable, P from the generator sweep, or D from the virtual
    // rotation of a still gyro: one of the three.
    EXPECT_EQ(t.estimates_k_and_d + t.estimates_correction + t.virtual_rotation, 1) << t.name;
    EXPECT_EQ(t.uses_generator_pairs, t.estimates_correction) << t.name;
    EXPECT_EQ(t.needs_turntable, !t.uses_generator_pairs && !t.virtual_rotation) << t.name;
    EXPECT_GT(std::string(t.description).size(), 10u) << t.name;
  }
  EXPECT_TRUE(traitsOf(CalibrationMethodKind::kCorrectionMatrix).uses_generator_pairs);
  EXPECT_TRUE(traitsOf(CalibrationMethodKind::kThermal).frequency_dependent);
  EXPECT_FALSE(traitsOf(CalibrationMethodKind::kDualRate).frequency_dependent);
  EXPECT_TRUE(traitsOf(CalibrationMethodKind::kField).virtual_rotation);
  EXPECT_FALSE(traitsOf(CalibrationMethodKind::kField).needs_turntable);
}

TEST(ParameterOriginTest, NoneManualAndEveryMethodRoundTripThroughText) {
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

TEST(ParameterOriginTest, ParameterFileRefusesAnUnknownMethodNamingTheKey) {
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

TEST(CalibrationMethodKindTest, SettingsParserRefusesAnUnknownMethodNamingTheKey) {
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

TEST(CalibrationMethodKindTest, EveryLaunchFileMethodArgumentListsEveryMethod) {
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

TEST(CalibrationMethodKindTest, ParameterTemplateAndDocsListEveryMethod) {
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
    const std::string line = sessions.substr(at, sessions.find('\n', at) - at);
    // hrg_session simulates one axis: it lists the single-axis methods, and refuses the triad.
    const bool one_axis = std::string(tool) == "[--method ";
    for (CalibrationMethodKind k : allCalibrationMethods()) {
      if (one_axis && traitsOf(k).three_axes) continue;
      EXPECT_NE(line.find(nameOf(k)), std::string::npos)
          << "docs/recorded_sessions.md: " << tool << " does not name the method " << nameOf(k);
    }
  }
  // docs/calibration.md: one row of the method table per method.
  const std::string doc = readSourceFile("docs/calibration.md");
  for (CalibrationMethodKind k : allCalibrationMethods()) {
    EXPECT_NE(doc.find("\n| `" + nameOf(k) + "`"), std::string::npos)
        << "docs/calibration.md: no table row for " << nameOf(k);
  }
}

// ---- generator pairing -----------------------------------------------------------------------------

struct Pair {
  Nanoseconds stamp;
  ChannelVector raw, reference;
};

}  // namespace
}  // namespace core
}  // namespace hrg_gyro

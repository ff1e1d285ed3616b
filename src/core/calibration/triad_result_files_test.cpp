#include "hrg_gyro/core/calibration/triad_result_files.h"

#include <gtest/gtest.h>
#include <stdlib.h>

#include <filesystem>
#include <set>

#include "hrg_gyro/core/common/atomic_file.h"
#include "hrg_gyro/core/model/parameter_file.h"

namespace hrg_gyro {
namespace core {
namespace {

namespace fs = std::filesystem;
using fault_injection::OutputFileStep;

TriadOutcome acceptedOutcome() {
  TriadOutcome o;
  o.accepted = true;
  o.axis_names = {{"x", "y", "z"}};
  for (int i = 0; i < 3; ++i) {
    o.axes[i].accepted = true;
    o.axes[i].parameters.scale_factor = HarmonicModel(-0.3 - 0.01 * i);
    o.axes[i].parameters.earth_rate.latitude = 0.97;
    o.axes[i].parameters.calibration.source = "session.bag";
  }
  o.triad.axis_to_body << 1.0, 2e-5, -1e-5, -3e-5, 1.0, 4e-5, 1e-5, -2e-5, 1.0;
  o.triad.bias << 1e-8, 2e-8, -1e-8;
  o.triad.calibration.source = "session.bag";
  return o;
}

class TriadResultFilesTest : public ::testing::Test {
 protected:
  void SetUp() override {
    char tmpl[] = "/tmp/hrg_triad_result_files_test_XXXXXX";
    ASSERT_NE(::mkdtemp(tmpl), nullptr);
    dir_ = tmpl;
    paths_.triad = dir_ + "/triad.yaml";
    for (int i = 0; i < 3; ++i) paths_.axes[i] = dir_ + "/" + std::string(1, "xyz"[i]) + ".yaml";
  }
  void TearDown() override {
    fault_injection::setOutputFileFault({});
    fs::remove_all(dir_);
  }
  std::set<std::string> listing() const {
    std::set<std::string> names;
    for (const auto& e : fs::directory_iterator(dir_)) names.insert(e.path().filename().string());
    return names;
  }
  std::string dir_;
  TriadResultPaths paths_;
};

TEST_F(TriadResultFilesTest, WritesTheFourFilesThatReadBackAsCalibrated) {
  const TriadOutcome o = acceptedOutcome();
  const std::vector<std::string> written = saveTriadResult(o, paths_);
  ASSERT_EQ(written.size(), 4u);
  EXPECT_EQ(written.back(), paths_.triad);  // the file that ties the axes together goes last
  for (int i = 0; i < 3; ++i) EXPECT_EQ(loadParameterFile(paths_.axes[i]), o.axes[i].parameters);
  EXPECT_EQ(loadTriadFile(paths_.triad), o.triad);
  EXPECT_EQ(listing(), (std::set<std::string>{"triad.yaml", "x.yaml", "y.yaml", "z.yaml"}));

  // A second run replaces them and keeps the first as .bak.
  TriadOutcome again = o;
  again.triad.bias(0) = 5e-8;
  saveTriadResult(again, paths_);
  EXPECT_EQ(loadTriadFile(paths_.triad), again.triad);
  EXPECT_EQ(loadTriadFile(paths_.triad + ".bak"), o.triad);
  EXPECT_EQ(loadParameterFile(paths_.axes[0] + ".bak"), o.axes[0].parameters);
}

TEST_F(TriadResultFilesTest, ARefusedOrInvalidResultTouchesNothing) {
  TriadOutcome refused = acceptedOutcome();
  refused.accepted = false;
  refused.reason = "positions";
  EXPECT_THROW(saveTriadResult(refused, paths_), std::runtime_error);
  EXPECT_TRUE(listing().empty());

  // The triad is checked before any axis file is written: a misalignment beyond the loader's limit.
  TriadOutcome invalid = acceptedOutcome();
  invalid.triad.axis_to_body(0, 1) = 0.5;
  try {
    saveTriadResult(invalid, paths_);
    FAIL() << "an invalid triad was written";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("axis_to_body"), std::string::npos) << e.what();
  }
  EXPECT_TRUE(listing().empty());

  TriadResultPaths same = paths_;
  same.axes[2] = same.axes[1];
  EXPECT_THROW(saveTriadResult(acceptedOutcome(), same), std::runtime_error);
  EXPECT_TRUE(listing().empty());
}

TEST_F(TriadResultFilesTest, AFailureMidwayNamesWhatWasAndWasNotReplaced) {
  const TriadOutcome o = acceptedOutcome();
  saveTriadResult(o, paths_);
  TriadOutcome next = o;
  for (int i = 0; i < 3; ++i) next.axes[i].parameters.scale_factor = HarmonicModel(-0.31 - 0.01 * i);
  next.triad.bias(1) = 7e-8;
  // The third axis file's rename fails (a full directory, a vanished disk).
  fault_injection::setOutputFileFault([&](OutputFileStep step, const std::string& target) {
    return step == OutputFileStep::kRename && target == paths_.axes[2] ? EIO : 0;
  });
  try {
    saveTriadResult(next, paths_);
    FAIL() << "the injected failure was not reported";
  } catch (const std::runtime_error& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("already replaced: " + paths_.axes[0] + ", " + paths_.axes[1]), std::string::npos) << what;
    EXPECT_NE(what.find("not written: " + paths_.axes[2]), std::string::npos) << what;
  }
  fault_injection::setOutputFileFault({});
  EXPECT_EQ(loadParameterFile(paths_.axes[0]), next.axes[0].parameters);
  EXPECT_EQ(loadParameterFile(paths_.axes[1]), next.axes[1].parameters);
  EXPECT_EQ(loadParameterFile(paths_.axes[2]), o.axes[2].parameters);  // untouched
  EXPECT_EQ(loadTriadFile(paths_.triad), o.triad);                     // untouched
  for (const std::string& name : listing()) EXPECT_EQ(name.find(".tmp"), std::string::npos) << name;
}

}  // namespace
}  // namespace core
}  // namespace hrg_gyro

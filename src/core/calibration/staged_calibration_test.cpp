// Staged calibration: the stages run in order, each on the prior the previous one wrote, one report
// per stage.
#include "hrg_gyro/core/calibration/staged_calibration.h"

#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>
#include <vector>

#include "hrg_gyro/core/calibration/calibration_settings.h"
#include "hrg_gyro/core/model/parameter_file.h"

namespace hrg_gyro {
namespace core {
namespace {

TEST(StagedCalibrationTest, OneStageOfTheSettingsMethodByDefault) {
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

TEST(StagedCalibrationTest, RunsTheStagesInOrderEachOnItsPrior) {
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

TEST(StagedCalibrationTest, NamesOneReportPerStage) {
  EXPECT_EQ(StagedCalibration::defaultReportPath("/w/params.yaml"), "/w/params.report.yaml");
  EXPECT_EQ(StagedCalibration::defaultReportPath("/w/params"), "/w/params.report.yaml");
  EXPECT_EQ(StagedCalibration::stageReportPath("/w/params.report.yaml", CalibrationMethodKind::kCorrectionMatrix),
            "/w/params.correction_matrix.report.yaml");
  EXPECT_EQ(StagedCalibration::stageReportPath("/w/mine.txt", CalibrationMethodKind::kDualRate), "/w/mine.txt");
}

}  // namespace
}  // namespace core
}  // namespace hrg_gyro

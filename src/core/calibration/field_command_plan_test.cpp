// The virtual rotation a field calibration commands: a rest at 0, one segment per direction long
// enough for `turns` full turns of settled data, then 0; the shipped scenario's schedule is checked
// against it in field_calibration_test. The plan under way: its commands due on the precession
// state's stamps; a command it did not send (another node's, a rate it did not command, more commands
// than it sent) ends it with the reason, and so does a plan that is over without complete data.
#include "hrg_gyro/core/calibration/field_command_plan.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <stdexcept>
#include <string>

#include "core/testing/resonator_cases.h"
#include "hrg_gyro/core/common/units.h"
#include "hrg_gyro/core/resonator/first_order_model.h"

namespace hrg_gyro {
namespace core {
namespace {

TEST(FieldCommandPlanTest, RestThenOneSegmentPerDirectionThenZero) {
  CalibrationSettings s;
  s.field.rate = 0.25;
  s.field.turns = 1.5;
  s.field.rest = 4.0;
  s.field.directions = {-1, 1, 1};
  s.plateau.settle_time = 3.0;
  s.plateau.smoothing_span = 2.0;
  // settle + sweep + half a smoothing span + 1 s to spare
  const double segment = 3.0 + 1.5 * kTwoPi / 0.25 + 1.0 + 1.0;
  EXPECT_NEAR(fieldSegmentDuration(s), segment, 1e-12);
  const std::vector<PlannedPrecession> plan = fieldCommandPlan(s);
  ASSERT_EQ(plan.size(), 5u);
  EXPECT_EQ(plan[0].time, 0.0);
  EXPECT_EQ(plan[0].rate, 0.0);
  const double rates[] = {-0.25, 0.25, 0.25};
  for (int i = 0; i < 3; ++i) {
    EXPECT_NEAR(plan[1 + i].time, 4.0 + i * segment, 1e-9) << i;
    EXPECT_EQ(plan[1 + i].rate, rates[i]) << i;
  }
  EXPECT_NEAR(plan[4].time, 4.0 + 3 * segment, 1e-9);
  EXPECT_EQ(plan[4].rate, 0.0);  // the wave is left at rest
}

TEST(FieldCommandPlanTest, TheShippedPlanTakes270Seconds) {
  const std::vector<PlannedPrecession> plan = fieldCommandPlan(CalibrationSettings());
  ASSERT_EQ(plan.size(), 6u);  // 0, + - - +, 0
  // 5 s of rest and four segments of 2 + 4 pi / 0.2 + 0.5 + 1 s (docs/field_calibration.md)
  EXPECT_NEAR(plan.back().time, 5.0 + 4 * (3.5 + 2.0 * kTwoPi / 0.2), 1e-9);
  EXPECT_NEAR(plan.back().time, 270.3, 0.05);
}

// No plan runs for ever or longer than a day, whatever reached the settings (the parser bounds the
// keys; the plateau's settle time is not one of them).
TEST(FieldCommandPlanTest, APlanLongerThanADayIsRefused) {
  CalibrationSettings s;
  EXPECT_EQ(fieldPlanLengthProblem(s), "");
  EXPECT_NEAR(fieldPlanDuration(s), fieldCommandPlan(s).back().time, 1e-9);
  s.plateau.settle_time = 1e308;
  EXPECT_NE(fieldPlanLengthProblem(s), "");
  EXPECT_THROW(fieldCommandPlan(s), std::invalid_argument);
  EXPECT_THROW(checkFieldPlan(s), std::invalid_argument);
  s = CalibrationSettings();
  s.field.rate = 0.01;
  s.field.turns = 100.0;
  std::printf("[ refused ] %s\n", fieldPlanLengthProblem(s).c_str());
  EXPECT_THROW(fieldCommandPlan(s), std::invalid_argument);
}

// The loops' lag at the plan's rate, for a gyro whose resonator is given: predicted, and a plan whose
// lag no standard error the drift_std gate accepts could cover is refused before it starts.
TEST(FieldCommandPlanTest, TheLoopsLagAtThePlannedRateIsPredictedForAKnownGyro) {
  CalibrationSettings s;
  EXPECT_TRUE(std::isnan(fieldLoopLag(s.field, s.field.rate)));  // unknown gyro: not predicted
  EXPECT_NO_THROW(checkFieldPlan(s));
  const testing::ResonatorCase gyro = testing::realisticResonator();
  s.field.resonator = FieldResonator{gyro.shell, gyro.loops, gyro.drive};
  const double shipped = fieldLoopLag(s.field, 0.2), fast = fieldLoopLag(s.field, 10.0);
  EXPECT_DOUBLE_EQ(shipped, precessionLagDrift(gyro.shell, gyro.loops, gyro.drive, 0.2).peakDeviation());
  std::printf("[ predicted ] realistic gyro: loop lag %.3g rad/s at 0.2 rad/s, %.3g at 10 rad/s\n", shipped, fast);
  EXPECT_LT(shipped, 1e-9);  // far below the shipped plan's D standard errors (1.2e-8)
  EXPECT_NO_THROW(checkFieldPlan(s));
  s.field.rate = 10.0;
  EXPECT_GT(fast, s.field.max_drift_std);
  try {
    checkFieldPlan(s);
    ADD_FAILURE() << "a plan at 10 rad/s passed";
  } catch (const std::invalid_argument& e) {
    std::printf("[ refused ] %s\n", e.what());
    EXPECT_EQ(std::string(e.what()).rfind("field/rate", 0), 0u) << e.what();
  }
  EXPECT_NO_THROW(fieldCommandPlan(s));  // the plan itself can be made (a simulation may want it)
  EXPECT_THROW(FieldPlanRun(s, "/calibrator"), std::invalid_argument) << "but not run";
}

// The shipped settings with two short segments: rest 5 s, +0.2 and -0.2 rad/s.
CalibrationSettings twoSegments() {
  CalibrationSettings s;
  s.field.directions = {1, -1};
  s.field.turns = 1.5;
  return s;
}

constexpr Nanoseconds kT0 = 1000000000;
Nanoseconds at(double seconds) { return kT0 + toNanoseconds(seconds); }

PrecessionReport state(double seconds, double rate, std::uint64_t commands, const std::string& source) {
  return {at(seconds), rate, commands, source};
}

TEST(FieldPlanRunTest, CommandsFallDueOnTheStreamTime) {
  const CalibrationSettings s = twoSegments();
  FieldPlanRun run(s, "/calibrator");
  PlannedPrecession p;
  EXPECT_FALSE(run.nextDue(at(0.0), &p)) << "nothing before the plan's clock starts";
  EXPECT_FALSE(run.midway());
  run.start(state(0.0, -0.2, 7, "/calibrator"));  // a previous run's rate still in force
  ASSERT_TRUE(run.nextDue(at(0.0), &p));
  EXPECT_EQ(p.rate, 0.0);
  EXPECT_FALSE(run.nextDue(at(0.0), &p));
  EXPECT_TRUE(run.midway()) << "from its first command on, a run that ends commands 0";
  EXPECT_FALSE(run.nextDue(at(4.999), &p));
  ASSERT_TRUE(run.nextDue(at(5.0), &p));
  EXPECT_EQ(p.rate, 0.2);
  EXPECT_TRUE(run.midway());
  const double segment = fieldSegmentDuration(s);
  ASSERT_TRUE(run.nextDue(at(5.0 + segment), &p));
  EXPECT_EQ(p.rate, -0.2);
  // A stream that jumps far ahead takes up the commands due in order.
  ASSERT_TRUE(run.nextDue(at(100.0 + 2 * segment), &p));
  EXPECT_EQ(p.rate, 0.0);
  EXPECT_FALSE(run.nextDue(at(1000.0), &p));
  EXPECT_FALSE(run.midway());
  EXPECT_EQ(run.sent(), 4u);
}

// The plan started on a state with `commands` executed; its first two commands sent (0, then +0.2 at 5 s).
FieldPlanRun runningPlan(std::uint64_t commands) {
  FieldPlanRun run(twoSegments(), "/calibrator");
  run.start(state(0.0, 0.0, commands, ""));
  PlannedPrecession p;
  while (run.nextDue(at(5.0), &p)) {
  }
  return run;
}

TEST(FieldPlanRunTest, ItsOwnCommandsAreWhatItExpects) {
  FieldPlanRun run = runningPlan(3);
  EXPECT_EQ(run.check(state(0.1, 0.0, 3, "")), "") << "none of its commands executed yet";
  EXPECT_EQ(run.check(state(0.2, 0.0, 4, "/calibrator")), "");
  EXPECT_EQ(run.check(state(5.1, 0.0, 4, "/calibrator")), "") << "+0.2 sent, not yet taken up";
  EXPECT_EQ(run.check(state(5.2, 0.2, 5, "/calibrator")), "");
  EXPECT_EQ(run.check(state(5.3, 0.2 * (1 + 1e-8), 5, "/calibrator")), "") << "a rate reported in single precision";
  // A driver that names this calibrator may execute its latched command again when it reconnects.
  EXPECT_EQ(run.check(state(5.4, 0.2, 6, "/calibrator")), "");
}

TEST(FieldPlanRunTest, ARateInForceBeforeItsFirstCommandIsNoStrangers) {
  // A calibrator killed mid-plan left -0.2 rad/s from /old_calibrator in force: this run's first
  // command (rate 0) replaces it; until the driver executes that, nothing is judged.
  FieldPlanRun run(twoSegments(), "/calibrator");
  run.start(state(0.0, -0.2, 2, "/old_calibrator"));
  PlannedPrecession p;
  ASSERT_TRUE(run.nextDue(at(0.0), &p));
  EXPECT_EQ(run.check(state(0.005, -0.2, 2, "/old_calibrator")), "");
  EXPECT_EQ(run.check(state(0.010, 0.0, 3, "/calibrator")), "");
}

TEST(FieldPlanRunTest, AnotherNodesCommandEndsTheRunNamingIt) {
  FieldPlanRun run = runningPlan(3);
  EXPECT_EQ(run.check(state(5.2, 0.2, 5, "/calibrator")), "");
  const std::string why = run.check(state(20.0, 0.0, 6, "/teleop"));
  EXPECT_EQ(why,
            "the precession loop executed a command from /teleop, not from this calibrator (/calibrator): 0 rad/s "
            "in force");
  // Even at the very rate the plan commands.
  FieldPlanRun same = runningPlan(3);
  EXPECT_NE(same.check(state(20.0, 0.2, 6, "/teleop")), "");
}

TEST(FieldPlanRunTest, ARateItDidNotCommandEndsTheRun) {
  // A driver that names nobody: the rate and the count tell.
  FieldPlanRun run = runningPlan(3);
  EXPECT_EQ(run.check(state(5.2, 0.2, 5, "")), "");
  EXPECT_EQ(run.check(state(20.0, 0.5, 6, "")),
            "the precession state shows 0.5 rad/s in force, which this run did not command (its last command: 0.2 "
            "rad/s)");
  FieldPlanRun counted = runningPlan(3);
  EXPECT_EQ(counted.check(state(20.0, 0.2, 6, "")),
            "the driver executed 3 commands since the plan began and this run sent 2: another node commanded the "
            "precession loop");
  // A restarted driver (its count back at 0, no rate in force) cannot be this run's either.
  FieldPlanRun restarted = runningPlan(3);
  EXPECT_EQ(restarted.check(state(5.2, 0.2, 5, "/calibrator")), "");
  const std::string why = restarted.check(state(20.0, 0.0, 0, ""));
  EXPECT_NE(why.find("did not command"), std::string::npos) << why;
  EXPECT_NE(why.find("went back from 3 to 0"), std::string::npos) << why;
}

TEST(FieldPlanRunTest, RecordsThatGoBackAreTheSessionsToJudge) {
  FieldPlanRun run = runningPlan(3);
  EXPECT_EQ(run.check(state(20.0, 0.2, 5, "/calibrator")), "");
  // A looping bag or a restarted simulator: the session restarts the run (and the plan) after a few.
  EXPECT_EQ(run.check(state(0.5, 0.0, 0, "")), "");
  EXPECT_EQ(run.check(state(20.0, 0.0, 0, "")), "") << "not after the last record judged";
}

TEST(FieldPlanRunTest, APlanOverWithoutItsDataEndsTheRunSayingWhatItHolds) {
  const CalibrationSettings s = twoSegments();
  FieldPlanRun run(s, "/calibrator");
  run.start(state(0.0, 0.0, 0, ""));
  PlannedPrecession p;
  const double end = run.plan().back().time;
  while (run.nextDue(at(end), &p)) {
  }
  const std::string progress = "field: 0.2 rad/s: 1.5 turns, coverage 100 %; -0.2 rad/s: 0.7 turns, coverage 70 %;";
  const double margin = FieldPlanRun::overdueMargin(s);
  EXPECT_EQ(margin, 4.0);  // settle 2 s, smoothing span 1 s, 1 s
  EXPECT_EQ(run.overdue(at(end + margin - 0.01), at(end + margin), progress), "");
  // The wave stream behind (a busy processor): waited for, 30 s more of the state's stream.
  EXPECT_EQ(run.overdue(at(end + margin), at(end), progress), "");
  EXPECT_EQ(run.overdue(at(end + margin + 29.0), at(end), progress), "");
  const std::string why = run.overdue(at(end + margin), at(end + margin), progress);
  EXPECT_EQ(why, "the plan's last command is 4 s of stream time past and the data are incomplete: " + progress +
                     " (each direction needs coverage 95 % and 1 turns)");
  const std::string stopped = run.overdue(at(end + margin + 30.0), at(end - 10.0), progress);
  EXPECT_NE(stopped.find("the wave stream stopped"), std::string::npos) << stopped;
  const std::string none = run.overdue(at(end + margin + 30.0), 0, progress);
  EXPECT_NE(none.find("no wave sample received"), std::string::npos) << none;
  // Not before the plan is over, nor for a plan that never started.
  FieldPlanRun waiting(s, "/calibrator");
  EXPECT_EQ(waiting.overdue(at(1000.0), at(1000.0), progress), "");
}

// What the live calibrator does with each precession state, in one step: the plan waits for the
// driver to listen, sends what is due, stops on a stranger's command, and says when it is overdue.
TEST(FieldPlanRunTest, AStepDoesWhatOnePrecessionStateAsks) {
  CalibrationSettings s = twoSegments();
  s.method = CalibrationMethodKind::kField;
  GyroParameters prior;
  prior.earth_rate.latitude = 0.9;
  const CalibrationSession session(s, prior);  // no data: never complete
  FieldPlanRun run(s, "/calibrator");
  bool listens = false;
  int asked = 0;
  auto driver = [&] {
    ++asked;
    return listens;
  };
  FieldPlanStep step = run.step(state(0.0, 0.0, 3, ""), driver, session, 0);
  EXPECT_TRUE(step.due.empty()) << "commands sent before the driver listens would be lost";
  EXPECT_FALSE(run.started());
  listens = true;
  step = run.step(state(0.1, 0.0, 3, ""), driver, session, 0);
  ASSERT_EQ(step.due.size(), 1u);
  EXPECT_EQ(step.due[0].rate, 0.0);
  EXPECT_TRUE(run.started());
  step = run.step(state(5.1, 0.0, 4, "/calibrator"), driver, session, at(5.0));
  ASSERT_EQ(step.due.size(), 1u);
  EXPECT_EQ(step.due[0].rate, 0.2);
  EXPECT_EQ(asked, 2) << "asked only while the plan waits to start";
  EXPECT_EQ(run.sent(), 2u);
  // Past the plan's end without the data: overdue, with what the session holds.
  const double end = 0.1 + run.plan().back().time, margin = FieldPlanRun::overdueMargin(s);
  step = run.step(state(end + margin, 0.2, 5, "/calibrator"), driver, session, at(end + margin));
  ASSERT_EQ(step.due.size(), 2u);  // -0.2, then 0
  EXPECT_TRUE(step.foreign.empty());
  EXPECT_EQ(step.overdue, run.overdue(at(end + margin), at(end + margin), session.progress().summary));
  EXPECT_NE(step.overdue, "");
  // A stranger's command: the run stops there, nothing else due.
  FieldPlanRun other(s, "/calibrator");
  other.step(state(0.0, 0.0, 3, ""), driver, session, 0);
  step = other.step(state(5.1, 0.2, 5, "/teleop"), driver, session, 0);
  EXPECT_NE(step.foreign.find("/teleop"), std::string::npos) << step.foreign;
  EXPECT_TRUE(step.due.empty());
}

TEST(FieldPlanRunTest, ARunThatEndsMidwayCommandsZeroAndARestartedOneBeginsAgain) {
  FieldPlanRun run = runningPlan(3);  // 0 and +0.2 sent
  EXPECT_TRUE(run.end()) << "the wave is turning: command 0";
  EXPECT_FALSE(run.midway());
  EXPECT_FALSE(run.end()) << "once";
  FieldPlanRun unstarted(twoSegments(), "/calibrator");
  EXPECT_FALSE(unstarted.end()) << "nothing commanded yet";
  run.restart();
  EXPECT_FALSE(run.started());
  EXPECT_EQ(run.sent(), 0u);
  EXPECT_EQ(run.plan().size(), 4u);
  PlannedPrecession p;
  EXPECT_FALSE(run.nextDue(at(100.0), &p)) << "it waits for its next start";
  run.start(state(100.0, 0.0, 9, ""));
  ASSERT_TRUE(run.nextDue(at(100.0), &p));
  EXPECT_EQ(p.rate, 0.0);
}

TEST(FieldPlanRunTest, ARefusalComesFirstAndIsTheReason) {
  CalibrationOutcome o;
  o.gate("coverage", false, 0.7, 0.95, "70 % of the bins");
  o.gate("samples", true, 5000, 1000, "enough");
  o.decide();
  refuseFieldRun(&o, "plan", "the plan is over");
  EXPECT_FALSE(o.accepted);
  EXPECT_EQ(o.reason, "plan: the plan is over");
  ASSERT_EQ(o.gates.size(), 3u);
  EXPECT_EQ(o.gates[0].name, "plan");
  EXPECT_FALSE(o.gates[0].passed);
  EXPECT_EQ(o.gates[1].name, "coverage");
}

}  // namespace
}  // namespace core
}  // namespace hrg_gyro

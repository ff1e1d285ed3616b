// The single-axis record switch: each record goes where the run's method wants it (the table's or
// the precession loop's states, raw channels paired or processed, the generator's reference), the
// sweep ends when the raw channels reach its end (or are given up on), a restarted run starts the
// feed over, and a run watched for its end may finish when the lagging waves reach the table's last
// record.
#include "hrg_gyro/core/calibration/calibration_feed.h"

#include <gtest/gtest.h>

#include <cstdio>
#include <deque>
#include <memory>
#include <string>
#include <tuple>
#include <vector>

#include "core/testing/angle_level_session.h"

namespace hrg_gyro {
namespace core {
namespace {

constexpr Nanoseconds kMs = 1000000;

// `method` with the harmonic orders of the angle-level gyro's model, over `s`.
CalibrationSettings settingsFor(CalibrationMethodKind method, CalibrationSettings s = {}) {
  s.method = method;
  s.scale_factor_orders = {2, 4};
  s.drift_orders = {2};
  return s;
}

// A standing wave turning slowly, as the pickoffs see it.
WaveParameters waveAt(Nanoseconds t) { return {1.0, 0.02, 0.1 - 0.028 * toSeconds(t), 0.3}; }

ChannelSample channelsAt(Nanoseconds t) {
  ChannelSample s;
  s.stamp = t;
  s.z = idealChannels(waveAt(t));
  s.frequency = 5000.0;
  return s;
}

// The generator sweep: the wave set to angles across [0, pi) in turn.
WaveParameters sweepAt(int i) { return {1.0, 0.01, 0.15 * i, 0.2}; }

// The nominal model at the angle-level gyro's latitude.
GyroParameters prior() {
  GyroParameters p;
  p.earth_rate.latitude = 0.9;
  return p;
}

TEST(CalibrationFeedTest, TheRotationStreamIsTheMethodsOwn) {
  for (const CalibrationMethodKind method : {CalibrationMethodKind::kDualRate, CalibrationMethodKind::kField}) {
    SCOPED_TRACE(nameOf(method));
    CalibrationSession session(settingsFor(method), prior());
    CalibrationFeed feed(&session);
    for (int i = 1; i <= 10; ++i) {
      feed.addTableState(i * 10 * kMs, 0.0, 0.0, i);
      feed.addTableState(i * 10 * kMs + 1, 0.0, 0.0, i);
      feed.addPrecessionState(i * 10 * kMs, 0.0, 0.0, i);
    }
    // Two table states for each precession state: the count says which stream the session saw.
    EXPECT_EQ(session.counters().rotation_records_total, method == CalibrationMethodKind::kField ? 10u : 20u);
  }
}

TEST(CalibrationFeedTest, RawChannelsArePairedForTheCorrectionMatrixAndProcessedOtherwise) {
  const auto parameters = std::make_shared<const GyroParameters>();
  // The correction matrix: raw channels wait for their reference, and never reach the processor.
  {
    CalibrationSession session(settingsFor(CalibrationMethodKind::kCorrectionMatrix), prior());
    GyroProcessor processor(ProcessorConfig{}, parameters);
    CalibrationFeed feed(&session, &processor);
    for (int i = 1; i <= 30; ++i) feed.addChannels({i * kMs, idealChannels(sweepAt(i)), 5000.0, NAN});
    for (int i = 1; i <= 30; i += 2) feed.addReference(i * kMs, sweepAt(i));
    EXPECT_EQ(session.counters().used, 15u);  // the pairs
    EXPECT_EQ(session.counters().wave, 0u);
    EXPECT_EQ(processor.counters().received, 0u);
  }
  // Any other method: the channels go through the processor, its waves into the session, and a
  // reference is no concern of the run.
  {
    CalibrationSession session(settingsFor(CalibrationMethodKind::kDualRate), prior());
    GyroProcessor processor(ProcessorConfig{}, parameters), alone(ProcessorConfig{}, parameters);
    CalibrationFeed feed(&session, &processor);
    std::uint64_t waves = 0;
    for (int i = 1; i <= 100; ++i) {
      feed.addReference(i * kMs, sweepAt(i));
      feed.addChannels(channelsAt(1000 * kMs + i * kMs));
      waves += alone.process(channelsAt(1000 * kMs + i * kMs)).has_wave ? 1 : 0;
    }
    EXPECT_EQ(processor.counters().received, 100u);
    EXPECT_EQ(waves, 100u);
    EXPECT_EQ(session.counters().wave, waves);
    EXPECT_EQ(session.counters().used, 0u);
    EXPECT_EQ(feed.newestWave(), 1100 * kMs);
  }
}

TEST(CalibrationFeedTest, ASourceThatKnowsTheSweepSaysSoWhateverTheMethod) {
  const auto parameters = std::make_shared<const GyroParameters>();
  for (const CalibrationMethodKind method :
       {CalibrationMethodKind::kCorrectionMatrix, CalibrationMethodKind::kDualRate}) {
    SCOPED_TRACE(nameOf(method));
    CalibrationSession session(settingsFor(method), prior());
    GyroProcessor processor(ProcessorConfig{}, parameters);
    CalibrationFeed feed(&session, &processor);
    for (int i = 1; i <= 20; ++i) feed.addSweepSample(i * kMs, idealChannels(sweepAt(i)), sweepAt(i));
    EXPECT_EQ(session.counters().used, 20u) << "paired, never processed";
    EXPECT_EQ(processor.counters().received, 0u);
    // The wave is filed under the stamp given (a glitch moved the channels' own).
    feed.addWaveChannels(channelsAt(1000 * kMs + 400 * kMs), 1000 * kMs);
    EXPECT_EQ(processor.counters().received, 1u);
    EXPECT_EQ(session.counters().wave, 1u);
    EXPECT_EQ(feed.newestWave(), 1000 * kMs);
  }
}

// A correction-matrix run watched for its end (auto_finish_idle > 0), 30 pairs: complete.
struct SweepRun {
  CalibrationSession session;
  CalibrationFeed feed;
  SweepRun() : session(watchedSweepSettings(), prior()), feed(&session, nullptr, true) {}
  static CalibrationSettings watchedSweepSettings() {
    CalibrationSettings s = settingsFor(CalibrationMethodKind::kCorrectionMatrix);
    s.auto_finish_idle = 1.0;
    return s;
  }
};

TEST(CalibrationFeedTest, TheSweepEndsOnceTheRawChannelsReachItsEnd) {
  SweepRun run;
  // The reference stream runs ahead and leaves the sweep at 41 ms; the raw channels lag.
  for (int i = 1; i <= 30; ++i) EXPECT_FALSE(run.feed.addReference(i * kMs, sweepAt(i)).should_finish);
  EXPECT_FALSE(run.feed.addSweepEnd(41 * kMs).should_finish);
  for (int i = 1; i <= 30; ++i) {
    EXPECT_FALSE(run.feed.addChannels({i * kMs, idealChannels(sweepAt(i)), 5000.0, NAN}).should_finish) << i;
  }
  ASSERT_TRUE(run.session.complete());
  EXPECT_FALSE(run.feed.addChannels({40 * kMs, idealChannels(sweepAt(40)), 5000.0, NAN}).should_finish);
  EXPECT_TRUE(run.feed.addChannels({41 * kMs, idealChannels(sweepAt(41)), 5000.0, NAN}).should_finish);
}

TEST(CalibrationFeedTest, RawChannelsThatDoNotComeAreGivenUpOnAfterThirtySecondsOfTheTable) {
  SweepRun run;
  for (int i = 1; i <= 30; ++i) {
    run.feed.addReference(i * kMs, sweepAt(i));
    run.feed.addChannels({i * kMs, idealChannels(sweepAt(i)), 5000.0, NAN});
  }
  run.feed.addReference(31 * kMs, sweepAt(31));  // its raw channels never come
  EXPECT_FALSE(run.feed.addSweepEnd(41 * kMs).should_finish);
  const Nanoseconds wait = toNanoseconds(CalibrationFeed::kSweepChannelsWait);
  const FeedStep on_time = run.feed.addTableState(41 * kMs + wait, 0.0, 0.0, 1);
  EXPECT_FALSE(on_time.sweep_given_up);
  EXPECT_FALSE(on_time.should_finish);
  const FeedStep late = run.feed.addTableState(41 * kMs + wait + 1, 0.0, 0.0, 2);
  EXPECT_TRUE(late.sweep_given_up);
  EXPECT_TRUE(late.should_finish);
}

TEST(CalibrationFeedTest, ARestartedRunStartsTheFeedOver) {
  CalibrationSession session(settingsFor(CalibrationMethodKind::kCorrectionMatrix), prior());
  CalibrationFeed feed(&session);
  feed.addReference(2000 * kMs, sweepAt(1));  // waits for its raw channels
  for (int i = 0; i <= 20; ++i) EXPECT_FALSE(feed.addWave(1000 * kMs + i * 100 * kMs, 0.1, NAN, NAN).restarted);
  EXPECT_EQ(feed.newestWave(), 3000 * kMs);
  // The wave stream goes back for good (a bag loop): jump_persist records in a row.
  int restarted = 0;
  for (int i = 0; i < session.settings().jump_persist; ++i) {
    restarted += feed.addWave(1000 * kMs + i * 10 * kMs, 0.1, NAN, NAN).restarted ? 1 : 0;
  }
  EXPECT_EQ(restarted, 1);
  EXPECT_EQ(session.counters().restarts, 1u);
  EXPECT_LT(feed.newestWave(), 2000 * kMs) << "the wave's newest stamp is the new timeline's";
  // The reference of the previous pass was forgotten: these channels find no partner.
  feed.addChannels({2000 * kMs, idealChannels(sweepAt(1)), 5000.0, NAN});
  EXPECT_EQ(session.counters().used, 0u);
}

// The waves come a hop later than the table's states (through the processor): a run whose data are
// complete only from waves that arrive after the table's last state finishes on the wave that
// reaches that state's stamp.
TEST(CalibrationFeedTest, AWatchedRunMayFinishWhenTheWavesReachTheTablesLastState) {
  const testing::AngleLevelGyro g = testing::referenceGyro();
  CalibrationSettings s = settingsFor(CalibrationMethodKind::kDualRate);
  s.auto_finish_idle = 10.0;
  for (const bool watch : {true, false}) {
    SCOPED_TRACE(watch ? "watched" : "not watched");
    CalibrationSession session(s, prior());
    CalibrationFeed feed(&session, nullptr, watch);
    std::deque<std::tuple<Nanoseconds, double>> in_transit;  // 50 s of waves
    Nanoseconds finished_at = 0, complete_at = 0, last_state = 0;
    auto wave = [&] {
      const auto [t, theta] = in_transit.front();
      in_transit.pop_front();
      if (feed.addWave(t, theta, NAN, NAN).should_finish && finished_at == 0) finished_at = t;
      if (session.complete() && complete_at == 0) complete_at = t;
    };
    testing::runAngleLevel(g, testing::dualRateProfile(0.05, -0.05, 120.0),
                           [&](Nanoseconds t, double angle, double rate, double theta, double) {
                             EXPECT_FALSE(feed.addTableState(t, angle, rate, 0).should_finish);
                             last_state = t;
                             in_transit.emplace_back(t, theta);
                             if (in_transit.size() > 50000) wave();
                           });
    ASSERT_GT(session.counters().rotation_records_total, 0u);
    EXPECT_FALSE(session.complete()) << "the waves in transit complete the data";
    while (!in_transit.empty()) wave();
    ASSERT_GT(complete_at, 0);
    EXPECT_LT(complete_at, last_state);
    EXPECT_EQ(finished_at, watch ? last_state : 0);
    EXPECT_EQ(session.shouldFinish(), true);
  }
}

// The waves trail the table by a hop through the processor, by more on a busy host: a watched run
// finishes holding the same samples and records however far they trail (the host's pace).
TEST(CalibrationFeedTest, AWatchedRunFinishesWithTheSameDataWhateverTheWavesLag) {
  const testing::AngleLevelGyro g = testing::referenceGyro();
  CalibrationSettings s = settingsFor(CalibrationMethodKind::kDualRate);
  s.auto_finish_idle = 10.0;
  std::vector<std::tuple<std::uint64_t, std::uint64_t, double>> finished;  // used, records, K0
  for (const std::size_t lag : {std::size_t{0}, std::size_t{1}, std::size_t{90}, std::size_t{5000}}) {
    SCOPED_TRACE("waves " + std::to_string(lag) + " samples behind");
    CalibrationSession session(s, prior());
    CalibrationFeed feed(&session, nullptr, true);
    std::deque<std::tuple<Nanoseconds, double>> in_transit;
    bool done = false;
    auto note = [&](const FeedStep& step) {
      if (!step.should_finish || done) return;
      done = true;
      const CalibrationOutcome o = session.finish();
      ASSERT_TRUE(o.accepted) << o.reason;
      finished.emplace_back(session.counters().used, session.counters().rotation_records_total,
                            o.parameters.scale_factor.meanAt(NAN));
    };
    testing::runAngleLevel(g, testing::dualRateProfile(0.05, -0.05, 120.0),
                           [&](Nanoseconds t, double angle, double rate, double theta, double) {
                             if (done) return;
                             in_transit.emplace_back(t, theta);
                             while (!done && in_transit.size() > lag) {
                               const auto [wt, wtheta] = in_transit.front();
                               in_transit.pop_front();
                               note(feed.addWave(wt, wtheta, NAN, NAN));
                             }
                             if (!done) note(feed.addTableState(t, angle, rate, 0));
                           });
    ASSERT_TRUE(done);
  }
  ASSERT_EQ(finished.size(), 4u);
  for (std::size_t i = 1; i < finished.size(); ++i) EXPECT_EQ(finished[i], finished[0]) << i;
  std::printf("[ measured ] finished with %llu samples used, %llu table records, whatever the lag\n",
              static_cast<unsigned long long>(std::get<0>(finished[0])),
              static_cast<unsigned long long>(std::get<1>(finished[0])));
}

}  // namespace
}  // namespace core
}  // namespace hrg_gyro

// The rule that flags a processor output when the precession loop turned the wave over its interval:
// a commanded rate in force at either end or an angle that moved in between flags it, a command
// shorter than a sample too; the verdicts depend on the stamps only, whatever the order in which the
// state records and the outputs arrive; no state stream, no wait and no flag; a state stream that
// stops flags what follows as unknown without holding the outputs any longer; bad records are
// dropped and counted; a loop of either stream starts a new timeline; memory is bounded.
#include "hrg_gyro/core/processing/precession_watch.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <vector>

#include "core/testing/refusal.h"
#include "hrg_gyro/core/common/yaml_field.h"

namespace hrg_gyro {
namespace core {
namespace {

constexpr Nanoseconds kPeriod = 5000000;  // 200 Hz
constexpr Nanoseconds kStart = 1000000000;

Nanoseconds stampOf(int k) { return kStart + k * kPeriod; }

// A driver's precession loop: commanded rates switched at given times, reported with each sample as
// the driver does: the rate in force at the window's end, the commanded angle at its centre.
struct Schedule {
  struct Change {
    Nanoseconds at;
    double rate;
  };
  std::vector<Change> changes;  // in time order, rate 0 before the first

  double rateAt(Nanoseconds t) const {
    double r = 0.0;
    for (const Change& c : changes) {
      if (c.at <= t) r = c.rate;
    }
    return r;
  }
  double angleAt(Nanoseconds t) const {
    double angle = 0.0, rate = 0.0;
    Nanoseconds since = 0;
    for (const Change& c : changes) {
      if (c.at > t) break;
      angle += rate * toSeconds(c.at - since);
      rate = c.rate;
      since = c.at;
    }
    return angle + rate * toSeconds(t - since);
  }
  PrecessionStateRecord record(int k) const {
    const Nanoseconds t = stampOf(k);
    return {t, rateAt(t + kPeriod / 2), angleAt(t)};
  }
};

struct Decided {
  int k;  // the output's index: it covers (stampOf(k - 1), stampOf(k)]
  PrecessionDecision d;
};

// Drains every decision that can be made now, tagging them with the outputs' indices in order.
void drain(PrecessionWatch* watch, std::vector<int>* queued, std::vector<Decided>* out) {
  PrecessionDecision d;
  while (watch->next(&d)) {
    ASSERT_FALSE(queued->empty());
    out->push_back({queued->front(), d});
    queued->erase(queued->begin());
  }
}

// Feeds samples 0..n-1: the state record of sample k arrives `state_lag` samples after the output
// of sample k (negative: before it); outputs from sample 1 on.
std::vector<Decided> run(const Schedule& schedule, int n, int state_lag) {
  PrecessionWatch watch;
  std::vector<int> queued;
  std::vector<Decided> out;
  // The loop's first record comes first: before any record the watch cannot know the gyro has a
  // loop, and does not hold its outputs (PrecessionWatch.WithoutAStateStreamNothingWaits...).
  watch.addState(schedule.record(0));
  for (int step = std::min(0, state_lag); step < n + std::max(0, state_lag); ++step) {
    const int output_k = step, state_k = step - state_lag;
    if (state_lag > 0) {
      // outputs first within a step
      if (output_k >= 1 && output_k < n) {
        watch.addOutput(stampOf(output_k - 1), stampOf(output_k));
        queued.push_back(output_k);
        drain(&watch, &queued, &out);
      }
      if (state_k >= 1 && state_k < n) watch.addState(schedule.record(state_k));
    } else {
      if (state_k >= 1 && state_k < n) watch.addState(schedule.record(state_k));
      if (output_k >= 1 && output_k < n) {
        watch.addOutput(stampOf(output_k - 1), stampOf(output_k));
        queued.push_back(output_k);
      }
    }
    drain(&watch, &queued, &out);
  }
  watch.finish();
  drain(&watch, &queued, &out);
  EXPECT_TRUE(queued.empty());
  return out;
}

std::vector<int> flaggedIndices(const std::vector<Decided>& decided) {
  std::vector<int> k;
  for (const Decided& x : decided) {
    if (x.d.flagged()) k.push_back(x.k);
  }
  return k;
}

// On at 1 ms after sample 10 (its window's second half), off 1 ms after sample 20; a pulse of 1 ms
// between samples 30 and 31 that the rate of no record shows.
Schedule testSchedule() {
  Schedule s;
  s.changes = {{stampOf(10) + 1000000, 0.2},
               {stampOf(20) + 1000000, 0.0},
               {stampOf(30) + 500000, -0.3},
               {stampOf(30) + 1500000, 0.0}};
  return s;
}

TEST(PrecessionWatch, FlagsTheIntervalsACommandedRateOrAnglePassesThrough) {
  const Schedule s = testSchedule();
  const std::vector<Decided> out = run(s, 60, 0);
  ASSERT_EQ(out.size(), 59u);
  std::vector<int> expected;
  // 10: its record already reports the rate commanded in its window's second half (a half sample
  // early, never late); 11..20: the rate in force; 21: the rate was 0 at both ends but the angle
  // moved until the stop 1 ms after sample 20; 31: the 1 ms pulse, seen by the angle alone.
  for (int k = 10; k <= 21; ++k) expected.push_back(k);
  expected.push_back(31);
  EXPECT_EQ(flaggedIndices(out), expected);
  for (const Decided& x : out) {
    EXPECT_EQ(x.d.verdict, x.d.flagged() ? PrecessionVerdict::kPrecessing : PrecessionVerdict::kStill) << x.k;
    EXPECT_EQ(x.d.rate, s.record(x.k).rate) << "the rate in force at the output's stamp, " << x.k;
  }
}

TEST(PrecessionWatch, TheVerdictsDependOnTheStampsNotOnTheArrivalOrder) {
  const Schedule s = testSchedule();
  const std::vector<Decided> reference = run(s, 80, 0);
  // The state of a sample before its output, after it, or tens of samples late or early (within
  // the 1 s hold): the same verdicts, in the same order.
  for (const int lag : {-1, 1, 3, 37, 150, -40}) {
    const std::vector<Decided> out = run(s, 80, lag);
    ASSERT_EQ(out.size(), reference.size()) << "lag " << lag;
    for (std::size_t i = 0; i < out.size(); ++i) {
      EXPECT_EQ(out[i].k, reference[i].k);
      EXPECT_EQ(out[i].d.verdict, reference[i].d.verdict) << "lag " << lag << " output " << out[i].k;
      EXPECT_EQ(out[i].d.rate, reference[i].d.rate) << "lag " << lag << " output " << out[i].k;
    }
  }
}

TEST(PrecessionWatch, OutputsWaitForTheStateOfTheirStamp) {
  PrecessionWatch watch;
  PrecessionDecision d;
  watch.addState({stampOf(0), 0.0, 0.0});
  watch.addOutput(stampOf(0), stampOf(1));
  EXPECT_FALSE(watch.next(&d)) << "the record of stamp 1 may still be on its way";
  EXPECT_EQ(watch.waiting(), 1u);
  watch.addState({stampOf(1), 0.5, 0.0});
  ASSERT_TRUE(watch.next(&d));
  EXPECT_EQ(d.verdict, PrecessionVerdict::kPrecessing);
  EXPECT_EQ(d.rate, 0.5);
  EXPECT_FALSE(watch.next(&d));
}

TEST(PrecessionWatch, WithoutAStateStreamNothingWaitsAndNothingIsFlagged) {
  PrecessionWatch watch;
  PrecessionDecision d;
  for (int k = 1; k < 100; ++k) {
    watch.addOutput(stampOf(k - 1), stampOf(k));
    ASSERT_TRUE(watch.next(&d)) << k;
    EXPECT_EQ(d.verdict, PrecessionVerdict::kNoState);
    EXPECT_FALSE(d.flagged());
    EXPECT_TRUE(std::isnan(d.rate));
  }
  EXPECT_FALSE(watch.seenState());
  EXPECT_EQ(watch.counters().decided, 99u);
}

TEST(PrecessionWatch, AStateStreamThatBeganLaterTellsByItsFirstRate) {
  // A calibrator killed mid-plan left -0.2 rad/s in force; a processor started since sees the loop's
  // first record after its first outputs' stamps.
  PrecessionWatch watch;
  PrecessionDecision d;
  watch.addState({stampOf(5), -0.2, 3.0});
  watch.addOutput(stampOf(2), stampOf(3));
  ASSERT_TRUE(watch.next(&d));
  EXPECT_EQ(d.verdict, PrecessionVerdict::kPrecessing);
  EXPECT_EQ(d.rate, -0.2);
}

TEST(PrecessionWatch, AStoppedStateStreamFlagsUnknownAndHoldsNoLonger) {
  const Schedule s;       // never precessed
  PrecessionWatch watch;  // hold 1 s = 200 samples
  std::vector<int> queued;
  std::vector<Decided> out;
  for (int k = 0; k <= 50; ++k) watch.addState(s.record(k));
  int first_released_late = -1;
  for (int k = 1; k <= 400; ++k) {
    watch.addOutput(stampOf(k - 1), stampOf(k));
    queued.push_back(k);
    const std::size_t before = out.size();
    drain(&watch, &queued, &out);
    if (k > 50 && first_released_late < 0 && out.size() > before) first_released_late = k;
  }
  // Outputs past the last record wait until the newest output is 1 s of stamps beyond that record;
  // then they go out as unknown, and every later one at once.
  EXPECT_EQ(first_released_late, 251);
  ASSERT_EQ(out.size(), 400u);
  EXPECT_EQ(watch.waiting(), 0u);
  for (const Decided& x : out) {
    EXPECT_EQ(x.d.verdict, x.k <= 50 ? PrecessionVerdict::kStill : PrecessionVerdict::kUnknown) << x.k;
  }
  // The stream comes back: records decide again (every output waits for its own record again).
  for (int k = 401; k <= 410; ++k) {
    watch.addState(s.record(k - 1));
    watch.addOutput(stampOf(k - 1), stampOf(k));
    queued.push_back(k);
    drain(&watch, &queued, &out);
  }
  watch.addState(s.record(410));
  drain(&watch, &queued, &out);
  ASSERT_EQ(out.size(), 410u);
  EXPECT_EQ(out.back().d.verdict, PrecessionVerdict::kStill);
  EXPECT_EQ(watch.counters().unknown, 350u);
}

TEST(PrecessionWatch, BadRecordsAreDroppedAndCounted) {
  PrecessionWatch watch;
  EXPECT_FALSE(watch.addState({0, 0.0, 0.0}));
  EXPECT_FALSE(watch.addState({stampOf(0), NAN, 0.0}));
  EXPECT_FALSE(watch.addState({stampOf(0), 0.0, INFINITY}));
  EXPECT_FALSE(watch.seenState());
  EXPECT_TRUE(watch.addState({stampOf(3), 0.0, 0.0}));
  EXPECT_FALSE(watch.addState({stampOf(3), 0.7, 0.0})) << "a duplicate stamp";
  EXPECT_FALSE(watch.addState({stampOf(2), 0.7, 0.0})) << "out of order, back by less than backward_reset";
  EXPECT_EQ(watch.counters().dropped_states, 5u);
  EXPECT_EQ(watch.counters().states, 1u);
  PrecessionDecision d;
  watch.addOutput(stampOf(2), stampOf(3));
  ASSERT_TRUE(watch.next(&d));
  EXPECT_EQ(d.verdict, PrecessionVerdict::kStill) << "the dropped 0.7 rad/s must not count";
}

TEST(PrecessionWatch, ALoopOfBothStreamsStartsANewTimelineInEitherOrder) {
  const Schedule s = testSchedule();
  for (const bool states_first : {true, false}) {
    PrecessionWatch watch;
    std::vector<int> queued;
    std::vector<Decided> out;
    // First pass: samples 0..140 (0.7 s), the outputs' last 3 still waiting for their records.
    for (int k = 0; k <= 140; ++k) {
      if (k <= 137) watch.addState(s.record(k));
      if (k >= 1) {
        watch.addOutput(stampOf(k - 1), stampOf(k));
        queued.push_back(k);
      }
      drain(&watch, &queued, &out);
    }
    EXPECT_EQ(watch.waiting(), 3u);
    // The bag loops back to sample 0: one stream goes back first, the other follows a few samples
    // later (its old timeline's last records still in transit).
    auto pass_states = [&](int from, int to) {
      for (int k = from; k <= to; ++k) watch.addState(s.record(k));
      drain(&watch, &queued, &out);
    };
    auto pass_outputs = [&](int from, int to) {
      for (int k = from; k <= to; ++k) {
        watch.addOutput(stampOf(k - 1), stampOf(k));
        queued.push_back(1000 + k);
        drain(&watch, &queued, &out);
      }
    };
    if (states_first) {
      pass_states(0, 5);  // the jump back decides the three waiting outputs (no record reached them)
      EXPECT_EQ(watch.waiting(), 0u);
      pass_outputs(2, 5);
      pass_states(6, 30);
      pass_outputs(6, 30);
    } else {
      pass_outputs(2, 5);  // the outputs go back: the three are decided, the records cleared
      EXPECT_FALSE(watch.addState(s.record(138))) << "a record of the old timeline, in transit";
      pass_states(1, 30);
      pass_outputs(6, 30);
    }
    drain(&watch, &queued, &out);
    EXPECT_EQ(watch.waiting(), 0u);
    ASSERT_EQ(out.size(), 140u + 29u);
    for (int i = 137; i < 140; ++i) EXPECT_EQ(out[i].d.verdict, PrecessionVerdict::kUnknown) << out[i].k;
    // The second pass is decided as the first was: 10..21 precessed.
    for (std::size_t i = 140; i < out.size(); ++i) {
      const int k = out[i].k - 1000;
      const bool expected = k >= 10 && k <= 21;
      EXPECT_EQ(out[i].d.flagged(), expected) << "second pass, output " << k << (states_first ? " (states first)" : "");
      EXPECT_NE(out[i].d.verdict, PrecessionVerdict::kUnknown) << k;
    }
    EXPECT_EQ(watch.counters().timelines, states_first ? 2u : 1u);
  }
}

TEST(PrecessionWatch, MemoryIsBoundedWhateverTheStreamsDo) {
  PrecessionWatchSettings settings;
  settings.max_held = 50;
  settings.hold = 1e6;  // no stall rule: only the bound can release them
  PrecessionWatch watch(settings);
  PrecessionDecision d;
  // A state stream with no outputs keeps at most max_held records.
  for (int k = 0; k < 1000; ++k) watch.addState({stampOf(k), 0.0, 0.0});
  // Outputs far ahead of the state stream wait, at most max_held of them.
  std::vector<PrecessionVerdict> verdicts;
  for (int k = 2000; k < 2200; ++k) {
    watch.addOutput(stampOf(k - 1), stampOf(k));
    while (watch.next(&d)) verdicts.push_back(d.verdict);
    EXPECT_LE(watch.waiting(), 50u);
  }
  EXPECT_EQ(verdicts.size(), 150u);
  for (PrecessionVerdict v : verdicts) EXPECT_EQ(v, PrecessionVerdict::kUnknown);
  watch.finish();
  while (watch.next(&d)) verdicts.push_back(d.verdict);
  EXPECT_EQ(verdicts.size(), 200u);
}

TEST(PrecessionWatch, SettingsAreCheckedNamingTheParameter) {
  PrecessionWatchSettings s;
  s.hold = 0.0;
  EXPECT_EQ(refusedKey([&] { PrecessionWatch w(s); }), "precession_hold");
  s.hold = 1.0;
  s.backward_reset = NAN;
  EXPECT_THROW(PrecessionWatch w(s), ConfigError);
}

}  // namespace
}  // namespace core
}  // namespace hrg_gyro

#include "hrg_gyro/core/estimation/table_stamp_regulariser.h"

#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <vector>

#include "hrg_gyro/core/simulation/gaussian_noise.h"

namespace hrg_gyro {
namespace core {
namespace {

constexpr Nanoseconds kStart = 1700000000LL * 1000000000LL;  // a realistic epoch stamp

struct LogClock {
  double rate = 100.0;      ///< Hz
  double jitter = 0.0;      ///< s
  double offset = 0.0;      ///< s
  double rate_error = 0.0;  ///< relative
  double step_at = -1.0;    ///< s (< 0: none) ...
  double step = 0.0;        ///< ... of this size, s
  double loss = 0.0;        ///< fraction of records lost
  bool with_sequence = true;
};

struct Outcome {
  double rms_error = 0.0;  ///< s, regularised stamp against the true sampling instant (+ offset)
  double max_error = 0.0;
  TableStampStatistics statistics;
};

/// Runs `seconds` of a log through a regulariser; the error of each returned stamp against the
/// instant the record was sampled at on the controller's clock without jitter, from `skip` s on.
Outcome run(const LogClock& clock, double seconds, double skip = 5.0, const StampRegulariserSettings& settings = {},
            std::uint64_t seed = 3) {
  TableStampRegulariser r(settings);
  GaussianNoise jitter(seed), loss(seed ^ 0x77);
  Outcome o;
  double squares = 0.0;
  long n = 0;
  const long records = static_cast<long>(seconds * clock.rate);
  for (long i = 0; i < records; ++i) {
    const double t = i / clock.rate;
    if (clock.loss > 0.0 && loss.uniform() < clock.loss) continue;
    double ideal = t + clock.offset + clock.rate_error * t;
    if (clock.step_at >= 0.0 && t >= clock.step_at) ideal += clock.step;
    const Nanoseconds stamp = kStart + toNanoseconds(ideal + clock.jitter * jitter.next());
    const Nanoseconds out =
        r.regularise(stamp, clock.with_sequence ? static_cast<std::uint64_t>(i) : TableStampRegulariser::kNoSequence);
    if (t < skip || (clock.step_at >= 0.0 && t >= clock.step_at && t < clock.step_at + skip)) continue;
    const double error = toSeconds(out - kStart) - ideal;
    squares += error * error;
    o.max_error = std::max(o.max_error, std::abs(error));
    ++n;
  }
  o.rms_error = std::sqrt(squares / std::max(1L, n));
  o.statistics = r.statistics();
  return o;
}

TEST(TableStampRegulariserTest, ExactStampsComeBackExact) {
  LogClock c;
  const Outcome o = run(c, 60.0, 1.0);
  EXPECT_LT(o.max_error, 2e-9);
  EXPECT_TRUE(o.statistics.fixed_rate);
  EXPECT_TRUE(o.statistics.used_sequence);
  EXPECT_NEAR(o.statistics.period, 0.01, 1e-12);
}

TEST(TableStampRegulariserTest, JitterIsRemovedAndMeasured) {
  // 2 ms of jitter at 100 Hz with 1 % of the records lost: a line over 20 s (2000 records) leaves
  // about 2 ms x 2 / sqrt(2000) = 0.09 ms at its newest end, smooth from record to record.
  LogClock c;
  c.offset = 0.1;
  c.loss = 0.01;
  for (bool sequence : {true, false}) {
    c.with_sequence = sequence;
    // Counted by the spacing, a record is taken for the next one unless its stamp lies 3/4 of a
    // spacing past it: 2 ms of jitter at 10 ms would miscount one record in 10^4, 1 ms none.
    c.jitter = sequence ? 2e-3 : 1e-3;
    const Outcome o = run(c, 300.0, 30.0);
    SCOPED_TRACE(sequence ? "sequence numbers" : "counted by the spacing");
    std::printf("jitter %.0f ms, %s: regularised stamps rms %.4f ms (max %.4f), jitter measured %.3f ms\n",
                1e3 * c.jitter, sequence ? "seq" : "spacing", 1e3 * o.rms_error, 1e3 * o.max_error,
                1e3 * o.statistics.jitter);
    EXPECT_TRUE(o.statistics.fixed_rate) << o.statistics.note;
    EXPECT_EQ(o.statistics.used_sequence, sequence);
    EXPECT_LT(o.rms_error, 0.1e-3);
    EXPECT_NEAR(o.statistics.jitter, c.jitter, 0.05 * c.jitter);
    EXPECT_EQ(o.statistics.clock_steps, 0u);
  }
}

TEST(TableStampRegulariserTest, FollowsTheRateDifferenceOfTwoClocks) {
  LogClock c;
  c.jitter = 1e-3;
  c.rate_error = 1e-4;  // 100 ppm: 0.1 s over the 1000 s
  const Outcome o = run(c, 1000.0, 30.0);
  EXPECT_LT(o.rms_error, 0.05e-3);
}

TEST(TableStampRegulariserTest, ALogFasterThanItsJitterNeedsItsSequenceNumbers) {
  // 1 kHz with 2 ms of jitter: the stamps even swap places, yet the sequence numbers count them.
  LogClock c;
  c.rate = 1000.0;
  c.jitter = 2e-3;
  const Outcome counted = run(c, 60.0, 25.0);
  EXPECT_TRUE(counted.statistics.fixed_rate) << counted.statistics.note;
  EXPECT_LT(counted.rms_error, 0.05e-3);
  c.with_sequence = false;
  const Outcome uncounted = run(c, 60.0, 25.0);
  EXPECT_FALSE(uncounted.statistics.fixed_rate);
  EXPECT_NE(uncounted.statistics.note.find("cannot be counted"), std::string::npos) << uncounted.statistics.note;
  EXPECT_EQ(uncounted.statistics.regularised, 0u);
}

TEST(TableStampRegulariserTest, AClockStepStartsANewLine) {
  LogClock c;
  c.jitter = 1e-3;
  c.step_at = 100.0;
  c.step = 0.045;  // not a whole number of spacings, which would look like lost records
  const Outcome o = run(c, 200.0, 30.0);
  EXPECT_EQ(o.statistics.clock_steps, 1u);
  // Records right after the step pass unchanged until the new line has enough of them; after that
  // the error is the jitter averaged over the growing line.
  EXPECT_LT(o.rms_error, 0.2e-3);
}

TEST(TableStampRegulariserTest, GlitchedStampsPassUnchangedAndDoNotMoveTheLine) {
  TableStampRegulariser r;
  for (int i = 0; i < 1000; ++i) {
    const Nanoseconds ideal = kStart + toNanoseconds(i * 0.01);
    Nanoseconds stamp = ideal;
    if (i == 500) stamp = 0;                           // a zero stamp
    if (i == 600) stamp = ideal - toNanoseconds(0.5);  // a backward one
    const Nanoseconds out = r.regularise(stamp, static_cast<std::uint64_t>(i));
    if (i == 500 || i == 600) {
      EXPECT_EQ(out, stamp) << i;
    } else if (i >= 20) {
      EXPECT_NEAR(toSeconds(out - ideal), 0.0, 1e-9) << i;
    }
  }
  EXPECT_EQ(r.statistics().off_line, 2u);
  EXPECT_EQ(r.statistics().clock_steps, 0u);
}

TEST(TableStampRegulariserTest, AnIrregularLogIsLeftAsItIs) {
  // Records every 5 to 15 ms at random (an event-driven logger): no line to put them on.
  TableStampRegulariser r;
  GaussianNoise u(5);
  double t = 0.0;
  for (int i = 0; i < 500; ++i) {
    t += 0.005 + 0.01 * u.uniform();
    const Nanoseconds stamp = kStart + toNanoseconds(t);
    EXPECT_EQ(r.regularise(stamp, static_cast<std::uint64_t>(i)), stamp);
  }
  EXPECT_FALSE(r.statistics().fixed_rate);
  EXPECT_NE(r.statistics().note.find("not a fixed-rate log"), std::string::npos) << r.statistics().note;
}

TEST(TableStampRegulariserTest, SequenceNumbersThatDoNotCountRecordsAreSetAside) {
  // A publisher that leaves every sequence number at 0: the records are counted by the spacing.
  TableStampRegulariser r;
  for (int i = 0; i < 500; ++i) {
    const Nanoseconds ideal = kStart + toNanoseconds(i * 0.01);
    const Nanoseconds out = r.regularise(ideal, 0);
    if (i >= 20) EXPECT_NEAR(toSeconds(out - ideal), 0.0, 1e-9) << i;
  }
  EXPECT_FALSE(r.statistics().used_sequence);
  EXPECT_TRUE(r.statistics().fixed_rate);
}

TEST(TableStampRegulariserTest, RenumberedSequenceNumbersAreSetAside) {
  // roscpp numbers the messages it sends over TCP itself: a record lost before publishing leaves no
  // gap. The stamps then disagree with the count, and the spacing takes over.
  TableStampRegulariser r;
  std::uint64_t published = 0;
  for (int i = 0; i < 2000; ++i) {
    if (i % 100 == 50) continue;  // lost at the controller
    const Nanoseconds ideal = kStart + toNanoseconds(i * 0.01);
    const Nanoseconds out = r.regularise(ideal, published++);
    if (i >= 400) EXPECT_NEAR(toSeconds(out - ideal), 0.0, 1e-9) << i;
  }
  EXPECT_FALSE(r.statistics().used_sequence);
  EXPECT_TRUE(r.statistics().fixed_rate);
  EXPECT_EQ(r.statistics().clock_steps, 0u);
}

TEST(TableStampRegulariserTest, DisabledOrBadSettings) {
  StampRegulariserSettings off;
  off.enabled = false;
  TableStampRegulariser r(off);
  EXPECT_EQ(r.regularise(kStart + 12345, 0), kStart + 12345);
  StampRegulariserSettings bad;
  bad.window = 0.0;
  EXPECT_THROW(TableStampRegulariser{bad}, std::invalid_argument);
}

}  // namespace
}  // namespace core
}  // namespace hrg_gyro

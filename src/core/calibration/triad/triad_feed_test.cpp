// The live triad calibrator's feed (triad_feed.h) on an angle-level triad session (core/testing/
// angle_level_triad.h): streams that arrive late relative to each other give the calibration, bit
// for bit, what it gets from the records in stamp order (what hrg_bag reads from a bag); a stream
// that lags beyond the hold is fed late, not lost; a missing axis stream delays the others by the
// hold only and its gate names the axis; bad records are dropped and counted; the glitch battery (a
// record stamped far ahead, far back, slightly back, zero, a duplicate, a bad value) on every stream,
// live and straight into the calibration, costs those records only; a stream that goes back for good
// restarts the run; the auto-finish rule.
#include "hrg_gyro/core/calibration/triad/triad_feed.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <vector>

#include "core/testing/angle_level_triad.h"

namespace hrg_gyro {
namespace core {
namespace {

using testing::AngleLevelTriad;
using testing::TriadPosition;

/// One record of the session, as some stream delivers it.
struct Event {
  int stream;  // TriadFeed::Stream
  Nanoseconds stamp;
  double a = 0.0, b = 0.0;
  std::uint32_t sequence = 0;
  FixtureRecord fixture;
  Nanoseconds sent = 0;  ///< when it was sent, if not at its stamp (a glitched stamp)
};

AngleLevelTriad triad() {
  AngleLevelTriad g = testing::misalignedTriad();
  g.d[1] = g.d[2] = HarmonicModel(0.0);  // one axis's D(theta) harmonics are enough here
  g.rate_hz = 200.0;                     // enough for the fits, and a session of 1.5 M records
  return g;
}

/// The session's records in the order the simulation emits them (stamp order), computed once.
const std::vector<Event>& session() {
  static const std::vector<Event> events = [] {
    std::vector<Event> out;
    testing::TriadSinks sinks;
    sinks.table = [&](Nanoseconds stamp, double angle, double rate, std::uint32_t seq) {
      out.push_back({TriadFeed::kTable, stamp, angle, rate, seq, {}});
    };
    sinks.fixture = [&](const FixtureRecord& f) { out.push_back({TriadFeed::kFixture, f.stamp, 0, 0, 0, f}); };
    sinks.wave = [&](int axis, Nanoseconds stamp, double theta) {
      out.push_back({TriadFeed::kAxis0 + axis, stamp, theta, NAN, 0, {}});
    };
    runAngleLevelTriad(triad(), testing::sixPositions(0.4, 40.0, 2, 30.0), sinks);
    return out;
  }();
  return events;
}

/// The calibration's settings and priors for triad().
const testing::AngleLevelTriadSettings& calibrationSettings() {
  static const testing::AngleLevelTriadSettings s = testing::settingsFor(triad());
  return s;
}

TriadFeed makeFeed(const TriadFeedSettings& feed = TriadFeedSettings()) {
  const testing::AngleLevelTriadSettings& s = calibrationSettings();
  return TriadFeed(s.axis, s.triad, s.priors, TriadParameters(), feed);
}

/// The calibration the feed feeds, fed here directly (the records in stamp order).
TriadCalibration makeCalibration() {
  const testing::AngleLevelTriadSettings& s = calibrationSettings();
  return TriadCalibration(s.axis, s.triad, s.priors, TriadParameters());
}

void deliver(TriadFeed* feed, const Event& e) {
  switch (e.stream) {
    case TriadFeed::kFixture:
      feed->addFixture(e.fixture);
      break;
    case TriadFeed::kTable:
      feed->addTurntable(e.stamp, e.a, e.b, e.sequence);
      break;
    default:
      feed->addWave(e.stream - TriadFeed::kAxis0, e.stamp, e.a, e.b);
  }
}

/// The events in the order they arrive when each stream is `delay[stream]` s late (transport, a
/// bench that publishes the fixture from another computer).
std::vector<Event> arrival(const std::vector<Event>& events, const std::array<double, TriadFeed::kStreamCount>& delay) {
  std::vector<std::pair<Nanoseconds, std::size_t>> order;
  order.reserve(events.size());
  for (std::size_t k = 0; k < events.size(); ++k) {
    const Nanoseconds sent = events[k].sent != 0 ? events[k].sent : events[k].stamp;
    order.push_back({sent + toNanoseconds(delay[events[k].stream]), k});
  }
  std::stable_sort(order.begin(), order.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
  std::vector<Event> out;
  out.reserve(events.size());
  for (const auto& o : order) out.push_back(events[o.second]);
  return out;
}

TEST(TriadFeedTest, LateStreamsGiveTheCalibrationExactlyWhatTheStampOrderGives) {
  // The reference: the records straight into the calibration in stamp order, as hrg_bag does.
  TriadCalibration direct = makeCalibration();
  for (const Event& e : session()) {
    if (e.stream == TriadFeed::kFixture) direct.addFixture(e.fixture);
    if (e.stream == TriadFeed::kTable) direct.addTurntable(e.stamp, e.a, e.b, e.sequence);
    if (e.stream >= TriadFeed::kAxis0) direct.addWave(e.stream - TriadFeed::kAxis0, e.stamp, e.a, e.b);
  }
  const TriadOutcome reference = direct.finish();
  ASSERT_TRUE(reference.accepted) << reference.reason;

  // Live: the fixture 0.9 s late (it repeats once a second), axis y 0.3 s, the table 50 ms.
  const std::vector<Event> live = arrival(session(), {{0.9, 0.05, 0.0, 0.3, 0.01}});
  TriadFeed feed = makeFeed();
  std::size_t most_held = 0;
  for (const Event& e : live) {
    deliver(&feed, e);
    most_held = std::max(most_held, feed.held());
  }
  const TriadOutcome o = feed.finish();
  ASSERT_TRUE(o.accepted) << o.reason;
  EXPECT_EQ(o.triad.axis_to_body, reference.triad.axis_to_body);
  EXPECT_EQ(o.triad.bias, reference.triad.bias);
  for (int i = 0; i < 3; ++i) {
    EXPECT_EQ(o.axes[i].parameters.scale_factor, reference.axes[i].parameters.scale_factor) << i;
    EXPECT_EQ(o.axes[i].parameters.drift, reference.axes[i].parameters.drift) << i;
  }
  for (int s = 0; s < TriadFeed::kStreamCount; ++s) {
    EXPECT_EQ(feed.counters(s).fed, feed.counters(s).received) << s;
    EXPECT_EQ(feed.counters(s).late, 0u) << s;
    EXPECT_EQ(feed.counters(s).out_of_order, 0u) << s;
  }
  // Held: about the fixture's delay plus its repeat period of every stream, not more.
  const double rate = triad().rate_hz;
  std::printf("most records held: %zu (%.2f s of the four fast streams)\n", most_held, most_held / (4 * rate));
  EXPECT_LE(most_held, static_cast<std::size_t>(4 * rate * TriadFeedSettings().hold + 10));
}

TEST(TriadFeedTest, AStreamLaggingBeyondTheHoldIsFedLateNotLost) {
  // Axis z 3 s behind the others, with a hold of 1 s: its records come after later stamps of the
  // others. They are fed all the same (counted late), in z's own order, and no stream restarts.
  TriadFeedSettings settings;
  settings.hold = 1.0;
  TriadFeed feed = makeFeed(settings);
  for (const Event& e : arrival(session(), {{0.0, 0.0, 0.0, 0.0, 3.0}})) deliver(&feed, e);
  const TriadStreamCounters& z = feed.counters(TriadFeed::kAxis0 + 2);
  EXPECT_GT(z.late, z.received / 2);
  EXPECT_EQ(z.out_of_order, 0u);
  EXPECT_EQ(feed.restarts(), 0u);
  const TriadOutcome o = feed.finish();
  EXPECT_EQ(z.fed, z.received);
  ASSERT_TRUE(o.accepted) << o.reason;
  // Each axis's stage and the stored samples are in stamp order per stream: only a z record at a
  // change of the fixture's state could be routed otherwise, and this plan changes it at rest.
  TriadFeed ordered = makeFeed();
  for (const Event& e : session()) deliver(&ordered, e);
  const TriadOutcome reference = ordered.finish();
  EXPECT_EQ(o.triad.axis_to_body, reference.triad.axis_to_body);
}

TEST(TriadFeedTest, AMissingAxisStreamDelaysTheOthersByTheHoldAndItsGateNamesIt) {
  TriadFeedSettings settings;
  settings.hold = 1.5;
  TriadFeed feed = makeFeed(settings);
  std::size_t most_held = 0;
  for (const Event& e : session()) {
    if (e.stream == TriadFeed::kAxis0 + 1) continue;  // axis y never arrives
    deliver(&feed, e);
    most_held = std::max(most_held, feed.held());
  }
  // Three fast streams of 200 Hz held for 1.5 s, and the fixture's records within it.
  EXPECT_LE(most_held, static_cast<std::size_t>(3 * 200 * 1.5 + 10));
  EXPECT_EQ(feed.counters(TriadFeed::kAxis0 + 1).received, 0u);
  const TriadOutcome o = feed.finish();
  EXPECT_FALSE(o.accepted);
  bool gate = false;
  for (const GateResult& g : o.gates) gate = gate || (g.name == "axis_y" && !g.passed);
  EXPECT_TRUE(gate);
  EXPECT_NE(o.reason.find("axis y"), std::string::npos) << o.reason;
  bool note = false;
  for (const std::string& n : o.notes) note = note || n.find("axis y: no wave sample was fed") != std::string::npos;
  EXPECT_TRUE(note);
  std::printf("axis y missing: %s\n", o.reason.c_str());
}

TEST(TriadFeedTest, BadRecordsAreDroppedAndCounted) {
  TriadFeedSettings settings;
  settings.hold = 0.5;
  TriadFeed feed = makeFeed(settings);
  FixtureRecord f;
  f.stamp = toNanoseconds(1.0);
  f.locked = true;
  f.body_to_table = Eigen::Quaterniond(1.0, 0.1, 0.0, 0.0);  // norm 1.005: not a rotation
  feed.addFixture(f);
  f.body_to_table = Eigen::Quaterniond(1.0005, 0.0, 0.0, 0.0);  // within 1e-3: a rotation, normalised
  feed.addFixture(f);
  f.body_to_table = Eigen::Quaterniond(NAN, 0.0, 0.0, 0.0);
  feed.addFixture(f);
  feed.addWave(0, toNanoseconds(1.0), NAN, NAN);
  feed.addWave(0, toNanoseconds(1.0), INFINITY, NAN);
  feed.addWave(1, 0, 0.1, NAN);  // zero stamp
  for (int k = 0; k < 400; ++k) {
    const Nanoseconds t = toNanoseconds(1.0 + 0.005 * k);
    feed.addTurntable(t, 0.0, 0.0, k);
    for (int i = 0; i < 3; ++i) feed.addWave(i, t, 0.1 * i, NAN);
  }
  // A record older than its stream's previous one (not far enough back to be a jump), and two whose
  // stamps jump: 1000 s ahead and 100 s back.
  feed.addWave(2, toNanoseconds(2.9), 0.2, NAN);
  feed.addTurntable(toNanoseconds(1002.0), 0.0, 0.0, 400);
  feed.addWave(1, toNanoseconds(1.0), 0.2, NAN);
  feed.addTurntable(toNanoseconds(3.0), 0.0, 0.0, 401);
  EXPECT_EQ(feed.counters(TriadFeed::kFixture).bad_value, 2u);
  EXPECT_EQ(feed.counters(TriadFeed::kFixture).fed, 1u);
  ASSERT_NE(feed.fixture(), nullptr);
  EXPECT_DOUBLE_EQ(feed.fixture()->body_to_table.norm(), 1.0);
  EXPECT_EQ(feed.counters(TriadFeed::kAxis0).bad_value, 2u);
  EXPECT_EQ(feed.counters(TriadFeed::kAxis0 + 1).bad_stamp, 1u);
  EXPECT_EQ(feed.counters(TriadFeed::kAxis0 + 2).out_of_order, 1u);
  EXPECT_EQ(feed.counters(TriadFeed::kTable).stamp_jump, 1u);
  EXPECT_EQ(feed.counters(TriadFeed::kAxis0 + 1).stamp_jump, 1u);
  EXPECT_EQ(feed.counters(TriadFeed::kTable).received, 402u);
  EXPECT_EQ(feed.counters(TriadFeed::kTable).last_stamp, toNanoseconds(3.0)) << "the table goes on after its glitch";
  EXPECT_EQ(feed.restarts(), 0u);
  const TriadOutcome o = feed.finish();  // too little for anything, but no crash and a named refusal
  EXPECT_FALSE(o.accepted);
  EXPECT_FALSE(o.reason.empty());
}

// The session with one glitch in about every `one_in[stream]` records of each stream, the kinds in
// turn: a stamp 1000 s ahead, 100 s back, two periods back, zero, the previous record's stamp, and a
// value that is no measurement (a NaN wave angle, a table rate of NaN, a fixture quaternion of norm
// 2). A stamp glitch is an extra record sent beside the good one of its instant (a stray, a buffered
// message); a value glitch replaces it.
std::vector<Event> glitched(const std::vector<Event>& events, const std::array<int, TriadFeed::kStreamCount>& one_in,
                            std::size_t* injected,
                            std::array<std::size_t, TriadFeed::kStreamCount>* per_stream = nullptr) {
  std::vector<Event> out;
  out.reserve(events.size() + events.size() / 100);
  std::array<Nanoseconds, TriadFeed::kStreamCount> previous{};
  std::array<int, TriadFeed::kStreamCount> kind{};
  std::uint64_t state = 12345;
  for (const Event& e : events) {
    state = state * 6364136223846793005ULL + 1442695040888963407ULL;
    if (previous[e.stream] > 0 && (state >> 33) % static_cast<std::uint64_t>(one_in[e.stream]) == 0) {
      Event g = e;
      g.sent = e.stamp;
      const int k = kind[e.stream]++ % 6;
      switch (k) {
        case 0:
          g.stamp += toNanoseconds(1000.0);
          break;
        case 1:
          g.stamp -= toNanoseconds(100.0);
          break;
        case 2:
          g.stamp = previous[e.stream] - 2 * (e.stamp - previous[e.stream]);
          break;
        case 3:
          g.stamp = 0;
          break;
        case 4:
          g.stamp = previous[e.stream];
          break;
        default:
          if (e.stream == TriadFeed::kFixture) {
            g.fixture.body_to_table.coeffs() *= 2.0;
          } else if (e.stream == TriadFeed::kTable) {
            g.b = NAN;
          } else {
            g.a = NAN;
          }
      }
      g.fixture.stamp = g.stamp;
      out.push_back(g);
      ++*injected;
      if (per_stream) ++(*per_stream)[e.stream];
      if (k == 5) {
        previous[e.stream] = e.stamp;
        continue;  // the value glitch took the good record's place
      }
    }
    out.push_back(e);
    previous[e.stream] = e.stamp;
  }
  return out;
}

void expectSameWithinSigmas(const TriadOutcome& clean, const TriadOutcome& o, double sigmas) {
  ASSERT_TRUE(o.accepted) << o.reason;
  double worst = 0.0;
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) {
      const double sigma = clean.body_to_axis_std(i, j);
      if (sigma > 0.0) worst = std::max(worst, std::abs(o.body_to_axis(i, j) - clean.body_to_axis(i, j)) / sigma);
    }
    const double k0 = clean.axes[i].scale_factor[0].mean, k0_std = clean.axes[i].scale_factor[0].mean_std;
    worst = std::max(worst, std::abs(o.axes[i].scale_factor[0].mean - k0) / k0_std);
    for (int j = 0; j < 3; ++j)
      worst = std::max(worst, std::abs(o.triad.bias(j) - clean.triad.bias(j)) / clean.triad.bias_std(j));
  }
  std::printf("[ measured ] glitched against clean: largest difference %.3f sigma (M, K0, bias)\n", worst);
  EXPECT_LE(worst, sigmas);
}

TEST(TriadFeedTest, OneGlitchedRecordOnAnyStreamCostsThatRecordOnly) {
  // About 20 glitches on each stream (the fixture logs once a second, the others at 200 Hz).
  std::size_t injected = 0;
  std::array<std::size_t, TriadFeed::kStreamCount> per_stream{};
  const std::vector<Event> events = glitched(session(), {{40, 8000, 8000, 8000, 8000}}, &injected, &per_stream);
  for (int s = 0; s < TriadFeed::kStreamCount; ++s) {
    std::printf("[ measured ] stream %d: %zu glitches injected\n", s, per_stream[s]);
  }
  EXPECT_GT(injected, 80u);
  TriadFeed clean = makeFeed();
  for (const Event& e : session()) deliver(&clean, e);
  const TriadOutcome reference = clean.finish();
  ASSERT_TRUE(reference.accepted) << reference.reason;

  // Live, the fixture and an axis late as in the field.
  TriadFeed feed = makeFeed();
  for (const Event& e : arrival(events, {{0.9, 0.05, 0.0, 0.3, 0.01}})) deliver(&feed, e);
  const TriadOutcome live = feed.finish();
  EXPECT_EQ(feed.restarts(), 0u);
  std::size_t dropped = 0;
  for (int s = 0; s < TriadFeed::kStreamCount; ++s) {
    const TriadStreamCounters& c = feed.counters(s);
    dropped += c.bad_stamp + c.bad_value + c.out_of_order + c.stamp_jump;
    EXPECT_GT(c.stamp_jump, 0u) << s;
    std::printf(
        "[ measured ] stream %d: %llu received, dropped: %llu zero stamp, %llu bad value, %llu out of order, %llu "
        "stamp jump\n",
        s, static_cast<unsigned long long>(c.received), static_cast<unsigned long long>(c.bad_stamp),
        static_cast<unsigned long long>(c.bad_value), static_cast<unsigned long long>(c.out_of_order),
        static_cast<unsigned long long>(c.stamp_jump));
  }
  // The table's NaN rates are the axis sessions' to count (they are values, not stamps).
  std::size_t nan_rates = 0;
  for (const Event& e : events) nan_rates += e.stream == TriadFeed::kTable && std::isnan(e.b) ? 1 : 0;
  EXPECT_GT(nan_rates, 0u);
  EXPECT_EQ(dropped + nan_rates, injected);
  expectSameWithinSigmas(reference, live, 0.05);

  // Offline: the records in stamp order straight into the calibration, as hrg_bag calibrate reads a bag.
  TriadCalibration direct = makeCalibration();
  for (const Event& e : events) {
    if (e.stream == TriadFeed::kFixture) direct.addFixture(e.fixture);
    if (e.stream == TriadFeed::kTable) direct.addTurntable(e.stamp, e.a, e.b, e.sequence);
    if (e.stream >= TriadFeed::kAxis0) direct.addWave(e.stream - TriadFeed::kAxis0, e.stamp, e.a, e.b);
  }
  const TriadOutcome offline = direct.finish();
  EXPECT_EQ(direct.restarts(), 0u);
  std::size_t offline_dropped = 0;
  for (int s = 0; s < kTriadStreamCount; ++s) {
    const TriadStreamRejects& r = direct.rejects(s);
    offline_dropped += r.total();
  }
  EXPECT_EQ(offline_dropped + nan_rates, injected);
  expectSameWithinSigmas(reference, offline, 0.05);
  bool noted = false;
  for (const std::string& n : offline.notes) noted = noted || n.find("fixture records dropped") != std::string::npos;
  EXPECT_TRUE(noted);
}

TEST(TriadFeedTest, AStreamThatGoesBackForGoodRestartsTheRun) {
  TriadFeedSettings settings;
  settings.hold = 0.5;
  TriadFeed feed = makeFeed(settings);
  // The first two positions' worth, twice (a bag played in a loop).
  const std::vector<Event>& all = session();
  const std::size_t part = all.size() / 3;
  for (int pass = 0; pass < 2; ++pass) {
    for (std::size_t k = 0; k < part; ++k) deliver(&feed, all[k]);
  }
  EXPECT_EQ(feed.restarts(), 1u);
  // After the restart the run knows only the second pass: the fixture from its records.
  ASSERT_NE(feed.fixture(), nullptr);
  EXPECT_TRUE(feed.axesAlongTable()[2]);
  EXPECT_LT(feed.duration(), toSeconds(all[part - 1].stamp - all[0].stamp) + 1e-9);
  EXPECT_GT(feed.duration(), toSeconds(all[part - 1].stamp - all[0].stamp) - 2.0);
}

/// Records held 0.5 s for stamp order; the run finishes by itself after `idle` s with the fixture released.
TriadFeedSettings autoFinishing(double idle) {
  TriadFeedSettings s;
  s.hold = 0.5;
  s.auto_finish_idle = idle;
  return s;
}

TEST(TriadFeedTest, AutoFinishOnceEveryAxisWasAlongTheTableAndTheFixtureStaysReleased) {
  const TriadFeedSettings settings = autoFinishing(10.0);
  TriadFeed feed = makeFeed(settings);
  const std::vector<Event>& all = session();
  for (const Event& e : all) {
    deliver(&feed, e);
    // Released between positions, but not every axis has been along the table axis yet.
    if (!(feed.axesAlongTable()[0] && feed.axesAlongTable()[1])) ASSERT_FALSE(feed.shouldFinish());
  }
  EXPECT_FALSE(feed.shouldFinish());  // the last position is still locked
  // The operator releases the fixture; the table keeps logging at rest.
  FixtureRecord released = *feed.fixture();
  released.locked = false;
  const Nanoseconds end = all.back().stamp;
  released.stamp = end + toNanoseconds(0.005);
  feed.addFixture(released);
  bool finished_at_idle = false;
  for (int k = 1; k <= 3000; ++k) {
    const Nanoseconds t = end + toNanoseconds(0.005 * k);
    feed.addTurntable(t, 0.0, 0.0, 1000000 + k);
    for (int i = 0; i < 3; ++i) feed.addWave(i, t, 0.0, NAN);
    if (feed.shouldFinish()) {
      // The idle time is counted on the records fed, which trail the newest by the hold.
      const double idle = toSeconds(t - released.stamp);
      EXPECT_GE(idle, settings.auto_finish_idle);
      EXPECT_LE(idle, settings.auto_finish_idle + settings.hold + 0.05);
      finished_at_idle = true;
      break;
    }
  }
  EXPECT_TRUE(finished_at_idle);
}

TEST(TriadFeedTest, NoAutoFinishWhileAnAxisWasNeverAlongTheTable) {
  TriadFeed feed = makeFeed(autoFinishing(1.0));
  // Only +z and -z: x and y never along the table axis, although the fixture is released between.
  const std::size_t part = session().size() / 3;
  for (std::size_t k = 0; k < part; ++k) ASSERT_FALSE((deliver(&feed, session()[k]), feed.shouldFinish())) << k;
  EXPECT_GE(feed.lockedPositions(), 2u);
  EXPECT_FALSE(feed.axesAlongTable()[0]);
}

}  // namespace
}  // namespace core
}  // namespace hrg_gyro

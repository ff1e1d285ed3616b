// The plateau detector on streams a table controller logs, built here from an exact piecewise profile:
// encoder noise with the rate differenced at the log rate, drive ripple, rate-only streams, gaps; real
// rate changes (ramps at 0.5 rad/s^2, the step method's moves) found within half a smoothing span.
#include "hrg_gyro/core/estimation/plateau_detector.h"

#include <gtest/gtest.h>

#include <cstdio>
#include <random>
#include <set>
#include <vector>

namespace hrg_gyro {
namespace core {
namespace {

// A table profile: pieces of constant acceleration, exact angle and rate at any time.
struct Piece {
  double duration, rate0, acceleration;
};

struct Profile {
  std::vector<Piece> pieces;
  double end() const {
    double t = 0.0;
    for (const Piece& p : pieces) t += p.duration;
    return t;
  }
  void at(double t, double* angle, double* rate) const {
    double t0 = 0.0, a = 0.0;
    *rate = 0.0;
    for (const Piece& p : pieces) {
      const double u = std::min(t - t0, p.duration);
      if (u <= 0.0) break;
      *rate = p.rate0 + p.acceleration * u;
      a += p.rate0 * u + 0.5 * p.acceleration * u * u;
      t0 += p.duration;
    }
    *angle = a;
  }
  /// Adds a ramp at `acceleration` from the last rate to `rate`, then `hold` s at it.
  Profile& to(double rate, double hold, double acceleration = 0.5) {
    const double from =
        pieces.empty() ? 0.0 : pieces.back().rate0 + pieces.back().acceleration * pieces.back().duration;
    if (rate != from)
      pieces.push_back({std::abs(rate - from) / acceleration, from, rate > from ? acceleration : -acceleration});
    pieces.push_back({hold, rate, 0.0});
    return *this;
  }
};

struct Logging {
  double log_hz = 100.0;
  double encoder_noise = 0.0;     ///< rad, white, on the logged angle
  bool differenced_rate = false;  ///< the reported rate is the logged angle differenced at the log rate
  bool log_angle = true;          ///< false: the angle field is NaN
  double ripple = 0.0;            ///< relative amplitude of a rate ripple
  double ripple_hz = 0.37;
};

struct Logged {
  Nanoseconds stamp;
  double true_angle, true_rate, angle, rate;
};

std::vector<Logged> logStream(const Profile& p, const Logging& l, std::uint64_t seed = 3) {
  std::mt19937_64 random(seed);
  std::normal_distribution<double> normal;
  std::vector<Logged> out;
  double previous_logged = NAN;
  const double h = 1.0 / l.log_hz;
  for (long i = 0; i * h < p.end(); ++i) {
    const double t = i * h;
    double angle, rate;
    p.at(t, &angle, &rate);
    // Ripple of the drive: rate w (1 + r sin(2 pi f t)), the angle its integral.
    const double w = 2.0 * kPi * l.ripple_hz;
    angle += l.ripple * rate * (1.0 - std::cos(w * t)) / w;
    rate += l.ripple * rate * std::sin(w * t);
    const double logged = angle + l.encoder_noise * normal(random);
    const double reported = l.differenced_rate ? (i == 0 ? 0.0 : (logged - previous_logged) / h) : rate;
    previous_logged = logged;
    out.push_back({toNanoseconds(10.0 + t), angle, rate, l.log_angle ? logged : NAN, reported});
  }
  return out;
}

std::vector<PlateauRecord> detect(const std::vector<Logged>& stream, const PlateauSettings& s,
                                  PlateauDetector* detector = nullptr) {
  PlateauDetector local(s);
  PlateauDetector& d = detector ? *detector : local;
  std::vector<PlateauRecord> out;
  for (const Logged& r : stream) d.add(r.stamp, r.angle, r.rate, &out);
  d.flush(&out);
  return out;
}

// The two-plateau profile of the dual-rate method.
Profile dualRate() {
  Profile p;
  p.to(0.0, 5.0).to(0.05, 60.0).to(-0.05, 60.0).to(0.0, 10.0);
  return p;
}

// Plateau ids of the records between from and to (s of the profile).
std::set<std::uint64_t> idsBetween(const std::vector<PlateauRecord>& records, double from, double to) {
  std::set<std::uint64_t> ids;
  for (const PlateauRecord& r : records) {
    const double t = toSeconds(r.stamp) - 10.0;
    if (t >= from && t <= to) ids.insert(r.plateau.id);
  }
  return ids;
}

TEST(PlateauDetectorTest, RecordsComeBackInOrderHalfASpanLate) {
  PlateauSettings s;
  s.smoothing_span = 1.0;
  PlateauDetector d(s);
  std::vector<PlateauRecord> out;
  for (int i = 0; i < 300; ++i) {
    d.add(toNanoseconds(1.0 + i * 0.01), 0.05 * i * 0.01, 0.05, &out);
    // Judged once the stream has passed it by half the span (0.5 s = 50 records).
    EXPECT_EQ(out.size(), static_cast<std::size_t>(std::max(0, i - 49))) << i;
  }
  d.flush(&out);
  ASSERT_EQ(out.size(), 300u);
  for (std::size_t i = 0; i < out.size(); ++i) EXPECT_EQ(out[i].stamp, toNanoseconds(1.0 + i * 0.01));
  EXPECT_EQ(out.back().plateau.id, 1u);
  EXPECT_NEAR(out.back().plateau.rate, 0.05, 1e-12);
  EXPECT_TRUE(out.back().angle_logged);
}

TEST(PlateauDetectorTest, ZeroSpanJudgesEachReportedRateAtOnce) {
  PlateauSettings s;
  s.smoothing_span = 0.0;
  PlateauDetector d(s);
  std::vector<PlateauRecord> out;
  d.add(toNanoseconds(1.0), NAN, 0.05, &out);
  ASSERT_EQ(out.size(), 1u);
  d.add(toNanoseconds(1.01), NAN, 0.0505, &out);  // 5e-4 from the mean: beyond 2e-4 + 1e-4
  ASSERT_EQ(out.size(), 2u);
  EXPECT_EQ(out[1].plateau.id, 2u);
  EXPECT_DOUBLE_EQ(out[1].judged_rate, 0.0505);
}

TEST(PlateauDetectorTest, EncoderNoiseAndRippleDoNotBreakAPlateau) {
  // 2 urad of encoder noise at 100 Hz, the rate logged as the angle differenced (~0.57 % of scatter
  // at 0.05 rad/s), and a drive ripple of 0.2 % at 0.37 Hz.
  Logging l;
  l.encoder_noise = 2e-6;
  l.differenced_rate = true;
  for (double ripple : {0.0, 2e-3}) {
    l.ripple = ripple;
    const auto stream = logStream(dualRate(), l);
    for (bool log_angle : {true, false}) {
      std::vector<Logged> s = stream;
      if (!log_angle) {
        for (Logged& r : s) r.angle = NAN;
      }
      PlateauDetector d{PlateauSettings()};
      const auto records = detect(s, PlateauSettings(), &d);
      // Ramps end at 5.1 s and 65.3 s: every record from 0.6 s after a ramp to 0.6 s before the next
      // is on one plateau.
      EXPECT_EQ(idsBetween(records, 5.7, 64.5).size(), 1u) << "angle logged: " << log_angle;
      EXPECT_EQ(idsBetween(records, 65.9, 124.6).size(), 1u) << "angle logged: " << log_angle;
      const PlateauStatistics st = d.statistics();
      std::printf(
          "[ measured ] ripple %.2g %%, angle logged %d: %llu plateaus, reported rate scatter %.3g %%, judged "
          "%.3g %% (%.3g of the tolerance)\n",
          100 * ripple, log_angle, static_cast<unsigned long long>(st.plateaus), 100 * st.reported_scatter,
          100 * st.judged_scatter, st.noise_to_tolerance);
      EXPECT_EQ(d.angleLogged(), log_angle);
      if (ripple == 0.0) {
        EXPECT_LT(st.noise_to_tolerance, 0.1);
      } else {
        // The judged rate does see the ripple: its rms through a centred 1 s mean, sin(x) / x with
        // x = pi 0.37 Hz 1 s, is 0.2 % 0.790 / sqrt(2) = 0.112 %.
        EXPECT_NEAR(st.judged_scatter, ripple * 0.7896 / std::sqrt(2.0), 1e-4);
      }
    }
  }
  const auto stream = logStream(dualRate(), l);
  // Judged record by record (span 0), the same stream breaks its plateaus over and over.
  PlateauSettings raw;
  raw.smoothing_span = 0.0;
  PlateauDetector d(raw);
  const auto records = detect(stream, raw, &d);
  const auto ids = idsBetween(records, 5.7, 64.5);
  const PlateauStatistics st = d.statistics();
  std::printf("[ measured ] judged record by record: %zu plateaus in the first 59 s, %llu of %llu breaks spurious\n",
              ids.size(), static_cast<unsigned long long>(st.spurious_breaks),
              static_cast<unsigned long long>(st.breaks));
  EXPECT_GT(ids.size(), 20u);
  EXPECT_GT(st.spurious_breaks, st.breaks / 4);
  // Its measured scatter is the injected one: sqrt(2) 2 urad / 10 ms / 0.05 rad/s = 0.57 %.
  EXPECT_NEAR(d.statistics().reported_scatter, std::sqrt(2.0) * 2e-6 / 0.01 / 0.05, 0.1 * 0.0057);
}

TEST(PlateauDetectorTest, ThePlateauRateIsTheAngleSlope) {
  Logging l;
  l.encoder_noise = 2e-6;
  l.differenced_rate = true;
  const auto records = detect(logStream(dualRate(), l), PlateauSettings());
  // The last record of each plateau: its rate from 59 s of angle.
  for (double t_end : {64.5, 124.7}) {
    const PlateauRecord* last = nullptr;
    for (const PlateauRecord& r : records) {
      if (toSeconds(r.stamp) - 10.0 <= t_end) last = &r;
    }
    ASSERT_NE(last, nullptr);
    const double truth = t_end < 100 ? 0.05 : -0.05;
    std::printf("[ measured ] plateau rate error %.3g rad/s\n", last->plateau.rate - truth);
    EXPECT_NEAR(last->plateau.rate, truth, 1e-7);
    EXPECT_TRUE(last->plateau.settled);
  }
}

// Records of a settled plateau whose table was not at that plateau's rate: none, for ramps and
// step moves; the delay from the end of a move to the plateau's start stays within half a span.
void expectMovesFoundPromptly(const Profile& p, const Logging& l, double* worst_delay) {
  const PlateauSettings s;
  const auto stream = logStream(p, l);
  const auto records = detect(stream, s);
  ASSERT_EQ(records.size(), stream.size());
  for (std::size_t i = 0; i < records.size(); ++i) {
    const PlateauRecord& r = records[i];
    const double true_rate = stream[i].true_rate;
    if (r.plateau.settled) {
      EXPECT_NEAR(true_rate, r.plateau.rate, 1e-4 * (1.0 + std::abs(true_rate))) << "t = " << toSeconds(r.stamp);
    }
  }
  // Each hold: the plateau covering its middle starts within half a span (+ one record) after it began.
  double t0 = 0.0;
  for (const Piece& piece : p.pieces) {
    if (piece.acceleration == 0.0 && piece.duration > 3.0) {
      const double middle = t0 + 0.5 * piece.duration;
      for (const PlateauRecord& r : records) {
        if (toSeconds(r.stamp) - 10.0 >= middle) {
          const double delay = toSeconds(r.plateau.start) - 10.0 - t0;
          if (t0 > 0.0) {
            EXPECT_GE(delay, 0.0);
            EXPECT_LE(delay, 0.5 * s.smoothing_span + 0.02);
            *worst_delay = std::max(*worst_delay, delay);
          }
          break;
        }
      }
    }
    t0 += piece.duration;
  }
}

TEST(PlateauDetectorTest, RampsAndStepMovesAreFoundWithinHalfASpan) {
  Logging l;
  l.encoder_noise = 2e-6;
  double worst = 0.0;
  expectMovesFoundPromptly(dualRate(), l, &worst);
  // The step method: rests of 8 s between moves of 0.3 rad at 0.3 rad/s, accelerating at 0.5 rad/s^2.
  Profile steps;
  steps.to(0.0, 8.0);
  for (int i = 0; i < 6; ++i) steps.to(0.3, 0.4).to(0.0, 8.0);
  expectMovesFoundPromptly(steps, l, &worst);
  l.differenced_rate = true;
  l.log_angle = false;
  expectMovesFoundPromptly(steps, l, &worst);
  std::printf("[ measured ] longest delay from the end of a move to its plateau's start: %.3f s\n", worst);
}

TEST(PlateauDetectorTest, RateOnlyStreamIntegratesTheReportedRate) {
  Logging l;
  l.log_angle = false;
  // The ramps start and end between two records (3.7 ms after one).
  Profile p;
  p.to(0.0, 5.0037).to(0.05, 60.0).to(-0.05, 60.0).to(0.0, 10.0);
  const auto stream = logStream(p, l);
  PlateauDetector d{PlateauSettings()};
  const auto records = detect(stream, PlateauSettings(), &d);
  EXPECT_FALSE(d.angleLogged());
  double worst = 0.0;
  for (std::size_t i = 0; i < records.size(); ++i) {
    EXPECT_FALSE(records[i].angle_logged);
    worst = std::max(worst, std::abs(records[i].angle - stream[i].true_angle));
  }
  // Trapezoids over 10 ms across a change of acceleration (0.5 rad/s^2) miss up to a h^2 / 8 each.
  std::printf("[ measured ] rate-only stream: integral of the rate within %.3g rad of the table angle\n", worst);
  EXPECT_LT(worst, 2e-5);
  // The first logged angle makes it an angle-logging stream: a new plateau from there.
  std::vector<PlateauRecord> out;
  d.add(stream.back().stamp + toNanoseconds(0.01), 3.0, 0.0, &out);
  d.flush(&out);
  ASSERT_FALSE(out.empty());
  EXPECT_TRUE(d.angleLogged());
  EXPECT_TRUE(out.back().angle_logged);
  EXPECT_DOUBLE_EQ(out.back().angle, 3.0);
  EXPECT_NE(out.back().plateau.id, records.back().plateau.id);
}

TEST(PlateauDetectorTest, AGapStartsANewPlateau) {
  PlateauDetector d{PlateauSettings()};
  std::vector<PlateauRecord> out;
  for (int i = 0; i < 400; ++i) {
    const double t = 1.0 + i * 0.01 + (i >= 200 ? 1.0 : 0.0);  // 1 s gap before record 200
    d.add(toNanoseconds(t), 0.05 * t, 0.05, &out);
  }
  d.flush(&out);
  ASSERT_EQ(out.size(), 400u);
  EXPECT_EQ(out[199].plateau.id, out[0].plateau.id);
  EXPECT_NE(out[200].plateau.id, out[199].plateau.id);
  EXPECT_EQ(out[200].plateau.start, out[200].stamp);
  EXPECT_EQ(out[399].plateau.id, out[200].plateau.id);
}

TEST(PlateauDetectorTest, CausalUpdateJudgesExactRates) {
  PlateauSettings s;
  s.settle_time = 1.0;
  PlateauDetector d(s);
  PlateauState st;
  for (int i = 0; i < 200; ++i) st = d.update(toNanoseconds(1.0 + i * 0.01), 0.1);
  EXPECT_TRUE(st.settled);
  EXPECT_NEAR(st.rate, 0.1, 1e-12);
  st = d.update(toNanoseconds(3.0), 0.2);
  EXPECT_FALSE(st.settled);
  EXPECT_EQ(st.id, 2u);
}

}  // namespace
}  // namespace core
}  // namespace hrg_gyro

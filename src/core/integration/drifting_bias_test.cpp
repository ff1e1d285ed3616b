// The dual-rate calibration on sessions whose bias wanders (a gyro warming up on the table, a lab
// whose temperature drifts), against the exact injected model: a linear trend of D0 by 1e-6 rad/s
// over a 16-minute session, in the plateau order + - + - that lets a constant-bias fit mistake part
// of it for K0, and in the order + - - + that cancels it; a random walk of the bias; and a session
// that cannot tell a trend from K0, refused with the cause named.
#include <gtest/gtest.h>

#include <cstdio>
#include <string>
#include <vector>

#include "core/testing/angle_level_session.h"

namespace hrg_gyro {
namespace core {
namespace {

using testing::AngleLevelGyro;
using testing::nominalGyro;
using testing::referencePrior;
using testing::TableImperfections;

constexpr double kPlateau = 226.0;  // s: four plateaus and their ramps make a 16-minute session

CalibrationSettings settings(int trend_order) {
  CalibrationSettings s;
  s.method = CalibrationMethodKind::kDualRate;
  s.bias_trend_order = trend_order;
  return s;
}

/// The trend that moves D0 by `change` rad/s over the profile.
double trendFor(const TurntableProfile& profile, double change) { return change / profile.duration(); }

struct SessionResult {
  CalibrationOutcome outcome;
  double k_peak_ppm = 0.0;
  double k0_error_ppm = 0.0;
  double d0_error = 0.0;  ///< rad/s, against the injected bias at the reference time
};

SessionResult calibrate(const AngleLevelGyro& g, const TurntableProfile& profile, int trend_order) {
  SessionResult r;
  r.outcome = testing::calibrateTableSession(g, TableImperfections(), profile, settings(trend_order), referencePrior());
  if (r.outcome.scale_factor.empty() || !r.outcome.scale_factor[0].ok) return r;
  const HarmonicModel k = toModel(r.outcome.scale_factor[0]);
  r.k_peak_ppm = testing::peakErrorPpm(k, g.k);
  r.k0_error_ppm = 1e6 * (k.meanAt(NAN) - g.k.meanAt(NAN)) / std::abs(g.k.meanAt(NAN));
  // The written D0 is the bias at the reference time (session stamps start at 1 s).
  const double t_ref = r.outcome.bias_trend.order > 0 ? toSeconds(r.outcome.bias_trend.reference_stamp) - 1.0 : 0.0;
  r.d0_error = r.outcome.drift[0].mean - (g.d.meanAt(NAN) + testing::biasTrendAt(g, t_ref));
  return r;
}

/// The gyro of `seed` whose D0 moves by 1e-6 rad/s over the profile, calibrated with a constant bias
/// and with a linear trend.
struct TrendComparison {
  AngleLevelGyro gyro;
  SessionResult constant, fitted;
};

TrendComparison calibrateWithAndWithoutTrend(const TurntableProfile& profile, std::uint64_t seed) {
  TrendComparison c;
  c.gyro = nominalGyro(seed);
  c.gyro.bias_trend = trendFor(profile, 1e-6);
  c.constant = calibrate(c.gyro, profile, 0);
  c.fitted = calibrate(c.gyro, profile, 1);
  return c;
}

TEST(DriftingBiasTest, ALinearTrendIsFittedWithKInTheOrderThatWouldAliasIt) {
  const TurntableProfile alternating = testing::dualRateProfile(0.05, -0.05, kPlateau, 2);
  const TrendComparison run = calibrateWithAndWithoutTrend(alternating, 11);
  const AngleLevelGyro& g = run.gyro;
  const SessionResult &constant = run.constant, &fitted = run.fitted;
  std::printf(
      "alternating + - + -, D0 trend 1e-6 rad/s over %.0f s: constant-bias fit K0 %+.2f ppm, peak %.2f ppm; "
      "trend fitted K0 %+.2f ppm, peak %.2f ppm, trend %.3e +- %.1e rad/s^2 (injected %.3e), K0 sigma x%.2f, "
      "correlation %.2f\n",
      alternating.duration(), constant.k0_error_ppm, constant.k_peak_ppm, fitted.k0_error_ppm, fitted.k_peak_ppm,
      fitted.outcome.bias_trend.coefficients[0], fitted.outcome.bias_trend.stds[0], g.bias_trend,
      fitted.outcome.bias_trend.k0_inflation, fitted.outcome.bias_trend.k0_correlation);
  // A constant-bias fit takes part of the trend for K0 (the plateaus' rate signs correlate with time).
  EXPECT_GT(std::abs(constant.k0_error_ppm), 2.0);
  ASSERT_TRUE(fitted.outcome.accepted) << fitted.outcome.reason;
  EXPECT_LE(fitted.k_peak_ppm, 1.0);
  EXPECT_LE(std::abs(fitted.k0_error_ppm), 3.0 * 1e6 * fitted.outcome.scale_factor[0].mean_std / 0.56);
  const BiasTrendFit& t = fitted.outcome.bias_trend;
  EXPECT_NEAR(t.coefficients[0], g.bias_trend, 3.0 * t.stds[0]);
  EXPECT_NEAR(fitted.outcome.drift[0].mean, g.d.meanAt(NAN) + g.bias_trend * (toSeconds(t.reference_stamp) - 1.0),
              3.0 * fitted.outcome.drift[0].mean_std);
}

TEST(DriftingBiasTest, TheBalancedOrderCancelsTheTrendEvenUnfitted) {
  const TurntableProfile balanced = testing::balancedDualRateProfile(0.05, -0.05, kPlateau, 4);
  const TrendComparison run = calibrateWithAndWithoutTrend(balanced, 12);
  const SessionResult &constant = run.constant, &fitted = run.fitted;
  std::printf(
      "balanced + - - +, same trend: constant-bias fit K0 %+.2f ppm, peak %.2f ppm; trend fitted K0 %+.2f "
      "ppm, peak %.2f ppm, K0 sigma x%.2f\n",
      constant.k0_error_ppm, constant.k_peak_ppm, fitted.k0_error_ppm, fitted.k_peak_ppm,
      fitted.outcome.bias_trend.k0_inflation);
  ASSERT_TRUE(constant.outcome.accepted) << constant.outcome.reason;
  ASSERT_TRUE(fitted.outcome.accepted) << fitted.outcome.reason;
  // K0 is freed of the trend by the order alone; the harmonics are not (within each plateau the
  // trend still correlates with the slowly swept cos k theta): only the fitted trend frees them.
  EXPECT_LE(std::abs(constant.k0_error_ppm), 0.5);
  EXPECT_GT(constant.k_peak_ppm, 1.0);
  EXPECT_LE(fitted.k_peak_ppm, 1.0);
  // The order that cancels the trend also keeps it apart from K0 when it is fitted.
  EXPECT_LT(fitted.outcome.bias_trend.k0_inflation, 1.2);
}

/// Share of the K coefficients (K0 and every harmonic), the D0 at the reference time and the trend
/// within 3 reported sigmas over `seeds` sessions, and the largest peak K error.
struct Coverage {
  int within = 0, total = 0;
  double worst_peak_ppm = 0.0;
  double share() const { return static_cast<double>(within) / total; }
};

/// count(error, sigma) for K0 and every fitted K harmonic against the injected K (which has the
/// fitted orders, in the same order).
template <typename Count>
void forEachKCoefficient(const HarmonicFitResult& k, const AngleLevelGyro& g, Count count) {
  count(k.mean - g.k.meanAt(NAN), k.mean_std);
  double truth[64];
  g.k.coefficientsAt(NAN, truth);
  const std::size_t n = g.k.orders().size();
  for (std::size_t j = 0; j < k.orders.size(); ++j) {
    count(k.cos[j] - truth[1 + j], k.cos_std[j]);
    count(k.sin[j] - truth[1 + n + j], k.sin_std[j]);
  }
}

Coverage coverage(AngleLevelGyro g, const TurntableProfile& profile, int seeds, bool count_bias = true) {
  Coverage c;
  for (int seed = 1; seed <= seeds; ++seed) {
    g.seed = 1000 + seed;
    const SessionResult r = calibrate(g, profile, 1);
    EXPECT_TRUE(r.outcome.accepted) << r.outcome.reason;
    if (!r.outcome.accepted) continue;
    const HarmonicFitResult& k = r.outcome.scale_factor[0];
    auto count = [&](double error, double sigma) {
      ++c.total;
      if (std::abs(error) <= 3.0 * sigma) ++c.within;
    };
    forEachKCoefficient(k, g, count);
    if (count_bias) {
      count(r.d0_error, r.outcome.drift[0].mean_std);
      count(r.outcome.bias_trend.coefficients[0] - g.bias_trend, r.outcome.bias_trend.stds[0]);
    }
    c.worst_peak_ppm = std::max(c.worst_peak_ppm, r.k_peak_ppm);
  }
  return c;
}

TEST(DriftingBiasTest, ReportedSigmasCoverTheErrorOver20Seeds) {
  const TurntableProfile alternating = testing::dualRateProfile(0.05, -0.05, 150.0, 2);
  AngleLevelGyro trend = nominalGyro(0);
  trend.bias_trend = trendFor(alternating, 1e-6);
  const Coverage c = coverage(trend, alternating, 20);
  std::printf("linear trend, + - + -, 20 seeds: %d of %d coefficients within 3 sigma (%.1f %%), worst peak %.2f ppm\n",
              c.within, c.total, 100.0 * c.share(), c.worst_peak_ppm);
  EXPECT_GE(c.share(), 0.95);
  EXPECT_LE(c.worst_peak_ppm, 1.0);
}

TEST(DriftingBiasTest, ARandomWalkOfTheBiasWidensTheSigmasHonestly) {
  // A random walk that moves D0 by about 3e-7 rad/s over the session (1.2e-8 rad/s/sqrt(s), far
  // beyond a navigation-grade gyro's): no polynomial follows it, so what the trend leaves is
  // correlated residual, which the block sandwich and the estimated walk (below) carry. K's
  // coefficients are counted (D0 and a trend are not defined for a random walk). Measured here: 100 %,
  // worst peak 3.95 ppm (97.2 % with the sandwich alone).
  const TurntableProfile alternating = testing::dualRateProfile(0.05, -0.05, 150.0, 2);
  AngleLevelGyro walk = nominalGyro(0);
  walk.bias_random_walk = 3e-7 / std::sqrt(alternating.duration());
  const Coverage c = coverage(walk, alternating, 20, false);
  std::printf(
      "bias random walk %.2e rad/s/sqrt(s), 20 seeds: %d of %d K coefficients within 3 sigma (%.1f %%), "
      "worst peak %.2f ppm\n",
      walk.bias_random_walk, c.within, c.total, 100.0 * c.share(), c.worst_peak_ppm);
  EXPECT_GE(c.share(), 0.95);
}

/// K's coefficients (K0 and every harmonic) within 2 reported sigmas over `seeds` sessions, and the
/// bias walk estimated in each.
struct WalkCoverage {
  int within = 0, total = 0, carried = 0, sessions = 0;
  double worst_ratio = 0.0;              ///< largest |error| / sigma
  double q_min = INFINITY, q_max = 0.0;  ///< estimated rate random walk, rad/s/sqrt(s)
  double worst_q_z = 0.0;                ///< largest |q estimate - injected| / its standard error
  double worst_peak_ppm = 0.0, largest_sigma_ppm = 0.0;
  double share() const { return static_cast<double>(within) / total; }
};

WalkCoverage walkCoverage(AngleLevelGyro g, const TurntableProfile& profile, int seeds) {
  WalkCoverage c;
  for (int seed = 1; seed <= seeds; ++seed) {
    g.seed = 2000 + seed;
    const SessionResult r = calibrate(g, profile, 1);
    EXPECT_TRUE(r.outcome.accepted) << r.outcome.reason;
    if (!r.outcome.accepted) continue;
    ++c.sessions;
    const HarmonicFitResult& k = r.outcome.scale_factor[0];
    auto count = [&](double error, double sigma) {
      ++c.total;
      if (std::abs(error) <= 2.0 * sigma) ++c.within;
      c.worst_ratio = std::max(c.worst_ratio, std::abs(error) / sigma);
      c.largest_sigma_ppm = std::max(c.largest_sigma_ppm, 1e6 * sigma / std::abs(k.mean));
    };
    forEachKCoefficient(k, g, count);
    const BiasWalkFit& w = r.outcome.bias_walk;
    if (w.carried) ++c.carried;
    c.q_min = std::min(c.q_min, w.rate_random_walk);
    c.q_max = std::max(c.q_max, w.rate_random_walk);
    if (w.rate_random_walk_std > 0.0)
      c.worst_q_z = std::max(c.worst_q_z, std::abs(w.rate_random_walk - g.bias_random_walk) / w.rate_random_walk_std);
    c.worst_peak_ppm = std::max(c.worst_peak_ppm, r.k_peak_ppm);
  }
  return c;
}

void printWalkCoverage(const char* what, const AngleLevelGyro& g, const WalkCoverage& c) {
  std::printf(
      "%s, bias random walk %.2e rad/s/sqrt(s), %d seeds: %d of %d K coefficients within 2 sigma (%.1f %%), "
      "largest |error|/sigma %.2f, largest sigma %.2f ppm, worst peak %.2f ppm; walk carried in %d, estimated "
      "%.2e..%.2e rad/s/sqrt(s) (largest |error|/std %.2f)\n",
      what, g.bias_random_walk, c.sessions, c.within, c.total, 100.0 * c.share(), c.worst_ratio, c.largest_sigma_ppm,
      c.worst_peak_ppm, c.carried, c.q_min, c.q_max, c.worst_q_z);
}

TEST(DriftingBiasTest, AStrongRandomWalkIsEstimatedAndCarriedInTheSigmas) {
  // The bias walks by about 1e-6 rad/s over the session (4e-8 rad/s/sqrt(s)): the increments' errors
  // are correlated over the whole session, which the block sandwich alone understates (83.9 % of K's
  // coefficients within 3 sigmas, worst peak 14.2 ppm, before the walk was estimated). The walk is estimated from the
  // residuals and carried in the covariance: measured 97.8 % within 2 sigmas, worst 3.1, the walk found in every
  // session (5.3e-9 to 5.4e-8 against 4.0e-8 rad/s/sqrt(s) injected).
  const TurntableProfile alternating = testing::dualRateProfile(0.05, -0.05, 150.0, 2);
  AngleLevelGyro walk = nominalGyro(0);
  walk.bias_random_walk = 1e-6 / std::sqrt(alternating.duration());
  const WalkCoverage c = walkCoverage(walk, alternating, 20);
  printWalkCoverage("+ - + -", walk, c);
  EXPECT_GE(c.share(), 0.92);
  EXPECT_GE(c.carried, c.sessions - 1);
  EXPECT_LE(c.worst_q_z, 5.0);
}

TEST(DriftingBiasTest, WithoutAWalkNoneWorthTheNameIsFound) {
  // The same sessions with a constant bias: the estimate is zero or far below the strong walk's (it
  // enters a coefficient's variance only where it exceeds the sandwich), and the sigmas still cover
  // the errors. Measured: a walk in 1 session of 20, 4.2e-10 rad/s/sqrt(s), 1 % of the strong one.
  const TurntableProfile alternating = testing::dualRateProfile(0.05, -0.05, 150.0, 2);
  const AngleLevelGyro steady = nominalGyro(0);
  const WalkCoverage c = walkCoverage(steady, alternating, 20);
  printWalkCoverage("+ - + -", steady, c);
  EXPECT_LE(c.carried, 2);
  EXPECT_LT(c.q_max, 1e-9);
  EXPECT_GE(c.share(), 0.92);
}

TEST(DriftingBiasTest, ATrendTheSessionCannotSeparateIsRefusedNamingTheOrder) {
  // + then -, two minutes each: the trend is told from K0 only by the curvature it gives each
  // plateau, which multiplies K0's standard error more than three times. With the nominal noise K0
  // stays known to about a ppm and the session is accepted; with three times the noise it would be
  // left at several ppm: refused.
  const TurntableProfile two = testing::dualRateProfile(0.05, -0.05, 120.0, 1);
  AngleLevelGyro g = nominalGyro(13);
  g.k = HarmonicModel({2, 4}, -0.56, {-6e-4, 2e-3}, {4e-4, 0.0});
  g.bias_trend = trendFor(two, 1e-6);
  CalibrationSettings s = settings(1);
  s.scale_factor_orders = {2, 4};
  s.drift_orders = {2};
  const CalibrationOutcome quiet = testing::calibrateTableSession(g, TableImperfections(), two, s, referencePrior());
  EXPECT_TRUE(quiet.accepted) << quiet.reason;
  g.noise = 3.0 * testing::kNominalNoise;
  const CalibrationOutcome o = testing::calibrateTableSession(g, TableImperfections(), two, s, referencePrior());
  std::printf("+ - at 3x noise: K0 sigma x%.2f, correlation %.2f: %s\n", o.bias_trend.k0_inflation,
              o.bias_trend.k0_correlation, o.reason.c_str());
  EXPECT_FALSE(o.accepted);
  EXPECT_EQ(o.reason.rfind("bias_trend: the session cannot separate a bias trend from K0", 0), 0u) << o.reason;
  EXPECT_NE(o.reason.find("+ - - +"), std::string::npos) << o.reason;
  EXPECT_GT(o.bias_trend.k0_inflation, 3.0);
  // Without the trend the same session is accepted: a user who knows the bias is stable says so.
  s.bias_trend_order = 0;
  const CalibrationOutcome stable = testing::calibrateTableSession(g, TableImperfections(), two, s, referencePrior());
  EXPECT_TRUE(stable.accepted) << stable.reason;
}

}  // namespace
}  // namespace core
}  // namespace hrg_gyro

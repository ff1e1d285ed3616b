// A real table session's imperfections, each on its own, through the whole offline chain the tools
// use (simulator -> processor -> calibration session fed with what the controller logged), compared
// with the exact injected model (computeEffectiveModel): the peak residual nonlinearity the
// calibrated K leaves must stay <= 1 ppm of |K0| at the shipped gyro's noise. Each test prints the
// measured residual, the K0 error and the reported standard errors.
//
// The sessions are short (eight sweeps of the wave angle per direction at +-0.4 rad/s, 450 s of
// plateaus) so that each runs in seconds. Their measured figures are in docs/simulation.md.
#include <gtest/gtest.h>

#include <cstdio>

#include "core/testing/model_errors.h"
#include "hrg_gyro/core/estimation/harmonic_fit.h"
#include "hrg_gyro/core/evaluation/offline_pipeline.h"
#include "hrg_gyro/core/model/parameter_file.h"
#include "hrg_gyro/core/simulation/injected_model.h"

namespace hrg_gyro {
namespace core {
namespace {

/// The shipped gyro (dual_rate.yaml) on a short dual-rate profile at +-rate rad/s, rate changes at
/// `acceleration` rad/s^2: each plateau sweeps the wave angle by 2 pi, `pairs` times per direction.
SimulationConfig shortDualRate(double rate = 0.4, double acceleration = 0.5, int pairs = 8) {
  SimulationConfig c = SimulationConfig::load(std::string(HRG_GYRO_SOURCE_DIR) + "/config/scenarios/dual_rate.yaml",
                                              nodeOnlyScenarioKeys());
  c.acceleration = acceleration;
  const double sweep = kTwoPi / (0.56 * rate);
  TurntableProfile p;
  p.append(5.0, 0.0, 0.0, "start");
  auto ramp = [&](double from, double to) {
    const double a = std::copysign(c.acceleration, to - from);
    p.append((to - from) / a, from, a, "ramp");
  };
  double now = 0.0;
  for (int r = 0; r < pairs; ++r) {
    for (const double w : {rate, -rate}) {
      ramp(now, w);
      p.append(3.0, w, 0.0, "settle");
      p.append(sweep, w, 0.0, "plateau");
      now = w;
    }
  }
  ramp(now, 0.0);
  p.append(5.0, 0.0, 0.0, "rest");
  c.profile = p;
  return c;
}

std::shared_ptr<const GyroParameters> uncalibrated() {
  return std::make_shared<const GyroParameters>(
      loadParameterFile(std::string(HRG_GYRO_SOURCE_DIR) + "/config/params_uncalibrated.yaml"));
}

struct Measured {
  bool accepted = false;
  std::string reason;
  double residual_ppm = NAN;  ///< peak |K_cal - K_eff - (K0_cal - K0_eff)| / |K0| over theta
  double k0_ppm = NAN;        ///< (K0_cal - K0_eff) / |K0|
  double sigma_ppm = NAN;     ///< root sum of squares of the reported standard errors of the K harmonics
  double k0_sigma_ppm = NAN;  ///< reported standard error of K0
  double injected_ppm = NAN;  ///< peak nonlinearity of the exact model
  OfflineCalibration run;
};

/// Calibrates on `c` and compares with the exact model of every even order up to 16.
Measured calibrate(const std::string& name, const SimulationConfig& c, CalibrationSettings settings = {}) {
  const auto prior = uncalibrated();
  Measured m;
  m.run = calibrateOnSimulation(c, prior, settings);
  m.accepted = m.run.outcome.accepted;
  m.reason = m.run.outcome.reason;
  std::vector<int> all;
  for (int k = 2; k <= 16; k += 2) all.push_back(k);
  const EffectiveModel exact = computeEffectiveModel(c, prior->correction, all, settings.drift_orders);
  const HarmonicModel truth = toModel(exact.scale_factor);
  m.injected_ppm = exact.nonlinearity_ppm;
  const double k0 = std::abs(truth.meanAt(NAN));
  if (!m.run.outcome.scale_factor.empty() && m.run.outcome.scale_factor[0].ok) {
    const HarmonicFitResult& fit = m.run.outcome.scale_factor[0];
    const HarmonicModel estimate = toModel(fit);
    const testing::ModelResidual residual = testing::residualAgainst(estimate, NAN, truth, NAN, 2048);
    m.residual_ppm = residual.nonlinearity_ppm;
    m.k0_ppm = residual.scale_ppm;
    m.k0_sigma_ppm = 1e6 * fit.mean_std / k0;
    double var = 0.0;
    for (std::size_t j = 0; j < fit.orders.size(); ++j)
      var += fit.cos_std[j] * fit.cos_std[j] + fit.sin_std[j] * fit.sin_std[j];
    m.sigma_ppm = 1e6 * std::sqrt(var) / k0;
  }
  std::printf(
      "[ measured ] %s: %s; residual nonlinearity %.3f ppm (reported sigma %.3f ppm), K0 error %.3f ppm (sigma "
      "%.3f ppm); injected nonlinearity %.1f ppm; %.0f s simulated\n",
      name.c_str(), m.accepted ? "accepted" : ("refused: " + m.reason).c_str(), m.residual_ppm, m.sigma_ppm, m.k0_ppm,
      m.k0_sigma_ppm, m.injected_ppm, m.run.simulated_seconds);
  return m;
}

void expectWithinOnePpm(const Measured& m) {
  ASSERT_TRUE(m.accepted) << m.reason;
  EXPECT_LE(m.residual_ppm, 1.0);
}

TEST(RealSessionImperfectionsTest, NominalSession) { expectWithinOnePpm(calibrate("nominal", shortDualRate())); }

TEST(RealSessionImperfectionsTest, SlowDriveAcceleration) {
  // A drive limited to 0.02 rad/s^2: 40 s ramps between the plateaus instead of 1.6 s.
  expectWithinOnePpm(calibrate("acceleration 0.02 rad/s^2", shortDualRate(0.4, 0.02)));
}

// A slow drive (40 s ramps): K0 too must stay exact. Before the plateaus were judged on the angle's
// slope and the body angle taken from the logged angle, K0 came out 2.2 ppm off here (about 60
// reported sigmas), and the independent generator showed the same.
TEST(RealSessionImperfectionsTest, SlowDriveAccelerationLeavesK0Exact) {
  const Measured m = calibrate("acceleration 0.02 rad/s^2, K0", shortDualRate(0.4, 0.02));
  ASSERT_TRUE(m.accepted) << m.reason;
  EXPECT_LE(std::abs(m.k0_ppm), 1.0);
}

TEST(RealSessionImperfectionsTest, LostMessagesAndGapsInBothStreams) {
  SimulationConfig c = shortDualRate();
  c.channels.drop_probability = 0.002;
  c.channels.gaps = {{40.0, 2.0}, {150.0, 0.5}};
  c.turntable_log.delivery.drop_probability = 0.002;
  c.turntable_log.delivery.gaps = {{90.0, 1.0}, {200.0, 3.0}};
  const Measured m = calibrate("0.2 % lost and gaps in both streams", c);
  expectWithinOnePpm(m);
  EXPECT_GT(m.run.processor.rejected() + m.run.session.unsynchronized + m.run.session.unsettled, 0u);
}

TEST(RealSessionImperfectionsTest, GlitchedTableRecords) {
  SimulationConfig c = shortDualRate();
  c.turntable_log.glitches.per_record = {1e-3, 1e-3, 1e-3, 1e-3, 1e-3};
  const Measured m = calibrate("1e-3 glitched records per kind", c);
  expectWithinOnePpm(m);
  const RotationRecordRejects& r = m.run.session.rejected;
  EXPECT_GT(r.bad_rate + r.bad_angle + r.bad_stamp + r.out_of_order, 0u);
  EXPECT_EQ(m.run.session.restarts, 0u);
}

TEST(RealSessionImperfectionsTest, LogRateOfTheTableBelowTheGyros) {
  SimulationConfig c = shortDualRate();
  c.turntable_log.rate = 100.0;  // the gyro outputs at 200 Hz
  expectWithinOnePpm(calibrate("table logged at 100 Hz", c));
}

// Encoder noise and counts with the rate logged as the differenced angle: the plateaus come from the
// angle's slope and the body angle per window from the logged angle, so the rate's scatter does not matter.
TEST(RealSessionImperfectionsTest, EncoderNoiseAndQuantisationWithDifferencedRate) {
  SimulationConfig c = shortDualRate();
  c.turntable_log.rate = 100.0;
  c.turntable_log.angle_noise = 2e-6;
  c.turntable_log.angle_resolution = kTwoPi / (1 << 23);  // a 23-bit encoder
  c.turntable_log.logged_rate = LoggedRate::kDifferencedAngle;
  expectWithinOnePpm(calibrate("encoder 2 urad, 23 bit, rate differenced at 100 Hz", c));
}

// Drive ripple is in the true motion and in the logged angle: it cancels through the logged angle.
TEST(RealSessionImperfectionsTest, DriveRateRipple) {
  SimulationConfig c = shortDualRate();
  c.ripple = {0.002, 0.37, 0.0};
  expectWithinOnePpm(calibrate("rate ripple 0.2 % at 0.37 Hz", c));
}

// A/d0 = 0.2 puts a 3 % cos 4theta term into K, with higher orders falling off fast: the calibration
// fits every even order up to 12 (with the default 8 the 10 and 12theta terms are left over).
TEST(RealSessionImperfectionsTest, StrongPickoffNonlinearity) {
  SimulationConfig c = shortDualRate();
  c.pickoff.gap = c.resonator.amplitude / 0.2;
  CalibrationSettings settings;
  settings.scale_factor_orders = {2, 4, 6, 8, 10, 12};
  expectWithinOnePpm(calibrate("A/d0 = 0.2", c, settings));
}

/// A shipped scenario, loaded as the node loads it.
SimulationConfig shipped(const std::string& name) {
  return SimulationConfig::load(std::string(HRG_GYRO_SOURCE_DIR) + "/config/scenarios/" + name, nodeOnlyScenarioKeys());
}

// A bias that wanders by 1e-6 rad/s over the session, in the shipped order that cancels a linear
// trend (+ - - + ...) and in the alternating order that would let a constant-bias fit take it for
// K0: the trend is fitted with K, and measured against the injected one.
TEST(RealSessionImperfectionsTest, ABiasThatWandersThroughTheSession) {
  for (const char* order : {"balanced", "alternating"}) {
    SimulationConfig c = shipped("dual_rate_drifting.yaml");
    if (std::string(order) == "alternating") {
      const SimulationConfig plain = shipped("dual_rate.yaml");
      c.profile = plain.profile;  // + - + - ..., the same plateaus
      c.resonator.bias_drift.rate = 1e-6 / c.profile.duration();
    }
    const Measured m = calibrate(std::string("D0 drifting 1e-6 rad/s, ") + order, c);
    expectWithinOnePpm(m);
    EXPECT_LE(std::abs(m.k0_ppm), 3.0 * m.k0_sigma_ppm + 0.05);
    const BiasTrendFit& t = m.run.outcome.bias_trend;
    ASSERT_EQ(t.order, 1);
    std::printf("[ measured ] %s: trend %.4e +- %.1e rad/s per s (injected %.4e), K0 sigma x%.2f\n", order,
                t.coefficients[0], t.stds[0], c.resonator.bias_drift.rate, t.k0_inflation);
    EXPECT_NEAR(t.coefficients[0], c.resonator.bias_drift.rate, 3.0 * t.stds[0] + 0.01 * c.resonator.bias_drift.rate);
  }
}

// The table logged at 100 Hz on its own clock: 100 ms late, 2 ms of jitter, a 2 urad encoder; and
// the same clock running 10 ppm fast, which stretches the table angle (and K) by 10 ppm.
TEST(RealSessionImperfectionsTest, TheTableOnItsOwnClock) {
  for (double rate_error : {0.0, 1e-5}) {
    SimulationConfig c = shipped("dual_rate_table_clock.yaml");
    c.turntable_log.clock.rate_error = rate_error;
    const Measured m = calibrate("table at 100 Hz, 100 ms late, 2 ms jitter, rate error " +
                                     std::to_string(static_cast<int>(rate_error * 1e6)) + " ppm",
                                 c);
    expectWithinOnePpm(m);
    EXPECT_LE(std::abs(m.k0_ppm), 3.0 * m.k0_sigma_ppm + 0.05);
    const TableClockReport& clock = m.run.outcome.table_clock;
    std::printf(
        "[ measured ] table clock: offset %.4f +- %.4f ms (injected %.1f ms at the start), jitter %.3f ms (injected "
        "%.1f ms), rate error %.3f +- %.3f ppm (injected %.1f)\n",
        1e3 * clock.offset.offset, 1e3 * clock.offset.offset_std, 1e3 * c.turntable_log.clock.offset,
        1e3 * clock.stamps.jitter, 1e3 * c.turntable_log.clock.jitter, 1e6 * clock.offset.rate_error,
        1e6 * clock.offset.rate_error_std, 1e6 * rate_error);
    ASSERT_TRUE(clock.offset.estimated) << clock.offset.note;
    ASSERT_TRUE(clock.offset.rate_estimated);
    EXPECT_NEAR(clock.offset.rate_error, rate_error, 3.0 * clock.offset.rate_error_std + 1e-8);
    if (rate_error == 0.0) {
      EXPECT_NEAR(clock.offset.offset, c.turntable_log.clock.offset, 3.0 * clock.offset.offset_std + 2e-5);
    }
    EXPECT_TRUE(clock.stamps.fixed_rate) << clock.stamps.note;
    EXPECT_NEAR(clock.stamps.jitter, c.turntable_log.clock.jitter, 0.1 * c.turntable_log.clock.jitter);
  }
}

}  // namespace
}  // namespace core
}  // namespace hrg_gyro

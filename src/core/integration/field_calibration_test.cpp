// The field method on a gyro simulated from its equations of motion (config/scenarios/
// resonator_field.yaml: the averaged resonator on a still table, its wave precessed both ways): D(theta)
// and the realised gain of the virtual rate against the injected model (the exact settled drift and
// gain through the pickoffs), its standard errors over many seeds, and its gates.
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>
#include <string>
#include <vector>

#include "core/testing/shipped_scenarios.h"
#include "hrg_gyro/core/calibration/field_command_plan.h"
#include "hrg_gyro/core/evaluation/offline_pipeline.h"
#include "hrg_gyro/core/model/earth_rate.h"
#include "hrg_gyro/core/resonator/first_order_model.h"
#include "hrg_gyro/core/simulation/injected_model.h"

namespace hrg_gyro {
namespace core {
namespace {

using testing::shippedScenario;

CalibrationSettings fieldSettings() {
  CalibrationSettings s;
  s.method = CalibrationMethodKind::kField;
  return s;
}

/// What a perfect table calibration left: the injected K and D, the site's latitude.
std::shared_ptr<GyroParameters> tablePrior(const SimulationConfig& c, const CalibrationSettings& s) {
  auto p = std::make_shared<GyroParameters>();
  const EffectiveModel e = computeEffectiveModel(c, p->correction, s.scale_factor_orders, s.drift_orders);
  p->scale_factor = toModel(e.scale_factor);
  p->drift = toModel(e.drift);
  p->earth_rate.latitude = c.latitude;
  return p;
}

/// The scenario with the virtual rotation the settings plan, and the table still until its end plus 3 s.
SimulationConfig withPlan(SimulationConfig c, const CalibrationSettings& s) {
  c.dynamics.commands.clear();
  for (const PlannedPrecession& p : fieldCommandPlan(s)) c.dynamics.commands.push_back({p.time, p.rate});
  c.profile = TurntableProfile();
  c.profile.append(c.dynamics.commands.back().time + 3.0, 0.0, 0.0, "still");
  return c;
}

/// (estimate - injected) / sigma for every term of a fit, mean first.
std::vector<double> normalisedErrors(const HarmonicFitResult& estimate, const HarmonicFitResult& injected) {
  std::vector<double> z{(estimate.mean - injected.mean) / estimate.mean_std};
  for (std::size_t j = 0; j < estimate.orders.size(); ++j) {
    z.push_back((estimate.cos[j] - injected.cos[j]) / estimate.cos_std[j]);
    z.push_back((estimate.sin[j] - injected.sin[j]) / estimate.sin_std[j]);
  }
  return z;
}

double largestMagnitude(const std::vector<double>& v) {
  double m = 0.0;
  for (double x : v) m = std::max(m, std::abs(x));
  return m;
}

TEST(FieldCalibration, ShippedScenarioCarriesTheShippedPlan) {
  const SimulationConfig c = shippedScenario("resonator_field.yaml");
  // The plan of config/calibrator.yaml's field section (which the live calibrator loads).
  YAML::Node settings;
  settings["field"] = YAML::LoadFile(std::string(HRG_GYRO_SOURCE_DIR) + "/config/calibrator.yaml")["field"];
  const std::vector<PlannedPrecession> plan = fieldCommandPlan(CalibrationSettings::parse(YamlField(settings, "")));
  ASSERT_EQ(plan.size(), fieldCommandPlan(CalibrationSettings()).size());  // the template is the defaults
  ASSERT_EQ(c.dynamics.commands.size(), plan.size());
  for (std::size_t i = 0; i < plan.size(); ++i) {
    EXPECT_NEAR(c.dynamics.commands[i].time, plan[i].time, 1e-6) << i;
    EXPECT_EQ(c.dynamics.commands[i].rate, plan[i].rate) << i;
  }
  EXPECT_EQ(c.profile.pieces().size(), 1u);  // the table never moves
}

TEST(FieldCalibration, RecoversTheInjectedDriftAndGainOnAStillGyro) {
  const SimulationConfig c = shippedScenario("resonator_field.yaml");
  const CalibrationSettings s = fieldSettings();
  const auto prior = tablePrior(c, s);
  const auto start = std::chrono::steady_clock::now();
  const OfflineCalibration run = calibrateOnSimulation(c, prior, s);
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  const CalibrationOutcome& o = run.outcome;
  for (const GateResult& g : o.gates)
    std::printf("  %s %s: %s\n", g.passed ? "pass" : "FAIL", g.name.c_str(), g.message.c_str());
  ASSERT_TRUE(o.accepted) << o.reason;
  EXPECT_TRUE(o.scale_factor.empty());  // K is kept
  EXPECT_EQ(o.parameters.scale_factor, prior->scale_factor);
  const EffectiveModel injected =
      computeEffectiveModel(c, prior->correction, s.scale_factor_orders, s.drift_orders, s.field.gain_orders);
  const HarmonicFitResult& d = o.drift[0];
  const HarmonicFitResult& g = o.field.virtual_rate_gain;
  std::printf("[ measured ] %.0f s simulated, calibrated in %.1f s\n", run.simulated_seconds, seconds);
  std::printf(
      "[ measured ] D0 %.5g (injected %.5g, sigma %.2g); cos2 %.6g (%.6g, %.2g); sin2 %.6g (%.6g, %.2g) rad/s\n",
      d.mean, injected.drift.mean, d.mean_std, d.cos[0], injected.drift.cos[0], d.cos_std[0], d.sin[0],
      injected.drift.sin[0], d.sin_std[0]);
  std::printf("[ measured ] G_v0 %.8f (injected %.8f, sigma %.2g); cos2 %.5g (%.5g, %.2g)\n", g.mean,
              injected.virtual_rate_gain.mean, g.mean_std, g.cos[0], injected.virtual_rate_gain.cos[0], g.cos_std[0]);
  const std::vector<double> zd = normalisedErrors(d, injected.drift),
                            zg = normalisedErrors(g, injected.virtual_rate_gain);
  std::printf("[ measured ] largest |estimate - injected| / sigma: D %.2f, G_v %.2f; stillness %.3f\n",
              largestMagnitude(zd), largestMagnitude(zg), o.field.excess_scatter);
  EXPECT_LT(largestMagnitude(zd), 3.0);
  EXPECT_LT(largestMagnitude(zg), 3.0);
}

// Over many seeds, the estimates scatter about the injected model as their standard errors say. The
// harmonics' errors come from the block sandwich; D0's and G_v0's (slopes in time) are conservative
// (the sandwich does not pair the increments across the blocks' boundaries, which telescope there).
TEST(FieldCalibration, StandardErrorsAreHonestOverSeeds) {
  CalibrationSettings s = fieldSettings();
  s.field.directions = {1, -1};
  const SimulationConfig base = withPlan(shippedScenario("resonator_field.yaml"), s);
  const auto prior = tablePrior(base, s);
  const EffectiveModel injected =
      computeEffectiveModel(base, prior->correction, s.scale_factor_orders, s.drift_orders, s.field.gain_orders);
  std::vector<double> harmonics, d0, g0;
  const int seeds = 10;
  for (int seed = 1; seed <= seeds; ++seed) {
    SimulationConfig c = base;
    c.seed = 1000 + seed;
    const CalibrationOutcome o = calibrateOnSimulation(c, prior, s).outcome;
    ASSERT_TRUE(o.accepted) << seed << ": " << o.reason;
    const std::vector<double> zd = normalisedErrors(o.drift[0], injected.drift);
    const std::vector<double> zg = normalisedErrors(o.field.virtual_rate_gain, injected.virtual_rate_gain);
    d0.push_back(zd[0]);
    g0.push_back(zg[0]);
    harmonics.insert(harmonics.end(), zd.begin() + 1, zd.end());
    harmonics.insert(harmonics.end(), zg.begin() + 1, zg.end());
  }
  auto rms = [](const std::vector<double>& v) {
    double ss = 0.0;
    for (double x : v) ss += x * x;
    return std::sqrt(ss / v.size());
  };
  std::printf(
      "[ measured ] %d seeds: rms of (estimate - injected) / sigma: harmonics of D and G_v %.2f (%zu terms, "
      "largest %.2f), D0 %.2f, G_v0 %.2f\n",
      seeds, rms(harmonics), harmonics.size(), largestMagnitude(harmonics), rms(d0), rms(g0));
  // 80 terms: the rms of honest errors lies within 0.78..1.22 with 95 % probability.
  EXPECT_GT(rms(harmonics), 0.75);
  EXPECT_LT(rms(harmonics), 1.25);
  EXPECT_LT(largestMagnitude(harmonics), 4.0);
  EXPECT_LT(rms(d0), 1.3);
  EXPECT_LT(rms(g0), 1.3);
}

// A gyro whose sensitive axis is not vertical sees another share of the Earth's rate: a horizontal
// axis pointing North at 51.6 deg N sees Omega_E cos(lat), simulated as the vertical rate of the
// complementary latitude. Taken as vertical at the prior's latitude, D0 is off by K0 times the
// difference; given in field/axis_earth_rate, D0 is right again.
TEST(FieldCalibration, TheEarthRateAboutATiltedAxisComesFromTheSettings) {
  SimulationConfig c = shippedScenario("resonator_field.yaml");
  const double site = c.latitude;
  c.latitude = 0.5 * M_PI - site;  // the horizontal North axis's share, as a vertical one
  CalibrationSettings s = fieldSettings();
  auto prior = tablePrior(c, s);
  prior->earth_rate.latitude = site;  // the prior knows the site, not the mounting
  const EffectiveModel injected = computeEffectiveModel(c, prior->correction, s.scale_factor_orders, s.drift_orders);
  const CalibrationOutcome assumed = calibrateOnSimulation(c, prior, s).outcome;
  s.field.axis_earth_rate = horizontalEarthRate(site);
  const CalibrationOutcome told = calibrateOnSimulation(c, prior, s).outcome;
  ASSERT_TRUE(told.accepted) << told.reason;
  const double expected_offset =
      prior->scale_factor.meanAt(NAN) * kEarthRotationRate * (std::cos(site) - std::sin(site));  // K0 dOmega
  const double assumed_error = assumed.drift.at(0).mean - injected.drift.mean;
  const double told_error = told.drift.at(0).mean - injected.drift.mean;
  std::printf(
      "[ measured ] horizontal axis: D0 off by %.3e rad/s taken as vertical (K0 dOmega %.3e), %.2e with "
      "field/axis_earth_rate (sigma %.1e)\n",
      assumed_error, expected_offset, told_error, told.drift[0].mean_std);
  EXPECT_NEAR(assumed_error, expected_offset, 3.0 * assumed.drift.at(0).mean_std + 1e-9);
  EXPECT_LT(std::abs(told_error), 3.0 * told.drift[0].mean_std);
  EXPECT_DOUBLE_EQ(told.field.earth_rate, s.field.axis_earth_rate);
}

const GateResult* findGate(const CalibrationOutcome& o, const std::string& name) {
  for (const GateResult& g : o.gates) {
    if (g.name == name) return &g;
  }
  return nullptr;
}

/// (estimate - exact - predicted) per D term, mean first, and each term's sigma: what of D's error
/// the loops' lag at `lag`'s rate does not explain.
struct Unexplained {
  std::vector<double> residual, sigma, predicted;
  std::vector<std::string> names;
};
Unexplained unexplainedDrift(const HarmonicFitResult& d, const HarmonicFitResult& exact, const HarmonicModel& lag) {
  Unexplained u;
  std::vector<double> terms(lag.termCount());
  lag.coefficientsAt(NAN, terms.data());
  const std::size_t n = d.orders.size(), nl = lag.orders().size();
  for (std::size_t i = 0; i < 1 + 2 * n; ++i) {
    const bool mean = i == 0, cosine = i >= 1 && i <= n;
    const std::size_t j = mean ? 0 : (cosine ? i - 1 : i - 1 - n);
    double predicted = 0.0;  // the lag's coefficient of this term (none for the mean)
    for (std::size_t k = 0; !mean && k < nl; ++k) {
      if (lag.orders()[k] == d.orders[j]) predicted = terms[cosine ? 1 + k : 1 + nl + k];
    }
    const double estimate = mean ? d.mean : (cosine ? d.cos[j] : d.sin[j]);
    const double truth = mean ? exact.mean : (cosine ? exact.cos[j] : exact.sin[j]);
    u.residual.push_back(estimate - truth - predicted);
    u.predicted.push_back(predicted);
    u.sigma.push_back(mean ? d.mean_std : (cosine ? d.cos_std[j] : d.sin_std[j]));
    u.names.push_back(mean ? std::string("D0") : (cosine ? "cos" : "sin") + std::to_string(d.orders[j]));
  }
  return u;
}

// A fast precession leaves the loops behind, and what they leave that keeps its sign in both
// directions is fitted as D. At 5 rad/s (40 turns a segment, 4 segments: about the shipped plan's
// time) the gyro's D is off its exact settled drift by precessionLagDrift, tens of its standard
// errors: checked on the simulated resonator read through ideal linear pickoffs at 1 kHz with a
// hundredth of the noise, so that nothing else at this rate moves D (tolerance 4 sigma of each term
// plus 2 % of the lag, the formula's accuracy against the closed-loop resonator); the loop_lag gate
// refuses the result. At the shipped 0.2 rad/s the gate passes (the lag is 0.5 % of D's standard
// errors). With the scenario's own pickoffs (capacitive, A/d0 = 0.05, and their defects) the signal
// level adds an even-in-rate term of its own, which the gate does not see (printed; at least 10 sigma
// at 5 rad/s).
TEST(FieldCalibration, TheLoopsLagAtAFastRateIsInDAsPredictedAndGated) {
  const SimulationConfig shipped = shippedScenario("resonator_field.yaml");
  CalibrationSettings s = fieldSettings();
  s.field.resonator = FieldResonator{shipped.dynamics.shell, shipped.dynamics.loops, shipped.dynamics.drive};
  const CalibrationOutcome slow = calibrateOnSimulation(shipped, tablePrior(shipped, s), s).outcome;
  const GateResult* slow_gate = findGate(slow, "loop_lag");
  ASSERT_NE(slow_gate, nullptr);
  std::printf("[ measured ] at 0.2 rad/s: %s\n", slow_gate->message.c_str());
  EXPECT_TRUE(slow_gate->passed);
  EXPECT_TRUE(slow.accepted) << slow.reason;

  s.field.rate = 5.0;
  s.field.turns = 40.0;
  SimulationConfig quiet = withPlan(shipped, s);
  quiet.resonator.periods_per_output = 5;  // 1 kHz: 5 mrad of theta per sample
  quiet.pickoff.noise = 2e-6;
  SimulationConfig linear = quiet;
  linear.pickoff.misplacement.fill(0.0);
  linear.pickoff.gain_error.fill(0.0);
  linear.pickoff.gap = std::numeric_limits<double>::infinity();
  const FieldResonator& g = *s.field.resonator;
  const HarmonicModel lag = precessionLagDrift(g.shell, g.loops, g.drive, s.field.rate);
  std::vector<double> terms(lag.termCount());
  lag.coefficientsAt(NAN, terms.data());
  double rss = 0.0;
  for (double t : terms) rss += t * t;
  for (const SimulationConfig* c : {&linear, &quiet}) {
    const bool ideal = c == &linear;
    const auto prior = tablePrior(*c, s);
    const EffectiveModel exact = computeEffectiveModel(*c, prior->correction, s.scale_factor_orders, s.drift_orders);
    const CalibrationOutcome o = calibrateOnSimulation(*c, prior, s).outcome;
    std::printf("5 rad/s, %s pickoffs:\n", ideal ? "ideal linear" : "the scenario's");
    for (const GateResult& r : o.gates)
      std::printf("  %s %s: %s\n", r.passed ? "pass" : "FAIL", r.name.c_str(), r.message.c_str());
    ASSERT_EQ(o.drift.size(), 1u);
    const Unexplained u = unexplainedDrift(o.drift[0], exact.drift, lag);
    double largest_z = 0.0, largest_unexplained_z = 0.0;
    for (std::size_t i = 0; i < u.residual.size(); ++i) {
      const double error = u.residual[i] + u.predicted[i];
      largest_z = std::max(largest_z, std::abs(error) / u.sigma[i]);
      largest_unexplained_z = std::max(largest_unexplained_z, std::abs(u.residual[i]) / u.sigma[i]);
      std::printf(
          "[ measured ] 5 rad/s, %s pickoffs, D %s: estimate - exact %+.4e rad/s, predicted lag %+.4e, sigma %.2e "
          "(unexplained %+.4e, %.1f sigma)\n",
          ideal ? "ideal" : "scenario", u.names[i].c_str(), error, u.predicted[i], u.sigma[i], u.residual[i],
          u.residual[i] / u.sigma[i]);
      if (ideal) EXPECT_NEAR(u.residual[i], 0.0, 4.0 * u.sigma[i] + 0.02 * std::sqrt(rss)) << u.names[i];
    }
    if (ideal) {
      EXPECT_GT(largest_z, 10.0);  // the lag shows
      const GateResult* gate = findGate(o, "loop_lag");
      ASSERT_NE(gate, nullptr);
      EXPECT_FALSE(gate->passed);
      EXPECT_FALSE(o.accepted);
    } else {
      EXPECT_GT(largest_unexplained_z, 10.0);  // the capacitive pickoffs' own share
    }
  }
}

// What a field session cannot give is refused by name: one direction only (D and the gain are then
// one unknown), and a case that moves (its rotation is read as drift).
TEST(FieldCalibration, GatesRefuseOneDirectionAndAMovingCase) {
  CalibrationSettings s = fieldSettings();
  s.field.directions = {1, 1};
  SimulationConfig c = withPlan(shippedScenario("resonator_field.yaml"), s);
  const auto prior = tablePrior(c, s);
  CalibrationOutcome o = calibrateOnSimulation(c, prior, s).outcome;
  EXPECT_FALSE(o.accepted);
  EXPECT_EQ(o.reason.rfind("directions", 0), 0u) << o.reason;

  s.field.directions = {1, -1};
  c = withPlan(shippedScenario("resonator_field.yaml"), s);
  // The vehicle sways: +-2e-4 rad/s at 0.2 Hz, 0.16 mrad of heading.
  const double end = c.profile.duration();
  std::string points;
  for (double t = 0.0; t <= end + 1e-9; t += 0.25) {
    points += (points.empty() ? "" : ", ") + std::string("[") + std::to_string(t) + ", " +
              std::to_string(2e-4 * std::sin(kTwoPi * 0.2 * t)) + "]";
  }
  c.profile = TurntableProfile::parse(
      YamlField(YAML::Load("profile: [{type: piecewise, points: [" + points + "]}]"), "")["profile"], c.acceleration);
  o = calibrateOnSimulation(c, prior, s).outcome;
  EXPECT_FALSE(o.accepted);
  bool stillness_failed = false;
  for (const GateResult& g : o.gates) {
    if (g.name == "stillness") {
      stillness_failed = !g.passed;
      std::printf("[ measured ] a swaying case: %s\n", g.message.c_str());
    }
  }
  EXPECT_TRUE(stillness_failed) << o.reason;
}

}  // namespace
}  // namespace core
}  // namespace hrg_gyro

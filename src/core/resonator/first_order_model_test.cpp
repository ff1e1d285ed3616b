// The first-order D(theta), K(theta) and virtual-rate gain: against the closed form (the neglected
// terms are of second order) and against the closed-loop resonator, the wave held still, turned by
// the body at a constant rate either way, and precessed through full turns either way.
#include "hrg_gyro/core/resonator/first_order_model.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <vector>

#include "core/testing/resonator_cases.h"
#include "hrg_gyro/core/common/units.h"
#include "hrg_gyro/core/estimation/harmonic_fit.h"
#include "hrg_gyro/core/resonator/resonator_dynamics.h"
#include "hrg_gyro/core/resonator/steady_state_response.h"

namespace hrg_gyro {
namespace core {
namespace {

using testing::loopTrackingBound;
using testing::RateSample;
using testing::ResonatorCase;
using testing::runResonator;

// The quadrature loop's lag factor of first_order_model.h at theta.
double lagFactor(const ResonatorCase& c, const ResonatorModel& m, double theta) {
  return 1.0 - m.quadrature_lag * (1.0 + std::cos(4.0 * (theta - c.shell.frequency_axis)));
}

struct SecondOrder {
  double drift = 0.0;  // max over theta of |D1 - D|, rad/s
  double gain = 0.0;   // max over theta of |G1 - G_v (lag)|
};

// How far the first-order model is from the closed form: the neglected orders, measured on a dense grid.
SecondOrder neglected(const ResonatorCase& c) {
  const ResonatorModel m = firstOrderModel(c.shell, c.loops, c.drive);
  const SteadyStateResponse steady(c.shell, c.loops, c.drive);
  SecondOrder e;
  for (int i = 0; i < 1024; ++i) {
    const double theta = kPi * i / 1024;
    e.drift = std::max(e.drift, std::abs(m.drift(theta) - steady.drift(theta)));
    e.gain =
        std::max(e.gain, std::abs(m.virtual_rate_gain(theta) - steady.virtualRateGain(theta) * lagFactor(c, m, theta)));
  }
  return e;
}

HarmonicFitResult fitRates(const std::vector<RateSample>& samples, const std::vector<int>& orders) {
  std::vector<FitPoint> points;
  points.reserve(samples.size());
  for (const RateSample& s : samples) {
    FitPoint p;
    p.theta = s.theta;
    p.value = s.rate;
    p.span = s.span;
    points.push_back(p);
  }
  HarmonicFitResult fit = fitHarmonics(points, orders);
  EXPECT_TRUE(fit.ok) << fit.reason;
  return fit;
}

// Two full turns of theta at a constant body rate or virtual rate, after the loops have settled.
std::vector<RateSample> sweep(const ResonatorCase& c, double body_rate, double virtual_rate) {
  ResonatorDynamics d(c.shell, c.loops, c.drive, {1.0, 0.0, 0.3, c.loops.phase});
  runResonator(&d, 1.0, body_rate, virtual_rate, false);
  const double turning = std::abs(c.shell.scaleFactor() * body_rate + virtual_rate);
  return runResonator(&d, 2.0 * kTwoPi / turning, body_rate, virtual_rate);
}

void printModel(const char* what, const HarmonicModel& m) {
  std::printf("  %-28s mean %+.4e", what, m.meanAt(NAN));
  std::vector<double> terms(m.termCount());
  m.coefficientsAt(NAN, terms.data());
  for (std::size_t i = 0; i < m.orders().size(); ++i) {
    std::printf("  cos%d %+.4e sin%d %+.4e", m.orders()[i], terms[1 + i], m.orders()[i],
                terms[1 + m.orders().size() + i]);
  }
  std::printf("\n");
}

// A harmonic model's coefficient for `order` (0: the mean; cos when `cosine`).
double coefficient(const HarmonicModel& m, int order, bool cosine) {
  std::vector<double> terms(m.termCount());
  m.coefficientsAt(NAN, terms.data());
  if (order == 0) return terms[0];
  for (std::size_t i = 0; i < m.orders().size(); ++i) {
    if (m.orders()[i] == order) return terms[cosine ? 1 + i : 1 + m.orders().size() + i];
  }
  return 0.0;
}
double coefficient(const HarmonicFitResult& f, int order, bool cosine) {
  if (order == 0) return f.mean;
  for (std::size_t i = 0; i < f.orders.size(); ++i) {
    if (f.orders[i] == order) return cosine ? f.cos[i] : f.sin[i];
  }
  return 0.0;
}

// Compares the mean and the order-2 and order-4 coefficients of `value` (a fit combination) with
// the model, within `tolerance`.
template <class Value>
void expectCoefficients(const char* what, const HarmonicModel& model, Value value, double tolerance) {
  for (int order : {0, 2, 4}) {
    for (bool cosine : {true, false}) {
      if (order == 0 && !cosine) continue;
      const double predicted = coefficient(model, order, cosine), simulated = value(order, cosine);
      std::printf("  %s %s%d: simulated %+.5e predicted %+.5e (tolerance %.1e)\n", what,
                  order == 0 ? "mean"
                  : cosine   ? "cos"
                             : "sin",
                  order == 0 ? 0 : order, simulated, predicted, tolerance);
      EXPECT_NEAR(simulated, predicted, tolerance) << what << " order " << order << (cosine ? " cos" : " sin");
    }
  }
}

TEST(ResonatorFirstOrderModel, DiffersFromTheClosedFormOnlyAtSecondOrder) {
  const ResonatorCase c = testing::realisticResonator();
  const SecondOrder full = neglected(c), half = neglected(c.scaled(0.5));
  const ResonatorModel m = firstOrderModel(c.shell, c.loops, c.drive);
  std::printf(
      "first order against the closed form: |dD| <= %.2e rad/s (D peak %.2e), |dG_v| <= %.2e; at half the "
      "defects %.2e and %.2e\n",
      full.drift, m.drift.peakDeviation(), full.gain, half.drift, half.gain);
  EXPECT_LT(full.drift, 5e-3 * m.drift.peakDeviation());
  EXPECT_LT(full.gain, 1e-4);
  // Halving every defect quarters what the first order leaves out.
  EXPECT_NEAR(full.drift / half.drift, 4.0, 0.4);
  EXPECT_NEAR(full.gain / half.gain, 4.0, 0.4);
}

TEST(ResonatorFirstOrderModel, PredictsTheDriftOfAWaveHeldStill) {
  const ResonatorCase c = testing::realisticResonator();
  const ResonatorModel m = firstOrderModel(c.shell, c.loops, c.drive);
  const double bound = neglected(c).drift;
  std::vector<RateSample> rest;
  for (int j = 0; j < 16; ++j) {
    ResonatorDynamics d(c.shell, c.loops, c.drive, {1.0, 0.0, kPi * j / 16, c.loops.phase});
    runResonator(&d, 1.5, 0.0, 0.0, false);
    const double before = d.wave().theta;
    runResonator(&d, 1.0, 0.0, 0.0, false);
    const double theta = 0.5 * (before + d.wave().theta), rate = d.wave().theta - before;
    EXPECT_NEAR(rate, m.drift(theta), bound + 2e-12) << "theta " << theta;
    rest.push_back({theta, rate, 0.0});
  }
  std::printf("wave held still at 16 angles (first-order model's error bound %.2e rad/s):\n", bound);
  printModel("predicted D", m.drift);
  const HarmonicFitResult fit = fitRates(rest, {2, 4});
  expectCoefficients(
      "rest D", m.drift, [&](int order, bool cosine) { return coefficient(fit, order, cosine); }, 2.0 * bound + 1e-11);
}

// The body turns the gyro at +-0.5 rad/s (theta at -+0.28 rad/s, two full turns each way). As in the
// dual-rate calibration, half the sum of the two runs' harmonics is D and half the difference over
// the rate is K.
TEST(ResonatorFirstOrderModel, PredictsDAndKAtAConstantBodyRate) {
  const ResonatorCase c = testing::realisticResonator();
  const ResonatorModel m = firstOrderModel(c.shell, c.loops, c.drive);
  const double rate = 0.5, turning = std::abs(c.shell.scaleFactor() * rate);
  const std::vector<int> orders = {2, 4, 6};
  const HarmonicFitResult up = fitRates(sweep(c, rate, 0.0), orders), down = fitRates(sweep(c, -rate, 0.0), orders);
  const double loops = loopTrackingBound(c, turning, m.quadrature_lag);
  const double drift_tolerance = 2.0 * (neglected(c).drift + loops) + 1e-11;
  std::printf("body rate +-%.1f rad/s (loop tracking bound %.2e rad/s):\n", rate, loops);
  printModel("predicted D", m.drift);
  printModel("predicted K", m.scale_factor);
  expectCoefficients(
      "D", m.drift,
      [&](int order, bool cosine) { return 0.5 * (coefficient(up, order, cosine) + coefficient(down, order, cosine)); },
      drift_tolerance);
  // Odd in the rate, only the lag's next order and rounding remain.
  expectCoefficients(
      "K", m.scale_factor,
      [&](int order, bool cosine) {
        return 0.5 * (coefficient(up, order, cosine) - coefficient(down, order, cosine)) / rate;
      },
      2.0 * loops / rate + 1e-11);
}

// The precession loop sweeps theta through two full turns each way at 2 rad/s electrical: half the
// sum is D, half the difference over the command the virtual rate's gain.
TEST(ResonatorFirstOrderModel, PredictsTheVirtualRateGainAndTheDriftUnderPrecession) {
  const ResonatorCase c = testing::realisticResonator();
  const ResonatorModel m = firstOrderModel(c.shell, c.loops, c.drive);
  const double command = 2.0;
  const std::vector<int> orders = {2, 4, 6};
  const HarmonicFitResult up = fitRates(sweep(c, 0.0, command), orders);
  const HarmonicFitResult down = fitRates(sweep(c, 0.0, -command), orders);
  const SecondOrder second = neglected(c);
  const double loops = loopTrackingBound(c, command, m.quadrature_lag);
  std::printf("virtual rate +-%.1f rad/s (loop tracking bound %.2e rad/s):\n", command, loops);
  printModel("predicted D", m.drift);
  printModel("predicted G_v", m.virtual_rate_gain);
  expectCoefficients(
      "D", m.drift,
      [&](int order, bool cosine) { return 0.5 * (coefficient(up, order, cosine) + coefficient(down, order, cosine)); },
      2.0 * (second.drift + loops) + 1e-11);
  expectCoefficients(
      "G_v", m.virtual_rate_gain,
      [&](int order, bool cosine) {
        return 0.5 * (coefficient(up, order, cosine) - coefficient(down, order, cosine)) / command;
      },
      2.0 * (second.gain + loops / command) + 1e-11);
}

// A split 30 times the realistic one and a 5 Hz quadrature loop make the loop's lag visible in K:
// L = Dw^2 / (2 ki) = 5.1e-4. What the first order leaves out: the lag slows the wave that causes it,
// so K = K0 / (1 + x) with x = L (1 + cos 4(theta - theta_omega)), of which K0 (1 - x) is the first
// order (x^2 puts up to 2 L^2 into a coefficient), and B trails the split's source by a further
// (2 rate / wn)^2 of the lag (odd in the rate, so the dual-rate difference keeps it).
TEST(ResonatorFirstOrderModel, TheQuadratureLoopsLagChangesKAsPredicted) {
  ResonatorCase c;
  c.shell.frequency_split = 1.0;
  c.shell.frequency_axis = -0.7;
  c.loops.quadrature_bandwidth = 5.0;
  const ResonatorModel m = firstOrderModel(c.shell, c.loops, c.drive);
  const double lag = m.quadrature_lag, k0 = std::abs(c.shell.scaleFactor());
  EXPECT_NEAR(lag, 1.0 / (2.0 * std::pow(kTwoPi * 5.0, 2)), 1e-15);
  const double rate = 0.5, turning = k0 * rate;
  const std::vector<int> orders = {2, 4, 6, 8};
  const HarmonicFitResult up = fitRates(sweep(c, rate, 0.0), orders), down = fitRates(sweep(c, -rate, 0.0), orders);
  const double tolerance = k0 * (2.0 * lag * lag + 2.0 * lag * std::pow(2.0 * turning / (kTwoPi * 5.0), 2));
  std::printf("split 1 rad/s, 5 Hz quadrature loop: L = %.3e\n", lag);
  printModel("predicted K", m.scale_factor);
  expectCoefficients(
      "K", m.scale_factor,
      [&](int order, bool cosine) {
        return 0.5 * (coefficient(up, order, cosine) - coefficient(down, order, cosine)) / rate;
      },
      tolerance);
  // The lag shows: K's mean is K0 L = 2.8e-4 from K0 (100 times the tolerance).
  EXPECT_GT(std::abs(0.5 * (up.mean - down.mean) / rate - c.shell.scaleFactor()), 0.9 * lag * k0);
}

// Mode reversal: the precession loop turns the wave a quarter turn electrically (45 degrees on the
// shell), which swaps the roles of the two modes of every defect's pair. The order-2 drift changes
// sign, the body rate's K0 does not, so the sum of the rates measured before and after is the part of
// the drift that does not reverse (here of second order), and their difference twice the part that does.
TEST(ResonatorFirstOrderModel, ModeReversalByAQuarterTurnFlipsTheOrderTwoDrift) {
  const ResonatorCase c = testing::realisticResonator();
  const ResonatorModel m = firstOrderModel(c.shell, c.loops, c.drive);
  const SteadyStateResponse steady(c.shell, c.loops, c.drive);
  const double bound = neglected(c).drift, theta0 = 0.5;
  ResonatorDynamics d(c.shell, c.loops, c.drive, {1.0, 0.0, theta0, c.loops.phase});
  // The rate over a second, and the angle in its middle.
  const auto rateOver = [&](double* theta) {
    const double before = d.wave().theta;
    runResonator(&d, 1.0, 0.0, 0.0, false);
    *theta = 0.5 * (before + d.wave().theta);
    return d.wave().theta - before;
  };
  double theta1, theta2;
  runResonator(&d, 1.5, 0.0, 0.0, false);
  const double r1 = rateOver(&theta1);
  runResonator(&d, 0.5, 0.0, kPi, false);  // pi/2 at pi rad/s, as far as the realised gain takes it
  runResonator(&d, 1.5, 0.0, 0.0, false);
  const double r2 = rateOver(&theta2);
  std::printf("mode reversal: theta %.4f -> %.4f rad, drift %+.4e -> %+.4e rad/s\n", theta1, theta2, r1, r2);
  EXPECT_NEAR(theta2 - theta1, 0.5 * kPi, 0.01);  // the precession channel's errors: a few mrad
  EXPECT_NEAR(r1, steady.drift(theta1), 2e-12);
  EXPECT_NEAR(r2, steady.drift(theta2), 2e-12);
  // D1 has no mean: r1 + r2 is what the landing error (theta2 - theta1 - pi/2) and the second order leave.
  const double landing = std::abs(theta2 - theta1 - 0.5 * kPi) * 2.0 * m.drift.peakDeviation();
  EXPECT_NEAR(r1 + r2, 0.0, 2.0 * bound + landing);
  EXPECT_GT(std::abs(r1 - r2), 1e-5);
}

// The drift the loops' lag adds under precession, against the closed-loop resonator: precessed both
// ways at 0.2 to 10 rad/s, half the sum of the two runs' harmonics less the settled drift at rest is
// the part even in the rate, which a field calibration takes for D. Four gyros: the realistic one,
// the same with a 10 mHz split, a 50 mHz split with a 5 Hz quadrature loop and an ideal drive (the
// split's term alone, the rate up to the loop's bandwidth), and one with every lag term large (10 Hz
// and 2 Hz loops, 3 mrad drive lag, forcers 3e-3 apart: the energy loop is outrun above 3 rad/s).
// Tolerance: 2 % of the predicted terms' root sum square, plus 5e-12 rad/s. The formula takes the
// loops as continuous (their sampling delay, half a control period, moves the terms by about 1 %)
// and leaves out second-order products (gamma^2 h_c w^2: ~3e-9 rad/s of D0 and of the order-4 terms
// at 10 rad/s, about 0.5 % of the terms there); 5e-12 covers the rest drift's and the fit's rounding
// (the settled drift matches the resonator to 2e-12 rad/s, PredictsTheDriftOfAWaveHeldStill).
TEST(ResonatorFirstOrderModel, PrecessionLagDriftMatchesTheClosedLoopResonator) {
  struct Case {
    const char* name;
    ResonatorCase gyro;
  };
  std::vector<Case> cases;
  cases.push_back({"realistic (5 mHz split)", testing::realisticResonator()});
  cases.push_back({"realistic, 10 mHz split", testing::realisticResonator()});
  cases.back().gyro.shell.frequency_split = kTwoPi * 10e-3;
  ResonatorCase split_only;
  split_only.shell.frequency_split = kTwoPi * 50e-3;
  split_only.shell.frequency_axis = -0.7;
  split_only.loops.quadrature_bandwidth = 5.0;
  cases.push_back({"50 mHz split, 5 Hz quadrature loop, ideal drive", split_only});
  ResonatorCase slow = testing::realisticResonator();
  slow.shell.frequency_split = kTwoPi * 10e-3;
  slow.loops.quadrature_bandwidth = 10.0;
  slow.loops.energy_bandwidth = 2.0;
  slow.drive.phase_error = 3e-3;
  slow.drive.gain_error_c = 3e-3;
  slow.drive.gain_error_s = -3e-3;
  cases.push_back({"10 mHz split, 10 Hz and 2 Hz loops, 3 mrad lag, forcers 6e-3 apart", slow});
  const std::vector<int> orders = {2, 4, 6, 8};
  for (const Case& k : cases) {
    const ResonatorCase& c = k.gyro;
    const SteadyStateResponse steady(c.shell, c.loops, c.drive);
    // The settled drift's coefficients (exact projection on a dense grid).
    std::vector<RateSample> rest;
    for (int i = 0; i < 4096; ++i) {
      const double theta = kTwoPi * i / 4096;
      rest.push_back({theta, steady.drift(theta), 0.0});
    }
    const HarmonicFitResult at_rest = fitRates(rest, orders);
    std::printf("%s:\n", k.name);
    for (double rate : {0.2, 1.0, 2.0, 5.0, 10.0}) {
      const HarmonicModel lag = precessionLagDrift(c.shell, c.loops, c.drive, rate);
      EXPECT_EQ(lag, precessionLagDrift(c.shell, c.loops, c.drive, -rate));  // even in the rate, bit for bit
      const HarmonicFitResult up = fitRates(sweep(c, 0.0, rate), orders);
      const HarmonicFitResult down = fitRates(sweep(c, 0.0, -rate), orders);
      double rss = 0.0;
      for (int order : {2, 4}) {
        for (bool cosine : {true, false}) rss += std::pow(coefficient(lag, order, cosine), 2);
      }
      const double tolerance = 0.02 * std::sqrt(rss) + 5e-12;
      std::printf("  %5.1f rad/s: peak %.3e rad/s (tolerance %.1e)\n", rate, lag.peakDeviation(), tolerance);
      expectCoefficients(
          "D_lag", lag,
          [&](int order, bool cosine) {
            return 0.5 * (coefficient(up, order, cosine) + coefficient(down, order, cosine)) -
                   coefficient(at_rest, order, cosine);
          },
          tolerance);
    }
  }
}

TEST(ResonatorFirstOrderModel, PrecessionLagDriftNeedsAFiniteRate) {
  const ResonatorCase c = testing::realisticResonator();
  EXPECT_THROW(precessionLagDrift(c.shell, c.loops, c.drive, NAN), std::invalid_argument);
  EXPECT_EQ(precessionLagDrift(c.shell, c.loops, c.drive, 0.0).peakDeviation(), 0.0);  // no sweep, no lag
  ResonatorCase open = c;
  open.loops.quadrature_bandwidth = 0.0;
  EXPECT_THROW(precessionLagDrift(open.shell, open.loops, open.drive, 0.2), std::invalid_argument);
}

TEST(ResonatorFirstOrderModel, RefusesASplitWithoutTheQuadratureLoop) {
  ResonatorCase c = testing::realisticResonator();
  c.loops.quadrature_bandwidth = 0.0;
  EXPECT_THROW(firstOrderModel(c.shell, c.loops, c.drive), std::invalid_argument);
  c.shell.frequency_split = 0.0;  // nothing feeds B: nothing to hold
  const ResonatorModel m = firstOrderModel(c.shell, c.loops, c.drive);
  EXPECT_EQ(m.quadrature_lag, 0.0);
}

}  // namespace
}  // namespace core
}  // namespace hrg_gyro

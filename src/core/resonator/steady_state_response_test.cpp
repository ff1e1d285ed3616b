// The settled drift and virtual-rate gain in closed form, against the closed-loop resonator.
#include "hrg_gyro/core/resonator/steady_state_response.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "core/testing/resonator_cases.h"
#include "hrg_gyro/core/common/units.h"
#include "hrg_gyro/core/resonator/first_order_model.h"
#include "hrg_gyro/core/resonator/resonator_dynamics.h"

namespace hrg_gyro {
namespace core {
namespace {

using testing::loopTrackingBound;
using testing::ResonatorCase;
using testing::runResonator;

// The rate of a wave held still at each of 16 angles, loops settled: the closed form to 1e-12 rad/s.
double worstRestDeviation(const ResonatorCase& c, double* largest_drift) {
  const SteadyStateResponse steady(c.shell, c.loops, c.drive);
  double worst = 0.0;
  *largest_drift = 0.0;
  for (int j = 0; j < 16; ++j) {
    ResonatorDynamics d(c.shell, c.loops, c.drive, {1.0, 0.0, kPi * j / 16, c.loops.phase});
    runResonator(&d, 1.5, 0.0, 0.0, false);
    const double before = d.wave().theta;
    runResonator(&d, 1.0, 0.0, 0.0, false);
    const double rate = d.wave().theta - before;
    const double predicted = steady.drift(0.5 * (before + d.wave().theta));
    worst = std::max(worst, std::abs(rate - predicted));
    *largest_drift = std::max(*largest_drift, std::abs(predicted));
  }
  return worst;
}

TEST(ResonatorSteadyState, AWaveHeldStillDriftsAsTheClosedFormSays) {
  const ResonatorCase c = testing::realisticResonator();
  double largest = 0.0;
  const double worst = worstRestDeviation(c, &largest);
  std::printf("settled drift at rest: largest %.3e rad/s, closed form off by %.2e rad/s at most\n", largest, worst);
  EXPECT_GT(largest, 1e-5);
  EXPECT_LT(worst, 2e-12);
  // Without the energy loop no force works against the damping, so none leaks onto the node. A
  // decays meanwhile (by 0.4 %), the quadrature loop's effort against the split decays with it and
  // the loop trails it by B = Dw A / (2 tau_d ki) = 2e-9 A, which turns the wave at Dw B / A = 5e-11 rad/s.
  ResonatorCase open = c;
  open.loops.energy_bandwidth = 0.0;
  EXPECT_LT(worstRestDeviation(open, &largest), 1e-10);
}

// Sweeping theta through two full turns (4 pi) each way at 2 rad/s electrical: each millisecond's rate
// against D(theta) + G_v(theta) w_v, scaled by the quadrature loop's lag (first_order_model.h). The
// measured deviation, 8.3e-8 rad/s, is the loops' tracking (testing::loopTrackingBound; its bound is
// 9.2e-8 rad/s here, 7.3e-8 of it the energy loop's); the test allows 1.5 times the bound.
TEST(ResonatorSteadyState, TheVirtualRateIsRealisedWithTheClosedFormGain) {
  const ResonatorCase c = testing::realisticResonator();
  const SteadyStateResponse steady(c.shell, c.loops, c.drive);
  const ResonatorModel model = firstOrderModel(c.shell, c.loops, c.drive);
  double gain_min = 2.0, gain_max = 0.0;
  for (double command : {2.0, -2.0}) {
    ResonatorDynamics d(c.shell, c.loops, c.drive, {1.0, 0.0, 0.3, c.loops.phase});
    runResonator(&d, 1.0, 0.0, command, false);
    const auto samples = runResonator(&d, 2.0 * kTwoPi / std::abs(command), 0.0, command);
    double worst = 0.0;
    for (const auto& s : samples) {
      const double lag = 1.0 - model.quadrature_lag * (1.0 + std::cos(4.0 * (s.theta - c.shell.frequency_axis)));
      const double predicted = (steady.drift(s.theta) + steady.virtualRateGain(s.theta) * command) * lag;
      worst = std::max(worst, std::abs(s.rate - predicted));
      gain_min = std::min(gain_min, steady.virtualRateGain(s.theta));
      gain_max = std::max(gain_max, steady.virtualRateGain(s.theta));
    }
    const double bound = loopTrackingBound(c, command, model.quadrature_lag);
    std::printf("virtual rate %+.1f rad/s: closed form off by %.2e rad/s at most over %zu steps (bound %.2e)\n",
                command, worst, samples.size(), bound);
    EXPECT_LT(worst, 1.5 * bound + 1e-11);
  }
  EXPECT_GT(gain_max - gain_min, 2.9e-3);  // the forcers' imbalance: 2 gamma = 3e-3 peak to peak
}

TEST(ResonatorSteadyState, NeedsTheQuadratureLoop) {
  ResonatorCase c = testing::realisticResonator();
  c.loops.quadrature_bandwidth = 0.0;
  EXPECT_THROW(SteadyStateResponse(c.shell, c.loops, c.drive), std::invalid_argument);
}

}  // namespace
}  // namespace core
}  // namespace hrg_gyro

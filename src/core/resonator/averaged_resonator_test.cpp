// The averaged equations against the oscillator they average, the force projections, and the ideal
// shell's exact scale factor.
#include "hrg_gyro/core/resonator/averaged_resonator.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "core/testing/resonator_cases.h"
#include "core/testing/uniform_draws.h"
#include "hrg_gyro/core/common/units.h"
#include "hrg_gyro/core/signal/wave_estimator.h"

namespace hrg_gyro {
namespace core {
namespace {

TEST(ResonatorAveragedEquations, WaveFrameAndModalForcesAreInverses) {
  testing::UniformDraws u(7);
  for (int i = 0; i < 200; ++i) {
    const double theta = 4.0 * u(), tau = 4.0 * u(), w0 = 3000.0;
    WaveFrameForce w{u(), u(), u(), u()};
    const ModalForce f = toModalForce(w, std::cos(theta), std::sin(theta), std::cos(tau), std::sin(tau), w0);
    const WaveFrameForce back = toWaveFrame(f, std::cos(theta), std::sin(theta), std::cos(tau), std::sin(tau), w0);
    testing::expectNear(back, w, 1e-13);
  }
}

TEST(ResonatorAveragedEquations, IdealShellTurnsAtK0TimesTheBodyRateWhateverTheQuadratureAndForce) {
  ShellParameters p;  // no anisotropy: only the mean damping and the Coriolis coupling
  const AveragedResonator resonator(p);
  testing::UniformDraws u(11);
  for (int i = 0; i < 100; ++i) {
    const WaveParameters wave{1.0 + 0.2 * u(), 0.3 * u(), 5.0 * u(), 3.0 * u()};
    const double rate = 2.0 * u();
    // A force with no node-velocity or antinode-displacement part changes A and B only.
    const WaveFrameForce w{u(), 0.0, 0.0, u()};
    const ModalForce f = toModalForce(w, std::cos(wave.theta), std::sin(wave.theta), std::cos(wave.phase),
                                      std::sin(wave.phase), p.angularFrequency());
    const WaveRates r = resonator.rates(wave, rate, f, 0.0);
    EXPECT_NEAR(r.theta, p.scaleFactor() * rate, 1e-15);
    EXPECT_NEAR(r.phase, 0.0, 1e-15);
    EXPECT_NEAR(r.amplitude, -wave.amplitude / p.damping_time + w.antinode_velocity, 1e-15);
    EXPECT_NEAR(r.quadrature, -wave.quadrature / p.damping_time + w.node_displacement, 1e-15);
  }
}

// The oscillator of the header, integrated at the carrier: x, y and their rates.
struct Oscillator {
  ShellParameters p;
  double omega;  // body rate, rad/s
  ModalForce f;

  void derivative(const double* s, double t, double* d) const {
    const double w0 = p.angularFrequency(), k0 = p.scaleFactor(), h = p.damping_anisotropy;
    const double ct = std::cos(2.0 * p.damping_axis), st = std::sin(2.0 * p.damping_axis);
    const double cw = std::cos(2.0 * p.frequency_axis), sw = std::sin(2.0 * p.frequency_axis);
    const double x = s[0], y = s[1], vx = s[2], vy = s[3];
    const double c = std::cos(w0 * t), sn = std::sin(w0 * t);
    const double fx = f.x_re * c - f.x_im * sn, fy = f.y_re * c - f.y_im * sn;
    const double dw = p.frequency_split, inv_tau = 1.0 / p.damping_time;
    d[0] = vx;
    d[1] = vy;
    d[2] = fx - 2.0 * k0 * omega * vy - 2.0 * inv_tau * vx - h * (ct * vx + st * vy) - w0 * w0 * x -
           w0 * dw * (cw * x + sw * y);
    d[3] = fy + 2.0 * k0 * omega * vx - 2.0 * inv_tau * vy - h * (st * vx - ct * vy) - w0 * w0 * y -
           w0 * dw * (sw * x - cw * y);
  }
};

double wrapTo(double x, double period) { return x - period * std::round(x / period); }

struct Discrepancy {
  double epsilon = 0.0;  // the largest slow rate over w0
  double amplitude = 0.0, quadrature = 0.0, theta = 0.0, phase = 0.0;
  WaveParameters end;
};

// Every defect, the Coriolis coupling and a force fixed on the electrodes, large enough to move the
// slow variables by a good fraction in 1.5 s: the oscillator integrated at the carrier f0 (RK4, 256
// steps per period) and demodulated period by period, against the averaged equations over the same
// time. The force is scaled with f0 so that the slow motion is the same at every f0.
Discrepancy compare(double f0) {
  ShellParameters p;
  p.frequency = f0;
  p.bryan_factor = 0.28;
  p.damping_time = 4.0;
  p.damping_anisotropy = 0.15;
  p.damping_axis = 0.4;
  p.frequency_split = 0.4;
  p.frequency_axis = -0.7;
  const double w0 = p.angularFrequency(), scale = f0 / 200.0;
  const Oscillator osc{p, 1.2, ModalForce{300.0 * scale, -150.0 * scale, 80.0 * scale, 250.0 * scale}};
  const AveragedResonator resonator(p);
  WaveParameters slow{1.0, 0.05, 0.3, 0.2};

  // The oscillator starts on the wave: x = Re(X e^(i w0 t)), x' = Re(i w0 X e^(i w0 t)) at t = 0.
  const ChannelVector z0 = idealChannels(slow);  // Ac, Bc, As, Bs: X = Ac - i Bc, Y = As - i Bs
  double s[4] = {z0[kAc], z0[kAs], w0 * z0[kBc], w0 * z0[kBs]};
  const int n = 256, periods = static_cast<int>(std::lround(1.5 * f0));
  const double period = 1.0 / f0, dt = period / n;
  double max_rate = 0.0;
  Discrepancy worst;
  // The averaged equations by RK4 over half periods: the demodulated amplitudes are the mean over a
  // period, the slow state at its centre.
  const auto slow_step = [&](double h) {
    const auto at = [](const WaveParameters& x, const WaveRates& r, double f) {
      return WaveParameters{x.amplitude + f * r.amplitude, x.quadrature + f * r.quadrature, x.theta + f * r.theta,
                            x.phase + f * r.phase};
    };
    const WaveRates r1 = resonator.rates(slow, osc.omega, osc.f, 0.0);
    const WaveRates r2 = resonator.rates(at(slow, r1, 0.5 * h), osc.omega, osc.f, 0.0);
    const WaveRates r3 = resonator.rates(at(slow, r2, 0.5 * h), osc.omega, osc.f, 0.0);
    const WaveRates r4 = resonator.rates(at(slow, r3, h), osc.omega, osc.f, 0.0);
    max_rate =
        std::max({max_rate, std::abs(r1.amplitude), std::abs(r1.quadrature), std::abs(r1.theta), std::abs(r1.phase)});
    slow.amplitude += h / 6.0 * (r1.amplitude + 2.0 * r2.amplitude + 2.0 * r3.amplitude + r4.amplitude);
    slow.quadrature += h / 6.0 * (r1.quadrature + 2.0 * r2.quadrature + 2.0 * r3.quadrature + r4.quadrature);
    slow.theta += h / 6.0 * (r1.theta + 2.0 * r2.theta + 2.0 * r3.theta + r4.theta);
    slow.phase += h / 6.0 * (r1.phase + 2.0 * r2.phase + 2.0 * r3.phase + r4.phase);
  };
  for (int j = 0; j < periods; ++j) {
    // Demodulate the oscillator over period j (rectangle rule: exact for the carrier's harmonics).
    double xr = 0.0, xi = 0.0, yr = 0.0, yi = 0.0;
    for (int k = 0; k < n; ++k) {
      const double t = (j * n + k) * dt;
      xr += s[0] * std::cos(w0 * t);
      xi -= s[0] * std::sin(w0 * t);
      yr += s[1] * std::cos(w0 * t);
      yi -= s[1] * std::sin(w0 * t);
      double k1[4], k2[4], k3[4], k4[4], tmp[4];
      osc.derivative(s, t, k1);
      for (int m = 0; m < 4; ++m) tmp[m] = s[m] + 0.5 * dt * k1[m];
      osc.derivative(tmp, t + 0.5 * dt, k2);
      for (int m = 0; m < 4; ++m) tmp[m] = s[m] + 0.5 * dt * k2[m];
      osc.derivative(tmp, t + 0.5 * dt, k3);
      for (int m = 0; m < 4; ++m) tmp[m] = s[m] + dt * k3[m];
      osc.derivative(tmp, t + dt, k4);
      for (int m = 0; m < 4; ++m) s[m] += dt / 6.0 * (k1[m] + 2.0 * k2[m] + 2.0 * k3[m] + k4[m]);
    }
    ChannelVector z;
    z << 2.0 * xr / n, -2.0 * xi / n, 2.0 * yr / n, -2.0 * yi / n;
    slow_step(0.5 * period);
    WaveState est;
    EXPECT_EQ(estimateWave(z, WaveLimits(), &est), WaveStatus::kOk) << "period " << j;
    worst.amplitude = std::max(worst.amplitude, std::abs(est.amplitude - slow.amplitude));
    worst.quadrature = std::max(worst.quadrature, std::abs(est.quadrature - slow.quadrature));
    worst.theta = std::max(worst.theta, std::abs(wrapTo(est.theta - slow.theta, kPi)));
    worst.phase = std::max(worst.phase, std::abs(wrapTo(est.phase - slow.phase, kTwoPi)));
    slow_step(0.5 * period);
  }
  worst.epsilon = max_rate / w0;
  worst.end = slow;
  std::printf(
      "averaged vs oscillator, f0 %.0f Hz, %d periods: epsilon %.2e, |dA| %.2e, |dB| %.2e, |dtheta| %.2e rad, "
      "|dtau| %.2e rad\n",
      f0, periods, worst.epsilon, worst.amplitude, worst.quadrature, worst.theta, worst.phase);
  return worst;
}

// The averaged equations hold to first order in epsilon = (largest slow rate) / w0: at 200 Hz
// epsilon is 7.2e-4 and the slow variables differ from the oscillator's by at most 2.0e-4 (A),
// 6.1e-4 (B), 2.4e-4 rad (theta) and 3.8e-4 rad (tau), within the 2 epsilon allowed; at 400 Hz every
// difference is half (measured ratios 1.95 to 2.01). A sign or factor error in any term would
// move the state by that term's whole effect instead (0.1 to 0.5 here).
TEST(ResonatorAveragedEquations, FollowTheOscillatorTheyAverageToFirstOrder) {
  const Discrepancy d200 = compare(200.0), d400 = compare(400.0);
  EXPECT_GT(std::abs(d200.end.theta - 0.3), 0.5);  // the wave moved far in the slow variables
  EXPECT_GT(std::abs(d200.end.quadrature - 0.05), 0.05);
  EXPECT_LT(d200.amplitude, 2.0 * d200.epsilon);
  EXPECT_LT(d200.quadrature, 2.0 * d200.epsilon);
  EXPECT_LT(d200.theta, 2.0 * d200.epsilon);
  EXPECT_LT(d200.phase, 2.0 * d200.epsilon);
  // First order: the discrepancies halve with epsilon.
  EXPECT_NEAR(d200.epsilon / d400.epsilon, 2.0, 0.05);
  EXPECT_GT(d200.amplitude / d400.amplitude, 1.6);
  EXPECT_GT(d200.quadrature / d400.quadrature, 1.6);
  EXPECT_GT(d200.theta / d400.theta, 1.6);
  EXPECT_GT(d200.phase / d400.phase, 1.6);
}

}  // namespace
}  // namespace core
}  // namespace hrg_gyro

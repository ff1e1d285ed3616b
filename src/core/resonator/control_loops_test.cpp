// The loops on the averaged resonator: each settles its quantity at the speed it was designed for,
// and what its integrator has learned is the defect it works against.
#include "hrg_gyro/core/resonator/control_loops.h"

#include <gtest/gtest.h>

#include <cmath>

#include "core/testing/resonator_cases.h"
#include "hrg_gyro/core/common/units.h"
#include "hrg_gyro/core/resonator/resonator_dynamics.h"

namespace hrg_gyro {
namespace core {
namespace {

using testing::runResonator;

// A shell with a split and a damping anisotropy, an ideal drive: the loops see only the shell.
ShellParameters splitShell() {
  ShellParameters p;
  p.damping_time = 600.0;
  p.damping_anisotropy = 4e-5;
  p.damping_axis = 0.4;
  p.frequency_split = kTwoPi * 5e-3;
  p.frequency_axis = -0.7;
  return p;
}

TEST(ResonatorLoops, EnergyLoopRestoresTheSetpointAndItsEffortMeasuresTheDamping) {
  const ShellParameters p = splitShell();
  LoopSettings loops;
  ResonatorDynamics d(p, loops, DriveChainErrors(), {0.8, 0.0, 0.3, 0.3});  // E = 0.64, setpoint 1
  // A second-order loop of 5 Hz, damping ratio 0.707: the error's envelope falls as
  // exp(-zeta wn t) = exp(-22.2 t), so it is still about a tenth after 0.1 s and gone after 1.5 s.
  runResonator(&d, 0.1, 0.0, 0.0, false);
  const double early = std::abs(d.wave().amplitude * d.wave().amplitude - 1.0);
  EXPECT_GT(early, 1e-2);
  EXPECT_LT(early, 0.36);
  runResonator(&d, 1.4, 0.0, 0.0, false);
  const WaveParameters& w = d.wave();
  EXPECT_NEAR(w.amplitude * w.amplitude + w.quadrature * w.quadrature, 1.0, 1e-10);
  // dE/dt = 2A (-A/tau_d - (h/2) A cos d_d) + c: the integrator holds c = 2E (1/tau_d + (h/2) cos d_d).
  const double theta = w.theta;
  const double expected =
      2.0 * (1.0 / p.damping_time + 0.5 * p.damping_anisotropy * std::cos(2.0 * (theta - p.damping_axis)));
  EXPECT_NEAR(-loops.integralGain(loops.energy_bandwidth) * d.loops().energyIntegral(), expected, 1e-8 * expected);
}

TEST(ResonatorLoops, QuadratureLoopNullsBAndItsEffortMeasuresTheSplit) {
  const ShellParameters p = splitShell();
  LoopSettings loops;
  ResonatorDynamics d(p, loops, DriveChainErrors(), {1.0, 0.05, 0.2, 0.3});
  // 20 Hz: exp(-zeta wn t) = exp(-88.9 t).
  runResonator(&d, 0.02, 0.0, 0.0, false);
  EXPECT_GT(std::abs(d.wave().quadrature), 5e-3);
  runResonator(&d, 0.5, 0.0, 0.0, false);
  // Not exactly 0: the anisotropic damping turns the wave at 2e-5 rad/s, so the split's source moves
  // and the loop trails it by d(source)/dt / ki = Dw A 2e-5 / (2 pi 20 Hz)^2 = 4e-11.
  EXPECT_LT(std::abs(d.wave().quadrature), 1e-10);
  // dB/dt = (Dw/2) A sin 2(theta - theta_omega) + n_d: the effort cancels the split's source.
  const WaveParameters& w = d.wave();
  const double source = 0.5 * p.frequency_split * w.amplitude * std::sin(2.0 * (w.theta - p.frequency_axis));
  EXPECT_NEAR(loops.integralGain(loops.quadrature_bandwidth) * d.loops().quadratureIntegral(), source, 1e-9);
  EXPECT_NEAR(d.command().force.node_displacement, -source, 1e-9);
}

TEST(ResonatorLoops, PhaseLoopFollowsTheWavesOwnFrequency) {
  const ShellParameters p = splitShell();
  LoopSettings loops;
  ResonatorDynamics d(p, loops, DriveChainErrors(), {1.0, 0.0, 0.2, 0.25});  // 50 mrad from the setpoint
  runResonator(&d, 1.0, 0.0, 0.0, false);
  EXPECT_NEAR(d.wave().phase, loops.phase, 1e-10);  // trails the frequency's drift with theta, as above
  // A wave along theta rings at w0 + (Dw/2) cos 2(theta - theta_omega): the carrier follows it.
  const double offset = 0.5 * p.frequency_split * std::cos(2.0 * (d.wave().theta - p.frequency_axis));
  EXPECT_NEAR(d.referenceOffset(), offset, 1e-9);
  EXPECT_NEAR(d.referenceFrequency(), p.frequency + offset / kTwoPi, 1e-9);
}

TEST(ResonatorLoops, PrecessionTurnsAnIdealShellAtTheCommandedRate) {
  ShellParameters p;  // isotropic
  LoopSettings loops;
  ResonatorDynamics d(p, loops, DriveChainErrors(), {1.0, 0.02, 0.1, 0.3});
  runResonator(&d, 1.0, 0.0, 0.0, false);
  const double before = d.wave().theta;
  runResonator(&d, 2.0, 0.0, 1.5, false);
  EXPECT_NEAR(d.wave().theta - before, 3.0, 1e-12);
}

TEST(ResonatorLoops, AnOpenLoopLeavesItsQuantityToTheShell) {
  ShellParameters p;
  p.damping_time = 2.0;
  LoopSettings loops;
  loops.energy_bandwidth = 0.0;
  ResonatorDynamics d(p, loops, DriveChainErrors(), {1.0, 0.0, 0.1, 0.3});
  runResonator(&d, 1.0, 0.0, 0.0, false);
  EXPECT_NEAR(d.wave().amplitude, std::exp(-0.5), 1e-12);  // free decay at 1/tau_d
  EXPECT_EQ(d.command().force.antinode_velocity, 0.0);
}

TEST(ResonatorLoops, SettingsAreValidatedByName) {
  LoopSettings s;
  s.quadrature_bandwidth = 600.0;  // above control_rate / 10
  try {
    ControlLoops loops(s);
    FAIL() << "accepted a loop faster than a tenth of its control rate";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("quadrature_bandwidth"), std::string::npos) << e.what();
  }
  s = LoopSettings();
  s.energy = -1.0;
  EXPECT_THROW(ControlLoops{s}, std::invalid_argument);
  // The fastest loop allowed still settles (a sampled loop at a tenth of its rate).
  s = LoopSettings();
  s.quadrature_bandwidth = s.energy_bandwidth = s.phase_bandwidth = 0.1 * s.control_rate;
  ResonatorDynamics d(splitShell(), s, DriveChainErrors(), {1.0, 0.05, 0.2, 0.4});
  runResonator(&d, 0.2, 0.0, 0.0, false);
  EXPECT_LT(std::abs(d.wave().quadrature), 1e-12);
  EXPECT_NEAR(d.wave().phase, s.phase, 1e-12);
}

}  // namespace
}  // namespace core
}  // namespace hrg_gyro

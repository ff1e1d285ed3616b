// The drive chain's errors, each against the wave-frame force it should produce.
#include "hrg_gyro/core/resonator/drive_chain.h"

#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "core/testing/refusal.h"
#include "core/testing/resonator_cases.h"

namespace hrg_gyro {
namespace core {
namespace {

constexpr double kW0 = 31415.9;

WaveFrameForce throughChain(const DriveChainErrors& e, const WaveFrameForce& command, double theta, double tau) {
  const double ct = std::cos(theta), st = std::sin(theta), cp = std::cos(tau), sp = std::sin(tau);
  return toWaveFrame(DriveChain(e).realise(command, ct, st, cp, sp, kW0), ct, st, cp, sp, kW0);
}

TEST(ResonatorDriveChain, AnIdealChainRealisesTheCommand) {
  const WaveFrameForce c{0.3, -0.2, 0.7, 0.1};
  const WaveFrameForce f = throughChain(DriveChainErrors(), c, 0.9, -0.4);
  testing::expectNear(f, c, 1e-14);
}

TEST(ResonatorDriveChain, ForcerImbalanceTurnsAntinodeForceOntoTheNode) {
  DriveChainErrors e;
  e.gain_error_c = 3e-3;
  e.gain_error_s = -1e-3;
  const double g = 1e-3, gamma = 2e-3;
  for (double theta : {0.0, 0.4, 1.1, 2.0}) {
    WaveFrameForce c;
    c.antinode_velocity = 1.0;
    const WaveFrameForce f = throughChain(e, c, theta, 0.3);
    EXPECT_NEAR(f.antinode_velocity, 1.0 + g + gamma * std::cos(2.0 * theta), 1e-14);
    EXPECT_NEAR(f.node_velocity, -gamma * std::sin(2.0 * theta), 1e-14);
    EXPECT_NEAR(f.node_displacement, 0.0, 1e-14);
    // The precession command: realised as 1 + g - gamma cos 2theta.
    c = WaveFrameForce();
    c.node_velocity = 1.0;
    EXPECT_NEAR(throughChain(e, c, theta, 0.3).node_velocity, 1.0 + g - gamma * std::cos(2.0 * theta), 1e-14);
  }
}

TEST(ResonatorDriveChain, PhaseLagTurnsQuadratureEffortIntoPrecession) {
  DriveChainErrors e;
  e.phase_error = 2e-3;
  WaveFrameForce c;
  c.node_displacement = 1.0;
  const WaveFrameForce f = throughChain(e, c, 0.7, 1.2);
  EXPECT_NEAR(f.node_displacement, std::cos(2e-3), 1e-14);
  EXPECT_NEAR(f.node_velocity, -std::sin(2e-3), 1e-14);
  c = WaveFrameForce();
  c.antinode_velocity = 1.0;
  const WaveFrameForce a = throughChain(e, c, 0.7, 1.2);
  EXPECT_NEAR(a.antinode_velocity, std::cos(2e-3), 1e-14);
  EXPECT_NEAR(a.antinode_displacement, -std::sin(2e-3), 1e-14);  // the phase loop's to absorb
}

TEST(ResonatorDriveChain, PrecessionScaleErrorActsOnThePrecessionCommandAlone) {
  DriveChainErrors e;
  e.virtual_rate_gain_error = 5e-3;
  const WaveFrameForce f = throughChain(e, {0.3, 0.0, 0.7, 0.1}, 0.2, 0.1);
  EXPECT_NEAR(f.node_velocity, 0.7 * 1.005, 1e-14);
  EXPECT_NEAR(f.antinode_velocity, 0.3, 1e-14);
  EXPECT_NEAR(f.node_displacement, 0.1, 1e-14);
}

// The closed form the dynamics use is the chain through the electrodes, for a command placed with the
// wave's own angle and phase.
TEST(ResonatorDriveChain, OnTheWaveIsTheChainThroughTheElectrodes) {
  DriveChainErrors e;
  e.gain_error_c = 4e-3;
  e.gain_error_s = -3e-3;
  e.phase_error = 0.02;
  e.virtual_rate_gain_error = -6e-3;
  const DriveChain chain(e);
  for (double theta : {-2.0, 0.3, 0.9, 2.5}) {
    for (double tau : {-1.0, 0.3}) {
      const WaveFrameForce c{0.3, -0.2, 0.7, 0.1};
      const WaveFrameForce via = throughChain(e, c, theta, tau);
      const WaveFrameForce direct = chain.onWave(c, std::cos(2.0 * theta), std::sin(2.0 * theta));
      SCOPED_TRACE(theta);
      testing::expectNear(direct, via, 1e-14);
    }
  }
}

TEST(ResonatorDriveChain, ErrorsAreValidatedByName) {
  DriveChainErrors e;
  e.phase_error = 2.0;
  const std::string refused = refusal([&] { DriveChain chain(e); });  // a lag beyond pi/2
  EXPECT_NE(refused.find("phase_error"), std::string::npos) << refused;
  e = DriveChainErrors();
  e.gain_error_s = -1.0;
  EXPECT_THROW(DriveChain{e}, std::invalid_argument);
}

}  // namespace
}  // namespace core
}  // namespace hrg_gyro

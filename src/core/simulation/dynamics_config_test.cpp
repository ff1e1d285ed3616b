// The dynamics section of a scenario: defaults, the averaged resonator's settings and every bad key named.
#include "hrg_gyro/core/simulation/dynamics_config.h"

#include <gtest/gtest.h>

#include <string>

#include "hrg_gyro/core/simulation/simulation_config.h"

namespace hrg_gyro {
namespace core {
namespace {

const char* const kProfile = "turntable: {profile: [{type: dwell, duration: 1.0}]}\n";

SimulationConfig parse(const std::string& text) {
  return SimulationConfig::parse(YamlField(YAML::Load(std::string(kProfile) + text), ""));
}

std::string errorOf(const std::string& text) {
  try {
    parse(text);
  } catch (const ConfigError& e) {
    return e.what();
  }
  return "no error";
}

TEST(DynamicsConfigTest, HarmonicByDefault) {
  const SimulationConfig c = parse("");
  EXPECT_FALSE(c.dynamics.averaged());
  EXPECT_FALSE(parse("dynamics: {model: harmonic}\n").dynamics.averaged());
}

TEST(DynamicsConfigTest, AveragedTakesTheResonatorSectionsFrequencyAmplitudeAndPhase) {
  const SimulationConfig c = parse(
      "resonator: {frequency: 4000.0, amplitude: 0.8, phase: 0.5, drift: {orders: [], mean: 1.0e-6, cos: [], sin: "
      "[]}}\n"
      "dynamics:\n"
      "  model: averaged\n"
      "  shell: {bryan_factor: 0.3, damping_time: 500.0, damping_anisotropy: 2.0e-5, damping_axis: 0.1,\n"
      "          frequency_split: 0.01, frequency_axis: -0.2}\n"
      "  loops: {energy_bandwidth: 4.0, quadrature_bandwidth: 15.0, phase_bandwidth: 10.0, damping_ratio: 0.8,\n"
      "          control_rate: 8000.0}\n"
      "  drive: {gain_error_c: 1.0e-3, gain_error_s: -1.0e-3, phase_error: 2.0e-3, virtual_rate_gain_error: 1.0e-3}\n"
      "  settle_time: 1.5\n"
      "  commands: [{time: 0.5, rate: 0.2}, {time: 0.75, rate: -0.2}]\n");
  const DynamicsConfig& d = c.dynamics;
  ASSERT_TRUE(d.averaged());
  EXPECT_EQ(d.shell.frequency, 4000.0);
  EXPECT_EQ(d.shell.bryan_factor, 0.3);
  EXPECT_EQ(d.shell.damping_time, 500.0);
  EXPECT_EQ(d.shell.damping_anisotropy, 2e-5);
  EXPECT_EQ(d.shell.frequency_axis, -0.2);
  EXPECT_DOUBLE_EQ(d.loops.energy, 0.64);
  EXPECT_EQ(d.loops.phase, 0.5);
  EXPECT_EQ(d.loops.control_rate, 8000.0);
  EXPECT_EQ(d.loops.damping_ratio, 0.8);
  EXPECT_EQ(d.drive.phase_error, 2e-3);
  EXPECT_EQ(d.drive.virtual_rate_gain_error, 1e-3);
  EXPECT_EQ(d.settle_time, 1.5);
  ASSERT_EQ(d.commands.size(), 2u);
  EXPECT_EQ(d.commands[1].time, 0.75);
  EXPECT_EQ(d.commands[1].rate, -0.2);
  // The shell's K replaces the given one; the quadrature loop holds B at 0; the added drift stays.
  EXPECT_DOUBLE_EQ(c.resonator.scale_factor.meanAt(NAN), -0.6);
  EXPECT_EQ(c.resonator.quadrature, 0.0);
  EXPECT_EQ(c.resonator.drift.meanAt(NAN), 1e-6);
}

TEST(DynamicsConfigTest, BadKeysAreNamed) {
  EXPECT_NE(errorOf("dynamics: {model: lumped}").find("dynamics.model"), std::string::npos);
  EXPECT_NE(errorOf("dynamics: {model: averaged, shel: {}}").find("shel"), std::string::npos);
  EXPECT_NE(errorOf("dynamics: {model: averaged, shell: {damping_time: -1.0}}").find("dynamics.shell"),
            std::string::npos);
  EXPECT_NE(errorOf("dynamics: {model: averaged, shell: {damping_time: -1.0}}").find("damping_time"),
            std::string::npos);
  EXPECT_NE(errorOf("dynamics: {model: averaged, loops: {quadrature_bandwidth: 900.0}}").find("quadrature_bandwidth"),
            std::string::npos);
  EXPECT_NE(errorOf("dynamics: {model: averaged, loops: {control_rate: 7000.0}}").find("dynamics.loops.control_rate"),
            std::string::npos);
  EXPECT_NE(errorOf("dynamics: {model: averaged, drive: {phase_error: 2.0}}").find("dynamics.drive"),
            std::string::npos);
  EXPECT_NE(errorOf("dynamics: {model: averaged, commands: [{time: 1.0, rate: 0.1}, {time: 1.0, rate: 0.2}]}")
                .find("dynamics.commands[1].time"),
            std::string::npos);
  EXPECT_NE(errorOf("dynamics: {model: averaged, commands: [{time: 1.0, rat: 0.1}]}").find("rat"), std::string::npos);
  EXPECT_NE(errorOf("dynamics: {model: averaged, settle_time: -1.0}").find("dynamics.settle_time"), std::string::npos);
  EXPECT_NE(errorOf("dynamics: {shell: {damping_time: 500.0}}").find("model: averaged"), std::string::npos);
  // One description of each quantity.
  EXPECT_NE(
      errorOf("resonator: {scale_factor: {mean: -0.5}}\ndynamics: {model: averaged}").find("resonator.scale_factor"),
      std::string::npos);
  EXPECT_NE(errorOf("resonator: {quadrature: 0.01}\ndynamics: {model: averaged}").find("resonator.quadrature"),
            std::string::npos);
  EXPECT_NE(
      errorOf(
          "thermal: {reference_temperature: 25.0, start_temperature: 25.0, profile: [{type: hold, duration: 1.0}]}\n"
          "dynamics: {model: averaged}")
          .find("thermal"),
      std::string::npos);
}

}  // namespace
}  // namespace core
}  // namespace hrg_gyro

// How a scenario's wave moves: the `dynamics` section. By default (model: harmonic, or no section)
// the simulator integrates d theta/dt = K(theta) Omega + D(theta) with the resonator section's given
// harmonic K and D. With model: averaged it steps the resonator from its equations of motion instead
// (core/resonator: the shell's defects, its control loops and the imperfect drive chain), so that K,
// D and the gain of the virtual precession follow from the defects; the precession loop then takes a
// commanded virtual rate, from the section's schedule or from a driver's command topic.
//
// The shell's mean frequency is the resonator section's `frequency`, the energy loop holds
// E = amplitude^2 and the phase loop holds tau at its `phase`: one gyro, described once.
#pragma once

#include <vector>

#include "hrg_gyro/core/common/yaml_field.h"
#include "hrg_gyro/core/resonator/control_loops.h"
#include "hrg_gyro/core/resonator/drive_chain.h"
#include "hrg_gyro/core/resonator/shell_parameters.h"

namespace hrg_gyro {
namespace core {

enum class DynamicsModel {
  kHarmonic,  ///< the given K(theta) and D(theta) (resonator.scale_factor, resonator.drift)
  kAveraged,  ///< the averaged resonator with its loops (core/resonator)
};

/// From `time` (s from the scenario start) the precession loop turns the wave at `rate` (electrical
/// rad/s, as commanded: the drive chain realises it with its own gain) until the next command.
struct ScheduledPrecession {
  double time = 0.0;
  double rate = 0.0;
};

struct DynamicsConfig {
  DynamicsModel model = DynamicsModel::kHarmonic;
  ShellParameters shell;  ///< frequency: the resonator section's
  LoopSettings loops;     ///< energy and phase setpoints: the resonator section's amplitude^2 and phase
  DriveChainErrors drive;
  /// s the loops run at rest before the first sample (not output): the session starts locked, as a
  /// gyro that has been running does.
  double settle_time = 2.0;
  std::vector<ScheduledPrecession> commands;  ///< time strictly increasing

  bool averaged() const { return model == DynamicsModel::kAveraged; }
};

/// Parses the `dynamics` section; `frequency`, `amplitude` and `phase` are the resonator section's.
/// Throws ConfigError naming the key (every setting is validated as the resonator core validates it).
DynamicsConfig parseDynamicsSection(const YamlField& section, double frequency, double amplitude, double phase);

}  // namespace core
}  // namespace hrg_gyro

// A simulation scenario: the gyro (resonator, pickoffs), the turntable profile, the generator
// sweep and, optionally, the temperature (temperature_dependence.h). The keys are those of the driver_sim node's
// private parameters, so one YAML file serves `roslaunch` (rosparam load into ~) and `hrg_bag simulate` alike.
// Defaults: the shipped simulated gyro (docs/simulation.md).
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "hrg_gyro/core/common/yaml_field.h"
#include "hrg_gyro/core/model/harmonic_model.h"
#include "hrg_gyro/core/signal/pickoff_array.h"
#include "hrg_gyro/core/simulation/dynamics_config.h"
#include "hrg_gyro/core/simulation/stream_delivery.h"
#include "hrg_gyro/core/simulation/temperature_dependence.h"
#include "hrg_gyro/core/simulation/turntable_log.h"
#include "hrg_gyro/core/simulation/turntable_profile.h"

namespace hrg_gyro {
namespace core {

/// A turn-on bias that wanders through the session, as a warming gyro's does:
///   D0(t) = D0 + rate t + random_walk B(t),
/// t s since the scenario start (generator sweep included), B a standard Wiener process. The wander
/// adds to d theta/dt like D does (it is not scaled by K). Off (zeros) by default.
struct BiasDriftConfig {
  double rate = 0.0;         ///< rad/s per s: the linear trend of D0
  double random_walk = 0.0;  ///< rad/s/sqrt(s): D0's random walk, its std grows as random_walk sqrt(t)

  bool enabled() const { return rate != 0.0 || random_walk != 0.0; }
  /// The trend's part of the wander at t s from the scenario start, rad/s.
  double trendAt(double t) const { return rate * t; }
};

/// A scenario's `resonator` section: the simulated gyro's carrier and sampling, the wave it holds and
/// its given K(theta) and D(theta). Not the shell's physics (resonator/shell_parameters.h, the
/// `dynamics.shell` section), which the averaged dynamics use instead of the given K and D.
struct ResonatorConfig {
  double frequency = 5000.0;          ///< Hz
  int samples_per_period = 32;        ///< N >= 8
  int periods_per_output = 5;         ///< periods demodulated into one output sample (5 -> 1 kHz)
  double amplitude = 1.0;             ///< A, amplitude units
  double quadrature = 0.02;           ///< B, held by the quadrature loop
  double phase = 0.3;                 ///< tau, rad
  double initial_theta = 0.0;         ///< electrical rad
  HarmonicModel scale_factor{-0.56};  ///< intrinsic K(theta) of the resonator (Bryan factor and its anisotropy)
  HarmonicModel drift{0.0};           ///< intrinsic D(theta), rad/s
  /// White noise of the body rate the resonator senses (angle random walk), rad/sqrt(s); the
  /// pickoff noise gives white *angle* noise instead. 0: none.
  double rate_noise = 0.0;
  BiasDriftConfig bias_drift;  ///< a wandering D0 (default: none)
};

struct GeneratorConfig {
  bool enabled = false;  ///< sweep known waves instead of running the dynamics
  int angles = 24;       ///< theta evenly over [0, pi)
  std::vector<double> quadratures{0.0, 0.05, -0.05};
  std::vector<double> phases{0.0, 1.0};  ///< rad
  double dwell = 0.05;                   ///< s per generator state
};

/// Speed ripple of the table drive (TurntableProfile::setRipple): the true rate is the commanded
/// rate times 1 + amplitude sin(2 pi frequency t + phase). Off (amplitude 0) by default.
struct TableRippleConfig {
  double amplitude = 0.0;  ///< fraction of the commanded rate
  double frequency = 0.0;  ///< Hz
  double phase = 0.0;      ///< rad at the profile start
};

struct SimulationConfig {
  std::uint64_t seed = 1;
  double start_time = 1.0;  ///< s: stamp of the first instant (ROS treats time 0 as unset)
  ResonatorConfig resonator;
  PickoffDefects pickoff;
  double latitude = 0.0;      ///< rad
  double acceleration = 0.5;  ///< rad/s^2 of the turntable
  TurntableProfile profile;   ///< commanded motion; the simulator adds `ripple` to it
  TableRippleConfig ripple;
  TurntableLogConfig turntable_log;  ///< what the table controller logs (default: the exact state)
  DeliveryConfig channels;           ///< lost channel-amplitude samples (default: none)
  GeneratorConfig generator;
  ThermalConfig thermal;  ///< disabled unless the scenario has a thermal section
  /// How the wave moves (dynamics_config.h): the given K and D by default, or the averaged resonator
  /// with its loops. With the latter, resonator.scale_factor is K0 = -2 k of the shell and
  /// resonator.quadrature 0 (the quadrature loop holds B at 0); resonator.drift adds to the shell's.
  DynamicsConfig dynamics;

  double outputPeriod() const { return resonator.periods_per_output / resonator.frequency; }

  /// Parses a scenario. `extra_keys` are accepted (and ignored) at the top level: the ROS-only
  /// parameters of the driver_sim node. Throws ConfigError naming the key.
  static SimulationConfig parse(const YamlField& root, const std::vector<std::string>& extra_keys = {});
  /// Reads and parses a scenario file: only a regular file of at most kMaxScenarioFileBytes (a
  /// FIFO, a device or a directory is refused at once, never opened in a way that could block).
  static SimulationConfig load(const std::string& path, const std::vector<std::string>& extra_keys = {});
};

/// The sections one simulated gyro is made of, as a scenario writes them (a triad scenario gives one of
/// each per axis). Each throws ConfigError naming the key. `amplitude`: the resonator's A, since the
/// pickoff section gives the electrode gap as A/d0.
ResonatorConfig parseResonatorSection(const YamlField& resonator);
PickoffDefects parsePickoffSection(const YamlField& pickoff, double amplitude);
/// The `dynamics` section of `parent` (a single gyro's scenario, or a triad's axis), its resonator
/// section already read into *resonator: with model: averaged the shell's K and the loops' B = 0
/// replace the resonator's (a given resonator.scale_factor or quadrature is refused by name).
DynamicsConfig parseDynamicsOf(const YamlField& parent, ResonatorConfig* resonator);
TableRippleConfig parseRippleSection(const YamlField& ripple);
DeliveryConfig parseChannelDeliverySection(const YamlField& channels);

/// A scenario's top level, as the single gyro's and the triad's are read: a map of `keys` and
/// `extra_keys` only (any other refused), its `seed` (>= 0, default 1) and `start_time` (> 0 s,
/// default `*start_time`). Throws ConfigError naming the key.
void parseScenarioTopLevel(const YamlField& root, std::vector<std::string> keys,
                           const std::vector<std::string>& extra_keys, std::uint64_t* seed, double* start_time);

/// A scenario file's YAML document: only a regular file of at most kMaxScenarioFileBytes (a FIFO, a
/// device or a directory is refused at once), a syntax error reported with its line. Throws ConfigError.
YAML::Node loadScenarioDocument(const std::string& path);

/// Largest scenario file read. The scenarios of config/scenarios are below 6 KiB; a turntable
/// profile of ten thousand pieces is below 1 MiB.
constexpr std::size_t kMaxScenarioFileBytes = std::size_t{4} << 20;

/// The scenario with its gyro frozen at one temperature: amplitude, pickoff defects and intrinsic K
/// and D taken at `temperature`, thermal section disabled (the sampling frequency stays f0). The
/// exact injected model at that temperature is computeEffectiveModel() of the result. Without a
/// thermal section the scenario is returned unchanged.
SimulationConfig atTemperature(const SimulationConfig& config, double temperature);

/// Parameters of driver_sim that only the ROS node reads; scenario files may carry them.
const std::vector<std::string>& nodeOnlyScenarioKeys();

}  // namespace core
}  // namespace hrg_gyro

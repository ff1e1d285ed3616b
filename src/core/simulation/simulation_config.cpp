#include "hrg_gyro/core/simulation/simulation_config.h"

#include <cmath>

#include "hrg_gyro/core/common/number_format.h"
#include "hrg_gyro/core/common/yaml_file.h"
#include "hrg_gyro/core/model/earth_rate.h"
#include "hrg_gyro/core/model/parameter_file.h"

namespace hrg_gyro {
namespace core {

const std::vector<std::string>& nodeOnlyScenarioKeys() {
  static const std::vector<std::string> keys = {
      "time_scale",   "clock_period",       "frame_id",   "publish_clock", "wait_for_subscribers",
      "wait_timeout", "shutdown_when_done", "queue_size", "max_lag",       "pace_topic",
      "max_lead",     "pace_timeout"};
  return keys;
}

namespace {

/// The limits the resonator and pickoff sections enforce must hold at every temperature of the
/// profile; the defects are linear in T, so checking both extremes suffices.
void checkThermalLimits(const SimulationConfig& c, const YamlField& section) {
  const ThermalConfig& t = c.thermal;
  const ResonatorConfig& rc = c.resonator;
  // The coefficient keys may be absent (0): name them by path rather than through the node.
  const std::string coefficients = section.path() + ".coefficients";
  for (const double temperature : {t.profile.minimum(), t.profile.maximum()}) {
    const std::string at = " at " + formatDouble(temperature) + " degC of the profile";
    if (!(t.frequencyAt(temperature, rc.frequency) > 0.0)) {
      throw ConfigError(section.path() + ".frequency_coefficient", "the resonance frequency becomes non-positive" + at);
    }
    const GyroAtTemperature g =
        gyroAtTemperature(t, temperature, rc.frequency, rc.amplitude, c.pickoff, rc.scale_factor, rc.drift);
    if (!(g.amplitude > 0.0) || !(std::abs(rc.quadrature) < 0.5 * g.amplitude) ||
        !(g.amplitude / c.pickoff.gap < 0.5)) {
      throw ConfigError(coefficients + ".amplitude", "the amplitude A = " + formatDouble(g.amplitude) +
                                                         " leaves the valid range (A > 2|B|, A/d0 < 0.5)" + at);
    }
    for (int i = 0; i < kPickoffCount; ++i) {
      const std::string index = "[" + std::to_string(i) + "]";
      if (std::abs(g.pickoff.misplacement[i]) > 0.1) {
        throw ConfigError(coefficients + ".misplacement" + index, "misplacement exceeds 0.1 rad" + at);
      }
      if (std::abs(g.pickoff.gain_error[i]) >= 0.5) {
        throw ConfigError(coefficients + ".gain_error" + index, "gain error reaches 0.5" + at);
      }
    }
    double harmonics = 0.0;
    const HarmonicModel& k = g.scale_factor;
    for (Eigen::Index r = 1; r < k.nodeValues().rows(); ++r) harmonics += std::abs(k.nodeValues()(r, 0));
    const double k0 = k.meanAt(NAN);
    if (!(k0 < 0.0) || harmonics >= 0.5 * std::abs(k0)) {
      throw ConfigError(coefficients + ".scale_factor", "K0 must stay negative and its harmonics below |K0|/2" + at);
    }
  }
}

BiasDriftConfig parseBiasDrift(const YamlField& section) {
  section.requireMap();
  section.rejectUnknownKeys({"rate", "random_walk"});
  BiasDriftConfig c;
  c.rate = section.getDouble("rate", 0.0);
  if (!std::isfinite(c.rate)) section["rate"].fail("must be finite (rad/s per s)");
  c.random_walk = section.getDouble("random_walk", 0.0);
  if (!(std::isfinite(c.random_walk) && c.random_walk >= 0.0)) {
    section["random_walk"].fail("must be >= 0 (rad/s/sqrt(s))");
  }
  return c;
}

}  // namespace

SimulationConfig atTemperature(const SimulationConfig& config, double temperature) {
  if (!config.thermal.enabled) return config;
  SimulationConfig c = config;
  const ResonatorConfig& rc = config.resonator;
  GyroAtTemperature g = gyroAtTemperature(config.thermal, temperature, rc.frequency, rc.amplitude, config.pickoff,
                                          rc.scale_factor, rc.drift);
  c.resonator.amplitude = g.amplitude;
  c.resonator.scale_factor = std::move(g.scale_factor);
  c.resonator.drift = std::move(g.drift);
  c.pickoff = g.pickoff;
  c.thermal = ThermalConfig();
  return c;
}

ResonatorConfig parseResonatorSection(const YamlField& r) {
  r.rejectUnknownKeys({"frequency", "samples_per_period", "periods_per_output", "amplitude", "quadrature", "phase",
                       "initial_theta", "scale_factor", "drift", "rate_noise", "bias_drift"});
  ResonatorConfig rc;
  rc.frequency = r.getDouble("frequency", rc.frequency);
  if (!(rc.frequency > 0.0)) r["frequency"].fail("must be positive (Hz)");
  rc.samples_per_period = static_cast<int>(r.getInteger("samples_per_period", rc.samples_per_period));
  if (rc.samples_per_period < 8 || rc.samples_per_period > 4096) {
    r["samples_per_period"].fail("must be in [8, 4096]: fewer than 8 samples alias the pickoff nonlinearity");
  }
  rc.periods_per_output = static_cast<int>(r.getInteger("periods_per_output", rc.periods_per_output));
  if (rc.periods_per_output < 1) r["periods_per_output"].fail("must be >= 1");
  rc.amplitude = r.getDouble("amplitude", rc.amplitude);
  if (!(rc.amplitude > 0.0)) r["amplitude"].fail("must be positive");
  rc.quadrature = r.getDouble("quadrature", rc.quadrature);
  if (!(std::abs(rc.quadrature) < 0.5 * rc.amplitude)) r["quadrature"].fail("|B| must stay below A/2");
  rc.phase = r.getDouble("phase", rc.phase);
  rc.initial_theta = r.getDouble("initial_theta", rc.initial_theta);
  if (r.has("scale_factor")) rc.scale_factor = parseScaleFactorModel(r["scale_factor"]);
  if (r.has("drift")) rc.drift = parseDriftModel(r["drift"]);
  rc.rate_noise = r.getDouble("rate_noise", 0.0);
  if (rc.rate_noise < 0.0) r["rate_noise"].fail("must be >= 0 (rad/sqrt(s))");
  if (r.has("bias_drift")) rc.bias_drift = parseBiasDrift(r["bias_drift"]);
  return rc;
}

PickoffDefects parsePickoffSection(const YamlField& p, double amplitude) {
  p.rejectUnknownKeys({"misplacement", "gain_error", "amplitude_to_gap", "noise"});
  PickoffDefects d;
  if (p.has("misplacement")) {
    const auto v = p["misplacement"].asDoubles(kPickoffCount);
    for (int i = 0; i < kPickoffCount; ++i) {
      if (std::abs(v[i]) > 0.1) p["misplacement"].at(i).fail("misplacement above 0.1 rad is not a small defect");
      d.misplacement[i] = v[i];
    }
  }
  if (p.has("gain_error")) {
    const auto v = p["gain_error"].asDoubles(kPickoffCount);
    for (int i = 0; i < kPickoffCount; ++i) {
      if (std::abs(v[i]) > 0.5) p["gain_error"].at(i).fail("gain error must be in (-0.5, 0.5)");
      d.gain_error[i] = v[i];
    }
  }
  const double ratio = p.getDouble("amplitude_to_gap", 0.0);
  if (ratio < 0.0 || ratio >= 0.5) p["amplitude_to_gap"].fail("A/d0 must be in [0, 0.5)");
  d.gap = ratio > 0.0 ? amplitude / ratio : INFINITY;
  d.noise = p.getDouble("noise", 0.0);
  if (d.noise < 0.0) p["noise"].fail("must be >= 0");
  return d;
}

TableRippleConfig parseRippleSection(const YamlField& r) {
  r.requireMap();
  r.rejectUnknownKeys({"amplitude", "frequency", "phase"});
  TableRippleConfig c;
  c.amplitude = r.getDouble("amplitude", 0.0);
  if (!(c.amplitude >= 0.0 && c.amplitude < 1.0))
    r["amplitude"].fail("must be in [0, 1): a fraction of the commanded rate");
  c.frequency = r.getDouble("frequency", 0.0);
  if (c.amplitude > 0.0 && !(std::isfinite(c.frequency) && c.frequency > 0.0)) {
    r["frequency"].fail("must be positive (Hz) when the ripple has an amplitude");
  }
  c.phase = r.getDouble("phase", 0.0);
  if (!std::isfinite(c.phase)) r["phase"].fail("must be finite (rad)");
  return c;
}

DeliveryConfig parseChannelDeliverySection(const YamlField& ch) {
  ch.requireMap();
  ch.rejectUnknownKeys({"drop_probability", "gaps", "stamp_glitches"});
  return DeliveryConfig::parse(ch);
}

YAML::Node loadScenarioDocument(const std::string& path) {
  return loadYamlFile(path, kMaxScenarioFileBytes, "scenario file");
}

void parseScenarioTopLevel(const YamlField& root, std::vector<std::string> keys,
                           const std::vector<std::string>& extra_keys, std::uint64_t* seed, double* start_time) {
  root.requireMap();
  keys.insert(keys.end(), extra_keys.begin(), extra_keys.end());
  root.rejectUnknownKeys(keys);
  const long s = root.getInteger("seed", 1);
  if (s < 0) root["seed"].fail("must be >= 0");
  *seed = static_cast<std::uint64_t>(s);
  *start_time = root.getDouble("start_time", *start_time);
  if (!(*start_time > 0.0)) root["start_time"].fail("must be positive (time 0 means 'unset' in ROS)");
}

DynamicsConfig parseDynamicsOf(const YamlField& parent, ResonatorConfig* resonator) {
  if (!parent.has("dynamics")) return DynamicsConfig();
  const DynamicsConfig d =
      parseDynamicsSection(parent["dynamics"], resonator->frequency, resonator->amplitude, resonator->phase);
  if (!d.averaged()) return d;
  // One description of each quantity: the shell's K and the loops' B = 0 replace the given ones.
  if (parent.has("resonator") && parent["resonator"].has("scale_factor")) {
    parent["resonator"]["scale_factor"].fail("the averaged resonator's K follows from dynamics.shell.bryan_factor");
  }
  if (parent.has("resonator") && parent["resonator"].has("quadrature")) {
    parent["resonator"]["quadrature"].fail("the averaged resonator's quadrature loop holds B at 0");
  }
  resonator->scale_factor = HarmonicModel(d.shell.scaleFactor());
  resonator->quadrature = 0.0;
  return d;
}

SimulationConfig SimulationConfig::parse(const YamlField& root, const std::vector<std::string>& extra_keys) {
  SimulationConfig c;
  parseScenarioTopLevel(
      root, {"seed", "start_time", "resonator", "pickoff", "turntable", "generator", "thermal", "channels", "dynamics"},
      extra_keys, &c.seed, &c.start_time);

  if (root.has("resonator")) c.resonator = parseResonatorSection(root["resonator"]);
  if (root.has("pickoff")) c.pickoff = parsePickoffSection(root["pickoff"], c.resonator.amplitude);

  if (root.has("generator")) {
    const YamlField g = root["generator"];
    g.rejectUnknownKeys({"enabled", "angles", "quadratures", "phases", "dwell"});
    GeneratorConfig& gc = c.generator;
    gc.enabled = g.getBool("enabled", gc.enabled);
    gc.angles = static_cast<int>(g.getInteger("angles", gc.angles));
    if (gc.angles < 2) g["angles"].fail("need at least 2 angles over [0, pi)");
    if (g.has("quadratures")) gc.quadratures = g["quadratures"].asDoubles();
    if (g.has("phases")) gc.phases = g["phases"].asDoubles();
    if (gc.quadratures.empty()) g["quadratures"].fail("need at least one value");
    if (gc.phases.empty()) g["phases"].fail("need at least one value");
    gc.dwell = g.getDouble("dwell", gc.dwell);
    if (!(gc.dwell > 0.0)) g["dwell"].fail("must be positive");
  }

  if (root.has("turntable")) {
    const YamlField t = root["turntable"];
    t.rejectUnknownKeys({"latitude", "acceleration", "profile", "ripple", "log"});
    c.latitude = t.getDouble("latitude", 0.0);
    if (!validLatitude(c.latitude)) t["latitude"].fail(kLatitudeRule);
    c.acceleration = t.getDouble("acceleration", c.acceleration);
    if (!(c.acceleration > 0.0)) t["acceleration"].fail("must be positive (rad/s^2)");
    if (t.has("profile")) c.profile = TurntableProfile::parse(t["profile"], c.acceleration);
    if (t.has("ripple")) c.ripple = parseRippleSection(t["ripple"]);
    if (t.has("log")) c.turntable_log = TurntableLogConfig::parse(t["log"]);
  }
  if (root.has("channels")) c.channels = parseChannelDeliverySection(root["channels"]);
  if (root.has("thermal")) {
    c.thermal = ThermalConfig::parse(root["thermal"]);
    checkThermalLimits(c, root["thermal"]);
  }
  c.dynamics = parseDynamicsOf(root, &c.resonator);
  if (c.dynamics.averaged() && c.thermal.enabled) root["thermal"].fail("not available with dynamics.model: averaged");
  if (!c.generator.enabled && c.profile.pieces().empty()) {
    throw ConfigError("turntable.profile", "missing: give a turntable profile (or enable the generator)");
  }
  return c;
}

SimulationConfig SimulationConfig::load(const std::string& path, const std::vector<std::string>& extra_keys) {
  return parse(YamlField(loadScenarioDocument(path), ""), extra_keys);
}

}  // namespace core
}  // namespace hrg_gyro

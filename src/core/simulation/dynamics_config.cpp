#include "hrg_gyro/core/simulation/dynamics_config.h"

#include <cmath>
#include <initializer_list>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "hrg_gyro/core/common/number_format.h"

namespace hrg_gyro {
namespace core {
namespace {

/// The resonator core validates its settings with messages naming the field; the section's path is
/// put in front so that the scenario's key is named in full.
template <class Settings>
void validateIn(const YamlField& section, const Settings& settings) {
  try {
    settings.validate();
  } catch (const std::invalid_argument& e) {
    section.fail(e.what());
  }
}

/// A section of numbers: a map of `fields`' keys only, each read over the default it points to.
void readNumbers(const YamlField& section, std::initializer_list<std::pair<const char*, double*>> fields) {
  section.requireMap();
  std::vector<std::string> keys;
  for (const auto& f : fields) keys.push_back(f.first);
  section.rejectUnknownKeys(keys);
  for (const auto& f : fields) *f.second = section.getDouble(f.first, *f.second);
}

}  // namespace

DynamicsConfig parseDynamicsSection(const YamlField& d, double frequency, double amplitude, double phase) {
  d.requireMap();
  d.rejectUnknownKeys({"model", "shell", "loops", "drive", "settle_time", "commands"});
  DynamicsConfig c;
  const std::string model = d.getString("model", "harmonic");
  if (model == "averaged") {
    c.model = DynamicsModel::kAveraged;
  } else if (model != "harmonic") {
    d["model"].fail("must be harmonic (the given K and D) or averaged (the resonator with its loops)");
  }
  c.shell.frequency = frequency;
  if (d.has("shell")) {
    const YamlField s = d["shell"];
    readNumbers(s, {{"bryan_factor", &c.shell.bryan_factor},
                    {"damping_time", &c.shell.damping_time},
                    {"damping_anisotropy", &c.shell.damping_anisotropy},
                    {"damping_axis", &c.shell.damping_axis},
                    {"frequency_split", &c.shell.frequency_split},
                    {"frequency_axis", &c.shell.frequency_axis}});
    validateIn(s, c.shell);
  }
  c.loops.energy = amplitude * amplitude;
  c.loops.phase = phase;
  if (d.has("loops")) {
    const YamlField l = d["loops"];
    readNumbers(l, {{"energy_bandwidth", &c.loops.energy_bandwidth},
                    {"quadrature_bandwidth", &c.loops.quadrature_bandwidth},
                    {"phase_bandwidth", &c.loops.phase_bandwidth},
                    {"damping_ratio", &c.loops.damping_ratio},
                    {"control_rate", &c.loops.control_rate}});
    validateIn(l, c.loops);
  }
  // The simulator steps the resonator per carrier period, the loops a whole number of times in each.
  const double per_period = std::round(c.loops.control_rate / frequency);
  if (c.averaged() &&
      (per_period < 1.0 || std::abs(per_period * frequency - c.loops.control_rate) > 1e-9 * c.loops.control_rate)) {
    const std::string what = "must be a whole multiple of the resonator frequency (" + std::to_string(frequency) +
                             " Hz): the simulator steps the loops a whole number of times per carrier period";
    if (d.has("loops") && d["loops"].has("control_rate")) d["loops"]["control_rate"].fail(what);
    d.fail("loops.control_rate (default 5000 Hz) " + what);
  }
  if (c.averaged() && c.loops.quadrature_bandwidth <= 0.0 && c.shell.frequency_split != 0.0) {
    d.fail("a frequency split needs the quadrature loop closed (quadrature_bandwidth > 0)");
  }
  if (d.has("drive")) {
    const YamlField r = d["drive"];
    readNumbers(r, {{"gain_error_c", &c.drive.gain_error_c},
                    {"gain_error_s", &c.drive.gain_error_s},
                    {"phase_error", &c.drive.phase_error},
                    {"virtual_rate_gain_error", &c.drive.virtual_rate_gain_error}});
    validateIn(r, c.drive);
  }
  c.settle_time = d.getDouble("settle_time", c.settle_time);
  if (!(c.settle_time >= 0.0 && c.settle_time <= 600.0)) d["settle_time"].fail("must be in [0, 600] s");
  if (d.has("commands")) {
    const YamlField list = d["commands"];
    list.requireSequence();
    for (std::size_t i = 0; i < list.size(); ++i) {
      const YamlField e = list.at(i);
      e.requireMap();
      e.rejectUnknownKeys({"time", "rate"});
      ScheduledPrecession p;
      p.time = e["time"].asDouble();
      p.rate = e["rate"].asDouble();
      if (!(p.time >= 0.0)) e["time"].fail("must be >= 0 (s from the scenario start)");
      if (!c.commands.empty() && !(p.time > c.commands.back().time))
        e["time"].fail("must increase from command to command");
      if (!(std::abs(p.rate) <= kMaxPrecessionRate)) {
        e["rate"].fail("must be within +-" + formatShort(kMaxPrecessionRate) + " rad/s (electrical)");
      }
      c.commands.push_back(p);
    }
  }
  if (!c.averaged() && (d.has("shell") || d.has("loops") || d.has("drive") || d.has("commands"))) {
    d.fail("shell, loops, drive and commands describe the averaged resonator: set model: averaged");
  }
  return c;
}

}  // namespace core
}  // namespace hrg_gyro

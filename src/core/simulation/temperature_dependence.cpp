#include "hrg_gyro/core/simulation/temperature_dependence.h"

#include <cmath>
#include <map>

#include "hrg_gyro/core/model/parameter_file.h"

namespace hrg_gyro {
namespace core {

HarmonicModel combineModels(const HarmonicModel& a, double frequency, const HarmonicModel& b, double s) {
  std::vector<double> ca(a.termCount()), cb(b.termCount());
  a.coefficientsAt(frequency, ca.data());
  b.coefficientsAt(NAN, cb.data());
  // Union of the orders, each with its (cos, sin) sum.
  std::map<int, std::pair<double, double>> terms;
  const std::size_t na = a.orders().size(), nb = b.orders().size();
  for (std::size_t i = 0; i < na; ++i) {
    auto& t = terms[a.orders()[i]];
    t.first += ca[1 + i];
    t.second += ca[1 + na + i];
  }
  for (std::size_t i = 0; i < nb; ++i) {
    auto& t = terms[b.orders()[i]];
    t.first += s * cb[1 + i];
    t.second += s * cb[1 + nb + i];
  }
  std::vector<int> orders;
  std::vector<double> cos, sin;
  for (const auto& kv : terms) {
    orders.push_back(kv.first);
    cos.push_back(kv.second.first);
    sin.push_back(kv.second.second);
  }
  return HarmonicModel(orders, ca[0] + s * cb[0], cos, sin);
}

GyroAtTemperature gyroAtTemperature(const ThermalConfig& thermal, double temperature, double nominal_frequency,
                                    double amplitude, const PickoffDefects& pickoff, const HarmonicModel& k,
                                    const HarmonicModel& d) {
  const ThermalCoefficients& c = thermal.coefficients;
  const double dt = temperature - thermal.reference_temperature;
  GyroAtTemperature g;
  g.temperature = temperature;
  g.frequency = thermal.frequencyAt(temperature, nominal_frequency);
  g.amplitude = amplitude * (1.0 + c.amplitude * dt);
  g.pickoff = pickoff;
  for (int i = 0; i < kPickoffCount; ++i) {
    g.pickoff.misplacement[i] += c.misplacement[i] * dt;
    g.pickoff.gain_error[i] += c.gain_error[i] * dt;
  }
  g.scale_factor = combineModels(k, g.frequency, c.scale_factor, dt);
  g.drift = combineModels(d, g.frequency, c.drift, dt);
  return g;
}

ThermalConfig ThermalConfig::parse(const YamlField& section) {
  section.requireMap();
  section.rejectUnknownKeys(
      {"reference_temperature", "start_temperature", "frequency_coefficient", "profile", "coefficients"});
  ThermalConfig t;
  t.enabled = true;
  t.reference_temperature = section.getDouble("reference_temperature", t.reference_temperature);
  if (std::abs(t.reference_temperature) > 200.0) section["reference_temperature"].fail("must be in [-200, 200] degC");
  const double start = section.getDouble("start_temperature", t.reference_temperature);
  if (start < -100.0 || start > 200.0) section["start_temperature"].fail("must be in [-100, 200] degC");
  t.frequency_coefficient = section.getDouble("frequency_coefficient", 0.0);
  if (std::abs(t.frequency_coefficient) > 100.0) {
    section["frequency_coefficient"].fail("above 100 Hz/degC in magnitude: not a resonator (units are Hz/degC)");
  }
  t.profile = section.has("profile") ? TemperatureProfile::parse(section["profile"], start) : TemperatureProfile(start);
  if (section.has("coefficients")) {
    const YamlField c = section["coefficients"];
    c.requireMap();
    c.rejectUnknownKeys({"amplitude", "misplacement", "gain_error", "scale_factor", "drift"});
    ThermalCoefficients& tc = t.coefficients;
    tc.amplitude = c.getDouble("amplitude", 0.0);
    if (std::abs(tc.amplitude) > 0.01) c["amplitude"].fail("above 1 %/degC in magnitude is implausible (1/degC)");
    for (const char* key : {"misplacement", "gain_error"}) {
      if (!c.has(key)) continue;
      const std::vector<double> v = c[key].asDoubles(kPickoffCount);
      auto& out = std::string(key) == "misplacement" ? tc.misplacement : tc.gain_error;
      for (int i = 0; i < kPickoffCount; ++i) {
        if (std::abs(v[i]) > 1e-3) c[key].at(i).fail("above 1e-3 per degC in magnitude is implausible");
        out[i] = v[i];
      }
    }
    for (const char* key : {"scale_factor", "drift"}) {
      if (!c.has(key)) continue;
      const HarmonicModel m = parseDriftModel(c[key]);
      if (m.frequencyDependent()) c[key]["frequency_nodes"].fail("a temperature coefficient is frequency independent");
      (std::string(key) == "scale_factor" ? tc.scale_factor : tc.drift) = m;
    }
  }
  return t;
}

}  // namespace core
}  // namespace hrg_gyro

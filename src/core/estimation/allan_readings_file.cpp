#include "hrg_gyro/core/estimation/allan_readings_file.h"

#include <yaml-cpp/yaml.h>

#include <cmath>

#include "hrg_gyro/core/common/yaml_field.h"
#include "hrg_gyro/core/common/yaml_file.h"

namespace hrg_gyro {
namespace core {
namespace {

/// The largest readings file read (a few hundred bytes when written here).
constexpr std::size_t kMaxAllanFileBytes = 64 * 1024;

struct Term {
  const char* key;
  NoiseReading AllanResult::*reading;
};
// In the order written: Q rad, N rad/sqrt(s), B rad/s, K rad/s/sqrt(s).
const Term kTerms[] = {{"angle_white_noise", &AllanResult::angle_white_noise},
                       {"angle_random_walk", &AllanResult::angle_random_walk},
                       {"bias_instability", &AllanResult::bias_instability},
                       {"rate_random_walk", &AllanResult::rate_random_walk}};

NoiseReading parseReading(const YamlField& f) {
  f.requireMap();
  f.rejectUnknownKeys({"identified", "value", "tau_min", "tau_max"});
  NoiseReading r;
  r.identified = f["identified"].asBool();
  r.value = f["value"].asDouble();
  r.tau_min = f["tau_min"].asDouble();
  r.tau_max = f["tau_max"].asDouble();
  if (r.value < 0.0) f["value"].fail("must be at least 0");
  if (r.identified && !(r.value > 0.0)) f["value"].fail("an identified reading must be positive");
  return r;
}

void emitReadings(YAML::Emitter& y, const AllanResult& result) {
  for (const Term& t : kTerms) {
    const NoiseReading& r = result.*t.reading;
    y << YAML::Key << t.key << YAML::Value << YAML::Flow << YAML::BeginMap;
    y << YAML::Key << "identified" << YAML::Value << r.identified;
    y << YAML::Key << "value" << YAML::Value << r.value;
    y << YAML::Key << "tau_min" << YAML::Value << r.tau_min;
    y << YAML::Key << "tau_max" << YAML::Value << r.tau_max;
    y << YAML::EndMap;
  }
}

}  // namespace

AllanResult worstOfAxes(const std::vector<AxisAllanReadings>& axes) {
  AllanResult out;
  for (const AxisAllanReadings& a : axes) {
    for (const Term& t : kTerms) {
      const NoiseReading& r = a.result.*t.reading;
      NoiseReading& w = out.*t.reading;
      if (r.identified && (!w.identified || r.value > w.value)) w = r;
    }
  }
  return out;
}

std::string allanReadingsYaml(const AllanReadings& readings) {
  YAML::Emitter y;
  y.SetDoublePrecision(17);
  y << YAML::BeginMap;
  y << YAML::Key << "samples" << YAML::Value << readings.samples;
  y << YAML::Key << "tau0" << YAML::Value << readings.tau0;
  y << YAML::Key << "record_length" << YAML::Value << readings.tau0 * static_cast<double>(readings.samples);
  emitReadings(y, readings.result);
  if (!readings.axes.empty()) {
    y << YAML::Key << "axes" << YAML::Value << YAML::BeginMap;
    for (const AxisAllanReadings& a : readings.axes) {
      y << YAML::Key << a.axis << YAML::Value << YAML::BeginMap;
      emitReadings(y, a.result);
      y << YAML::EndMap;
    }
    y << YAML::EndMap;
  }
  y << YAML::EndMap;
  return std::string("# hrg_bag allan readings, SI: Q rad, N rad/sqrt(s), B rad/s, K rad/s/sqrt(s); tau in s.\n") +
         y.c_str() + "\n";
}

AllanReadings loadAllanReadings(const std::string& path) {
  const YAML::Node node = loadYamlFile(path, kMaxAllanFileBytes, "Allan readings file");
  try {
    const YamlField root(node, "");
    root.requireMap();
    root.rejectUnknownKeys({"samples", "tau0", "record_length", "angle_white_noise", "angle_random_walk",
                            "bias_instability", "rate_random_walk", "axes"});
    AllanReadings out;
    const long samples = root["samples"].asInteger();
    if (samples < 0) root["samples"].fail("must be at least 0");
    out.samples = static_cast<std::size_t>(samples);
    out.tau0 = root["tau0"].asDouble();
    if (!(out.tau0 > 0.0)) root["tau0"].fail("must be positive (s)");
    for (const Term& t : kTerms) out.result.*t.reading = parseReading(root[t.key]);
    if (root.has("axes")) {
      const YamlField axes = root["axes"];
      axes.requireMap();
      for (const std::string& name : {"x", "y", "z"}) {
        if (!axes.has(name)) continue;
        AxisAllanReadings a;
        a.axis = name;
        const YamlField f = axes[name];
        f.requireMap();
        for (const Term& t : kTerms) a.result.*t.reading = parseReading(f[t.key]);
        out.axes.push_back(a);
      }
      axes.rejectUnknownKeys({"x", "y", "z"});
    }
    return out;
  } catch (const ConfigError& e) {
    throw ConfigError(e.key(), e.problem() + " (in '" + path + "')");
  }
}

}  // namespace core
}  // namespace hrg_gyro

#include "hrg_gyro/core/calibration/calibration_settings.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "hrg_gyro/core/common/number_format.h"
#include "hrg_gyro/core/common/units.h"
#include "hrg_gyro/core/model/earth_rate.h"
#include "hrg_gyro/core/resonator/first_order_model.h"

namespace hrg_gyro {
namespace core {
namespace {

std::vector<int> parseEvenOrders(const YamlField& f) {
  std::vector<int> out;
  const auto raw = f.asIntegers();
  for (std::size_t i = 0; i < raw.size(); ++i) {
    if (raw[i] < 2 || raw[i] > 64 || raw[i] % 2 != 0) f.at(i).fail("orders must be even, in [2, 64]");
    if (!out.empty() && raw[i] <= out.back()) f.at(i).fail("orders must be strictly increasing");
    out.push_back(static_cast<int>(raw[i]));
  }
  return out;
}

// The keys, listed once: parse() refuses any other, keyPaths() lists them for the node's template check.
const std::vector<std::string> kPlateauKeys = {"rate_tolerance", "relative_tolerance", "settle_time",   "static_rate",
                                               "max_gap",        "max_rate",           "smoothing_span"};
const std::vector<std::string> kGateKeys = {
    "min_coverage",     "min_rate_separation", "max_rate_noise",        "max_table_error",
    "min_samples",      "max_condition",       "max_relative_residual", "max_k0_change",
    "max_harmonic_std", "min_steps",           "min_dwell_time",        "min_pairs",
    "max_p_condition",  "max_trend_inflation", "max_trend_k0_std"};
const std::vector<std::string> kTableClockKeys = {"offset", "regularise", "window", "max_jitter", "max_offset"};
const std::vector<std::string> kThermalKeys = {"frequency_nodes", "node_count", "interpolation", "slice_width",
                                               "max_slices"};
const std::vector<std::string> kFieldKeys = {"gain_orders",    "rate",         "turns",
                                             "directions",     "rest",         "axis_earth_rate",
                                             "resonator",      "min_turns",    "max_excess_scatter",
                                             "max_gain_error", "max_drift_std"};
const std::vector<std::string> kScalarKeys = {
    "method",         "scale_factor_orders", "drift_orders",    "bins",
    "window",         "window_span",         "group_tolerance", "auto_finish_idle",
    "backward_reset", "bias_trend_order",    "forward_jump",    "jump_persist"};
// Former names parse() still reads, left out of keyPaths(): the template gives the current name only.
const std::vector<std::string> kFormerKeys = {"backward_persist"};

double positive(const YamlField& parent, const char* key, double fallback) {
  const double v = parent.getDouble(key, fallback);
  if (!(v > 0.0)) parent[key].fail("must be positive");
  return v;
}

// field/resonator: 'unknown', or the gyro's shell, loops and drive under the names of a scenario's
// dynamics section (which may be pasted whole: its other keys are read and checked too). Every value
// the lag's prediction uses is required, so that nothing unknown is taken for zero.
std::optional<FieldResonator> parseFieldResonator(const YamlField& r, double rate) {
  if (r.node().IsScalar() && r.node().Scalar() == "unknown") return std::nullopt;
  if (!r.isMap()) r.fail("must be 'unknown' or a map of shell, loops and drive (as in a scenario's dynamics section)");
  r.rejectUnknownKeys({"shell", "loops", "drive"});
  FieldResonator g;
  struct Key {
    const char* name;
    double* value;
    bool required;
  };
  const auto read = [&r](const char* section, std::initializer_list<Key> keys) {
    const YamlField m = r[section];
    m.requireMap();
    std::vector<std::string> names;
    for (const Key& k : keys) names.push_back(k.name);
    m.rejectUnknownKeys(names);
    for (const Key& k : keys) *k.value = k.required ? m[k.name].asDouble() : m.getDouble(k.name, *k.value);
    return m;
  };
  const YamlField shell = read("shell", {{"frequency_split", &g.shell.frequency_split, true},
                                         {"frequency_axis", &g.shell.frequency_axis, true},
                                         {"damping_anisotropy", &g.shell.damping_anisotropy, true},
                                         {"damping_axis", &g.shell.damping_axis, true},
                                         {"bryan_factor", &g.shell.bryan_factor, false},
                                         {"damping_time", &g.shell.damping_time, false}});
  const YamlField loops = read("loops", {{"quadrature_bandwidth", &g.loops.quadrature_bandwidth, true},
                                         {"energy_bandwidth", &g.loops.energy_bandwidth, true},
                                         {"damping_ratio", &g.loops.damping_ratio, true},
                                         {"control_rate", &g.loops.control_rate, true},
                                         {"phase_bandwidth", &g.loops.phase_bandwidth, false}});
  const YamlField drive = read("drive", {{"gain_error_c", &g.drive.gain_error_c, true},
                                         {"gain_error_s", &g.drive.gain_error_s, true},
                                         {"phase_error", &g.drive.phase_error, true},
                                         {"virtual_rate_gain_error", &g.drive.virtual_rate_gain_error, false}});
  const auto check = [](const YamlField& where, const auto& validate) {
    try {
      validate();
    } catch (const std::invalid_argument& e) {
      where.fail(e.what());
    }
  };
  check(shell, [&] { g.shell.validate(); });
  check(loops, [&] { g.loops.validate(); });
  check(drive, [&] { g.drive.validate(); });
  check(r, [&] { precessionLagDrift(g.shell, g.loops, g.drive, rate); });
  return g;
}

/// The keys at the top level: the method, the fitted orders, the windows and the stamp rule.
void parseTopLevelKeys(const YamlField& root, CalibrationSettings* s) {
  if (root.has("method")) {
    try {
      s->method = parseCalibrationMethod(root["method"].asString());
    } catch (const std::invalid_argument& e) {
      root["method"].fail(e.what());
    }
  }
  if (root.has("scale_factor_orders")) s->scale_factor_orders = parseEvenOrders(root["scale_factor_orders"]);
  if (root.has("drift_orders")) s->drift_orders = parseEvenOrders(root["drift_orders"]);
  s->bias_trend_order = static_cast<int>(root.getInteger("bias_trend_order", s->bias_trend_order));
  if (s->bias_trend_order < 0 || s->bias_trend_order > 2) root["bias_trend_order"].fail("must be 0, 1 or 2");
  s->bins = static_cast<int>(root.getInteger("bins", s->bins));
  if (s->bins < 8 || s->bins > 4096) root["bins"].fail("must be in [8, 4096]");
  s->window = positive(root, "window", s->window);
  s->window_span = positive(root, "window_span", s->window_span);
  s->group_tolerance = positive(root, "group_tolerance", s->group_tolerance);
  s->auto_finish_idle = root.getDouble("auto_finish_idle", s->auto_finish_idle);
  s->backward_reset = positive(root, "backward_reset", s->backward_reset);
  s->forward_jump = positive(root, "forward_jump", s->forward_jump);
  if (s->forward_jump > 600.0) root["forward_jump"].fail("must be at most 600 s");
  // jump_persist, once backward_persist (before it applied to forward jumps too): either name, not both.
  const char* persist_key = root.has("backward_persist") ? "backward_persist" : "jump_persist";
  if (root.has("backward_persist") && root.has("jump_persist")) {
    root["backward_persist"].fail("is the former name of jump_persist: give one of them");
  }
  s->jump_persist = static_cast<int>(root.getInteger(persist_key, s->jump_persist));
  if (s->jump_persist < 1 || s->jump_persist > 1000) root[persist_key].fail("must be in [1, 1000]");
}

/// plateau/: how the plateau detector judges the rotation's records.
void parsePlateauKeys(const YamlField& p, CalibrationSettings* s) {
  p.rejectUnknownKeys(kPlateauKeys);
  s->plateau.rate_tolerance = positive(p, "rate_tolerance", s->plateau.rate_tolerance);
  s->plateau.relative_tolerance = p.getDouble("relative_tolerance", s->plateau.relative_tolerance);
  if (s->plateau.relative_tolerance < 0.0) p["relative_tolerance"].fail("must be >= 0");
  s->plateau.settle_time = p.getDouble("settle_time", s->plateau.settle_time);
  if (s->plateau.settle_time < 0.0) p["settle_time"].fail("must be >= 0");
  s->plateau.static_rate = positive(p, "static_rate", s->plateau.static_rate);
  s->plateau.max_gap = positive(p, "max_gap", s->plateau.max_gap);
  s->plateau.max_rate = positive(p, "max_rate", s->plateau.max_rate);
  // Records wait half the span to be judged; wave samples wait for them at most a minute.
  s->plateau.smoothing_span = p.getDouble("smoothing_span", s->plateau.smoothing_span);
  if (!(s->plateau.smoothing_span >= 0.0 && s->plateau.smoothing_span <= 20.0))
    p["smoothing_span"].fail("must be in [0, 20] s");
}

/// gates/: the quality limits.
void parseGateKeys(const YamlField& g, CalibrationSettings* s) {
  g.rejectUnknownKeys(kGateKeys);
  QualityLimits& q = s->gates;
  q.min_coverage = g.getDouble("min_coverage", q.min_coverage);
  if (q.min_coverage < 0.0 || q.min_coverage > 1.0) g["min_coverage"].fail("must be in [0, 1]");
  q.min_rate_separation = positive(g, "min_rate_separation", q.min_rate_separation);
  q.max_rate_noise = positive(g, "max_rate_noise", q.max_rate_noise);
  q.max_table_error = positive(g, "max_table_error", q.max_table_error);
  const long min_samples = g.getInteger("min_samples", static_cast<long>(q.min_samples));
  if (min_samples < 0) g["min_samples"].fail("must be >= 0");
  q.min_samples = static_cast<std::uint64_t>(min_samples);
  q.max_condition = positive(g, "max_condition", q.max_condition);
  q.max_relative_residual = positive(g, "max_relative_residual", q.max_relative_residual);
  q.max_k0_change = positive(g, "max_k0_change", q.max_k0_change);
  q.max_harmonic_std = positive(g, "max_harmonic_std", q.max_harmonic_std);
  q.min_steps = static_cast<int>(g.getInteger("min_steps", q.min_steps));
  if (q.min_steps < 2) g["min_steps"].fail("must be >= 2");
  q.min_dwell_time = g.getDouble("min_dwell_time", q.min_dwell_time);
  const long min_pairs = g.getInteger("min_pairs", static_cast<long>(q.min_pairs));
  if (min_pairs < 2) g["min_pairs"].fail("must be >= 2");
  q.min_pairs = static_cast<std::uint64_t>(min_pairs);
  q.max_p_condition = positive(g, "max_p_condition", q.max_p_condition);
  q.max_trend_inflation = g.getDouble("max_trend_inflation", q.max_trend_inflation);
  if (!(q.max_trend_inflation >= 1.0)) g["max_trend_inflation"].fail("must be >= 1 (a factor on K0's standard error)");
  q.max_trend_k0_std = positive(g, "max_trend_k0_std", q.max_trend_k0_std);
}

/// table_clock/: the table's clock against the gyro's.
void parseTableClockKeys(const YamlField& c, CalibrationSettings* s) {
  c.rejectUnknownKeys(kTableClockKeys);
  TableClockSettings& tc = s->table_clock;
  tc.offset = c.getDouble("offset", tc.offset);
  if (!(std::abs(tc.offset) <= 3600.0)) c["offset"].fail("must be a finite number of seconds, |offset| <= 3600");
  tc.regularise = c.getBool("regularise", tc.regularise);
  tc.window = c.getDouble("window", tc.window);
  if (!(tc.window >= 1.0 && tc.window <= 600.0)) c["window"].fail("must be in [1, 600] s");
  tc.max_jitter = positive(c, "max_jitter", tc.max_jitter);
  tc.max_offset = positive(c, "max_offset", tc.max_offset);
}

/// field/: the field method's plan and gates.
void parseFieldKeys(const YamlField& f, CalibrationSettings* s) {
  f.requireMap();
  f.rejectUnknownKeys(kFieldKeys);
  FieldSettings& fs = s->field;
  if (f.has("gain_orders")) fs.gain_orders = parseEvenOrders(f["gain_orders"]);
  fs.rate = f.getDouble("rate", fs.rate);
  if (!(fs.rate >= FieldSettings::kMinRate && fs.rate <= kMaxPrecessionRate)) {
    f["rate"].fail("must be in [" + formatShort(FieldSettings::kMinRate) + ", " + formatShort(kMaxPrecessionRate) +
                   "] rad/s (electrical)");
  }
  fs.turns = f.getDouble("turns", fs.turns);
  if (!(fs.turns > 0.0 && fs.turns <= FieldSettings::kMaxTurns))
    f["turns"].fail("must be in (0, 100] full turns per segment");
  if (f.has("directions")) {
    const YamlField d = f["directions"];
    const auto raw = d.asIntegers();
    fs.directions.clear();
    for (std::size_t i = 0; i < raw.size(); ++i) {
      if (raw[i] != 1 && raw[i] != -1) d.at(i).fail("must be 1 or -1 (the sign of the commanded rate)");
      fs.directions.push_back(static_cast<int>(raw[i]));
    }
    if (fs.directions.size() > FieldSettings::kMaxDirections) d.fail("at most 16 segments");
    if (std::find(fs.directions.begin(), fs.directions.end(), 1) == fs.directions.end() ||
        std::find(fs.directions.begin(), fs.directions.end(), -1) == fs.directions.end()) {
      d.fail("need both signs (1 and -1): the two directions separate D from the gain, one alone is refused");
    }
  }
  if (f.has("axis_earth_rate")) {
    const YamlField a = f["axis_earth_rate"];
    const char* problem = "must be 'vertical' or the Earth's rate about the sensitive axis in rad/s (|x| <= 7.29e-5)";
    if (a.node().IsScalar() && a.node().Scalar() == "vertical") {
      fs.axis_earth_rate = NAN;
    } else {
      try {
        fs.axis_earth_rate = a.asDouble();
      } catch (const ConfigError&) {
        a.fail(problem);
      }
      if (!(std::abs(fs.axis_earth_rate) <= kEarthRotationRate * (1.0 + 1e-6))) a.fail(problem);
    }
  }
  fs.rest = f.getDouble("rest", fs.rest);
  if (!(fs.rest >= 0.0 && fs.rest <= FieldSettings::kMaxRest)) f["rest"].fail("must be in [0, 600] s");
  if (f.has("resonator")) fs.resonator = parseFieldResonator(f["resonator"], fs.rate);
  fs.min_turns = f.getDouble("min_turns", fs.min_turns);
  if (!(fs.min_turns >= 0.0)) f["min_turns"].fail("must be >= 0");
  fs.max_excess_scatter = f.getDouble("max_excess_scatter", fs.max_excess_scatter);
  if (!(fs.max_excess_scatter >= 1.0)) f["max_excess_scatter"].fail("must be >= 1 (a ratio of scatters)");
  fs.max_gain_error = positive(f, "max_gain_error", fs.max_gain_error);
  fs.max_drift_std = positive(f, "max_drift_std", fs.max_drift_std);
}

/// thermal/: the thermal method's frequency nodes and slices.
void parseThermalKeys(const YamlField& t, CalibrationSettings* s) {
  t.rejectUnknownKeys(kThermalKeys);
  ThermalSettings& ts = s->thermal;
  if (t.has("frequency_nodes")) {
    const YamlField nf = t["frequency_nodes"];
    ts.frequency_nodes = nf.asDoubles();
    if (ts.frequency_nodes.size() == 1) nf.fail("give at least 2 nodes, or none for automatic nodes (node_count)");
    for (std::size_t j = 0; j < ts.frequency_nodes.size(); ++j) {
      if (!(ts.frequency_nodes[j] > 0.0)) nf.at(j).fail("frequency must be positive (Hz)");
      if (j > 0 && !(ts.frequency_nodes[j] > ts.frequency_nodes[j - 1]))
        nf.at(j).fail("nodes must be strictly increasing");
    }
  }
  ts.node_count = static_cast<int>(t.getInteger("node_count", ts.node_count));
  if (ts.node_count < 2 || ts.node_count > 32) t["node_count"].fail("must be in [2, 32]");
  if (t.has("interpolation") && !parseInterpolation(t["interpolation"].asString(), &ts.interpolation)) {
    t["interpolation"].fail("expected natural_cubic_spline or piecewise_linear");
  }
  ts.slice_width = positive(t, "slice_width", ts.slice_width);
  ts.max_slices = static_cast<int>(t.getInteger("max_slices", ts.max_slices));
  if (ts.max_slices < 1 || ts.max_slices > 100000) t["max_slices"].fail("must be in [1, 100000]");
}

}  // namespace

std::vector<std::string> CalibrationSettings::keyPaths() {
  std::vector<std::string> keys = kScalarKeys;
  for (const std::string& k : kPlateauKeys) keys.push_back("plateau/" + k);
  for (const std::string& k : kGateKeys) keys.push_back("gates/" + k);
  for (const std::string& k : kThermalKeys) keys.push_back("thermal/" + k);
  for (const std::string& k : kTableClockKeys) keys.push_back("table_clock/" + k);
  for (const std::string& k : kFieldKeys) keys.push_back("field/" + k);
  return keys;
}

std::vector<std::string> CalibrationSettings::formerKeyPaths() { return kFormerKeys; }

StampRule CalibrationSettings::stampRule() const {
  StampRule r;
  r.backward_reset = backward_reset;
  r.forward_jump = forward_jump;
  r.persist = jump_persist;
  return r;
}

CalibrationSettings CalibrationSettings::parse(const YamlField& root, const std::vector<std::string>& extra_keys) {
  CalibrationSettings s;
  root.requireMap();
  std::vector<std::string> allowed = kScalarKeys;
  allowed.insert(allowed.end(), kFormerKeys.begin(), kFormerKeys.end());
  allowed.insert(allowed.end(), {"plateau", "gates", "thermal", "table_clock", "field"});
  allowed.insert(allowed.end(), extra_keys.begin(), extra_keys.end());
  root.rejectUnknownKeys(allowed);
  parseTopLevelKeys(root, &s);
  if (root.has("plateau")) parsePlateauKeys(root["plateau"], &s);
  if (root.has("gates")) parseGateKeys(root["gates"], &s);
  if (root.has("table_clock")) parseTableClockKeys(root["table_clock"], &s);
  if (root.has("field")) parseFieldKeys(root["field"], &s);
  // The plan's keys are each bounded; so is the whole plan (with the plateau's settle time) when it will run.
  if (s.method == CalibrationMethodKind::kField) {
    const std::string problem = fieldPlanLengthProblem(s);
    if (!problem.empty()) throw ConfigError("field", problem);
  }
  if (root.has("thermal")) parseThermalKeys(root["thermal"], &s);
  return s;
}

double fieldSegmentDuration(const CalibrationSettings& s) {
  const double sweep = s.field.turns * kTwoPi / s.field.rate;
  return s.plateau.settle_time + sweep + 0.5 * s.plateau.smoothing_span + 1.0;
}

double fieldPlanDuration(const CalibrationSettings& s) {
  return s.field.rest + static_cast<double>(s.field.directions.size()) * fieldSegmentDuration(s);
}

std::string fieldPlanLengthProblem(const CalibrationSettings& s) {
  const double total = fieldPlanDuration(s);
  if (total <= kMaxFieldPlanDuration) return "";
  return "the plan lasts " + formatShort(total, 3) + " s (rest " + formatShort(s.field.rest, 3) + " s + " +
         std::to_string(s.field.directions.size()) + " segments of " + formatShort(fieldSegmentDuration(s), 3) +
         " s: plateau settle time + turns x 2 pi / rate + 1.5 s), more than " + formatShort(kMaxFieldPlanDuration, 6) +
         " s (a day): fewer turns or directions, a faster rate or a shorter rest";
}

}  // namespace core
}  // namespace hrg_gyro

#include "hrg_gyro/core/model/parameter_file.h"

#include <cmath>
#include <cstring>
#include <stdexcept>
#include <vector>

#include "hrg_gyro/core/common/atomic_file.h"
#include "hrg_gyro/core/common/number_format.h"
#include "hrg_gyro/core/model/earth_rate.h"

namespace hrg_gyro {
namespace core {
namespace {

enum class ModelKind { kScaleFactor, kDrift };

constexpr int kMaxHarmonicOrder = 64;

std::vector<int> parseOrders(const YamlField& f) {
  std::vector<int> orders;
  const auto raw = f.asIntegers();
  for (std::size_t i = 0; i < raw.size(); ++i) {
    const long k = raw[i];
    const YamlField item = f.at(i);
    if (k < 2 || k > kMaxHarmonicOrder) item.fail("harmonic order must be in [2, 64], got " + std::to_string(k));
    if (k % 2 != 0) {
      item.fail("harmonic order " + std::to_string(k) +
                " is odd: theta is defined modulo pi, so K and D have even harmonics only");
    }
    if (!orders.empty() && k <= orders.back()) item.fail("orders must be strictly increasing");
    orders.push_back(static_cast<int>(k));
  }
  return orders;
}

/// Per-node values of a coefficient: a number (one node) or a list with one value per node.
std::vector<double> parseNodeValues(const YamlField& f, std::size_t nodes) {
  if (nodes == 1) return {f.asDouble()};
  if (!f.isSequence()) f.fail("expected a list of " + std::to_string(nodes) + " values (one per frequency node)");
  return f.asDoubles(nodes);
}

// The frequency nodes and their interpolation; a frequency-independent interpolator without the key.
FrequencyInterpolator parseInterpolator(const YamlField& f) {
  if (!f.has("frequency_nodes")) {
    if (f.has("interpolation")) f["interpolation"].fail("only meaningful together with frequency_nodes");
    return FrequencyInterpolator();
  }
  const YamlField nf = f["frequency_nodes"];
  // Before any per-node work: the spline set-up and the overshoot check cost the cube of the count.
  if (nf.isSequence() && nf.size() > kMaxFrequencyNodes) {
    nf.fail("at most " + std::to_string(kMaxFrequencyNodes) + " frequency nodes, got " + std::to_string(nf.size()));
  }
  const std::vector<double> nodes = nf.asDoubles();
  if (nodes.size() < 2) nf.fail("give at least 2 frequency nodes, or omit the key for a frequency-independent model");
  for (std::size_t j = 0; j < nodes.size(); ++j) {
    if (!(nodes[j] > 0.0)) nf.at(j).fail("frequency must be positive (Hz)");
    if (j > 0 && !(nodes[j] > nodes[j - 1])) nf.at(j).fail("frequency nodes must be strictly increasing");
  }
  Interpolation kind_of_interp = Interpolation::kNaturalCubicSpline;
  if (f.has("interpolation") && !parseInterpolation(f["interpolation"].asString(), &kind_of_interp)) {
    f["interpolation"].fail("expected natural_cubic_spline or piecewise_linear");
  }
  return FrequencyInterpolator(nodes, kind_of_interp);
}

// The limits a model's coefficients at one frequency (mean, then n cos and n sin) are held to: K must
// keep its sign and D stay plausible. `where` says at which node or between which nodes.
void checkCoefficients(const YamlField& f, ModelKind kind, const Eigen::VectorXd& v, std::size_t n,
                       const std::string& where) {
  const double m0 = v(0);
  double harmonics = 0.0;
  for (std::size_t r = 1; r < 1 + 2 * n; ++r) harmonics += std::abs(v(r));
  if (!std::isfinite(m0) || !std::isfinite(harmonics)) f.fail("coefficients overflow" + where);
  if (kind == ModelKind::kScaleFactor) {
    if (m0 == 0.0) f["mean"].fail("K0 must be non-zero" + where);
    if (m0 > 0.0) {
      f["mean"].fail("K0 must be negative (electrical wave angle lags the body rotation, K0 = -2k); got " +
                     formatDouble(m0) + where);
    }
    if (std::abs(m0) < kMinScaleFactorMagnitude || std::abs(m0) > kMaxScaleFactorMagnitude) {
      f["mean"].fail("|K0| must be in [" + formatDouble(kMinScaleFactorMagnitude) + ", " +
                     formatDouble(kMaxScaleFactorMagnitude) +
                     "] (K0 = -2k, Bryan factor k below 1; -0.56 for a "
                     "hemisphere); got " +
                     formatDouble(m0) + where);
    }
    if (harmonics >= 0.5 * std::abs(m0)) {
      f.fail("harmonics too large: sum of |cos| + |sin| = " + formatDouble(harmonics) +
             " must stay below |K0|/2 so that K(theta) keeps its sign" + where);
    }
  } else if (std::abs(m0) + harmonics > kMaxDriftMagnitude) {
    f.fail("drift coefficients add up to " + formatDouble(std::abs(m0) + harmonics) +
           " rad/s, above the plausible limit of " + formatDouble(kMaxDriftMagnitude) +
           " rad/s (units are rad/s of electrical angle)" + where);
  }
}

// The same limits hold at every node and, for a spline (which can overshoot its nodes), on a grid
// between them: K must keep its sign and D stay plausible at every temperature.
void checkEveryFrequency(const YamlField& f, ModelKind kind, const FrequencyInterpolator& interp,
                         const Eigen::MatrixXd& values, std::size_t n) {
  const std::size_t nodes = interp.size();
  for (std::size_t j = 0; j < nodes; ++j) {
    checkCoefficients(f, kind, values.col(j), n, nodes > 1 ? " at frequency node " + std::to_string(j) : "");
  }
  if (nodes < 2 || interp.kind() != Interpolation::kNaturalCubicSpline) return;
  constexpr int kPointsPerInterval = 16;
  const std::vector<double>& fn = interp.nodes();
  Eigen::VectorXd w(nodes);
  for (std::size_t j = 0; j + 1 < nodes; ++j) {
    for (int i = 1; i < kPointsPerInterval; ++i) {
      const double fi = fn[j] + (fn[j + 1] - fn[j]) * i / kPointsPerInterval;
      interp.weights(fi, w.data());
      checkCoefficients(f, kind, values * w, n,
                        " between frequency nodes " + std::to_string(j) + " and " + std::to_string(j + 1) +
                            " (the spline at " + formatDouble(fi) +
                            " Hz overshoots; add nodes or use piecewise_linear)");
    }
  }
}

HarmonicModel parseModel(const YamlField& f, ModelKind kind) {
  f.requireMap();
  f.rejectUnknownKeys({"orders", "mean", "cos", "sin", "frequency_nodes", "interpolation"});
  const std::vector<int> orders = parseOrders(f["orders"]);
  const FrequencyInterpolator interp = parseInterpolator(f);
  const std::size_t n = orders.size(), nodes = interp.size();
  Eigen::MatrixXd values(1 + 2 * n, nodes);
  const std::vector<double> mean = parseNodeValues(f["mean"], nodes);
  for (std::size_t j = 0; j < nodes; ++j) values(0, j) = mean[j];
  for (const char* part : {"cos", "sin"}) {
    const YamlField list = f[part];
    list.requireSequence();
    if (list.size() != n) {
      list.fail("expected " + std::to_string(n) + " entries (one per harmonic order), got " +
                std::to_string(list.size()));
    }
    const std::size_t row0 = std::strcmp(part, "cos") == 0 ? 1 : 1 + n;
    for (std::size_t i = 0; i < n; ++i) {
      const std::vector<double> v = parseNodeValues(list.at(i), nodes);
      for (std::size_t j = 0; j < nodes; ++j) values(row0 + i, j) = v[j];
    }
  }
  checkEveryFrequency(f, kind, interp, values, n);
  if (nodes == 1) {
    std::vector<double> c(n), s(n);
    for (std::size_t i = 0; i < n; ++i) {
      c[i] = values(1 + i, 0);
      s[i] = values(1 + n + i, 0);
    }
    return HarmonicModel(orders, values(0, 0), c, s);
  }
  return HarmonicModel(orders, interp, values);
}

void emitModel(YAML::Emitter& out, const HarmonicModel& m) {
  const bool fdep = m.frequencyDependent();
  const std::size_t n = m.orders().size(), nodes = m.interpolator().size();
  const Eigen::MatrixXd& v = m.nodeValues();
  auto nodeValues = [&](std::size_t row) {
    if (!fdep) {
      out << formatDouble(v(row, 0));
      return;
    }
    out << YAML::Flow << YAML::BeginSeq;
    for (std::size_t j = 0; j < nodes; ++j) out << formatDouble(v(row, j));
    out << YAML::EndSeq;
  };
  out << YAML::BeginMap;
  out << YAML::Key << "orders" << YAML::Value << YAML::Flow << m.orders() << YAML::Comment("harmonic orders k (even)");
  if (fdep) {
    out << YAML::Key << "frequency_nodes" << YAML::Value << YAML::Flow << YAML::BeginSeq;
    for (double f : m.interpolator().nodes()) out << formatDouble(f);
    out << YAML::EndSeq << YAML::Comment("Hz, strictly increasing");
    out << YAML::Key << "interpolation" << YAML::Value << toString(m.interpolator().kind());
  }
  out << YAML::Key << "mean" << YAML::Value;
  nodeValues(0);
  for (const char* part : {"cos", "sin"}) {
    const std::size_t row0 = std::strcmp(part, "cos") == 0 ? 1 : 1 + n;
    out << YAML::Key << part << YAML::Value;
    out << (fdep ? YAML::Block : YAML::Flow) << YAML::BeginSeq;
    for (std::size_t i = 0; i < n; ++i) nodeValues(row0 + i);
    out << YAML::EndSeq;
  }
  out << YAML::EndMap;
}

}  // namespace

HarmonicModel parseScaleFactorModel(const YamlField& section) { return parseModel(section, ModelKind::kScaleFactor); }
HarmonicModel parseDriftModel(const YamlField& section) { return parseModel(section, ModelKind::kDrift); }

GyroParameters parseParameters(const YAML::Node& root) {
  const YamlField doc(root, "");
  if (!root.IsMap()) throw ConfigError("", "parameter file must be a YAML map (is it empty or truncated?)");
  doc.rejectUnknownKeys({"schema_version", "scale_factor", "drift", "correction_matrix", "earth_rate", "calibration"});
  const long version = doc["schema_version"].asInteger();
  if (version != kParameterSchemaVersion) {
    doc["schema_version"].fail("unsupported schema version " + std::to_string(version) + " (this build reads " +
                               std::to_string(kParameterSchemaVersion) + ")");
  }
  GyroParameters p;
  p.scale_factor = parseModel(doc["scale_factor"], ModelKind::kScaleFactor);
  p.drift = parseModel(doc["drift"], ModelKind::kDrift);

  const YamlField cm = doc["correction_matrix"];
  cm.requireMap();
  cm.rejectUnknownKeys({"p"});
  const std::vector<double> pv = cm["p"].asDoubles(4);
  for (int i = 0; i < 4; ++i) {
    if (std::abs(pv[i]) >= 0.5)
      cm["p"].at(i).fail("|p" + std::to_string(i + 1) + "| must be below 0.5 (a small correction)");
    p.correction.p[i] = pv[i];
  }

  const YamlField er = doc["earth_rate"];
  er.requireMap();
  er.rejectUnknownKeys({"enabled", "latitude"});
  p.earth_rate.enabled = er["enabled"].asBool();
  p.earth_rate.latitude = er["latitude"].asDouble();
  if (!validLatitude(p.earth_rate.latitude)) er["latitude"].fail(std::string("latitude ") + kLatitudeRule);

  if (doc.has("calibration")) p.calibration = parseProvenance(doc["calibration"]);
  return p;
}

CalibrationProvenance parseProvenance(const YamlField& cal) {
  cal.requireMap();
  cal.rejectUnknownKeys({"method", "time", "source", "notes"});
  CalibrationProvenance c;
  if (cal.has("method")) {
    try {
      c.method = ParameterOrigin::parse(cal["method"].asString());
    } catch (const std::invalid_argument& e) {
      cal["method"].fail(e.what());
    }
  }
  c.time = cal.getString("time", "");
  c.source = cal.getString("source", "");
  c.notes = cal.getString("notes", "");
  return c;
}

void emitProvenance(YAML::Emitter& out, const CalibrationProvenance& c) {
  out << YAML::Key << "calibration" << YAML::Comment("provenance") << YAML::Value << YAML::BeginMap;
  out << YAML::Key << "method" << YAML::Value << c.method.name();
  out << YAML::Key << "time" << YAML::Value << YAML::DoubleQuoted << c.time;
  out << YAML::Key << "source" << YAML::Value << YAML::DoubleQuoted << c.source;
  out << YAML::Key << "notes" << YAML::Value << YAML::DoubleQuoted << c.notes;
  out << YAML::EndMap;
}

GyroParameters parseParameterText(const std::string& text) {
  YAML::Node root;
  try {
    root = YAML::Load(text);
  } catch (const YAML::ParserException& e) {
    throw ConfigError("", "YAML syntax error at line " + std::to_string(e.mark.line + 1) + ", column " +
                              std::to_string(e.mark.column + 1) + ": " + e.msg);
  }
  try {
    return parseParameters(root);
  } catch (const YAML::Exception& e) {
    // Every key is checked before it is converted; this is the backstop that keeps the promise
    // "ConfigError or a valid model" for whatever yaml-cpp may still throw.
    throw ConfigError("", std::string("unreadable YAML structure: ") + e.what());
  }
}

GyroParameters loadParameterFile(const std::string& path) {
  std::string text;
  try {
    text = readBoundedRegularFile(path, kMaxParameterFileBytes, "parameter file");
  } catch (const std::runtime_error& e) {
    throw ConfigError("", e.what());
  }
  try {
    return parseParameterText(text);
  } catch (const ConfigError& e) {
    throw ConfigError(e.key(), e.problem() + " (in '" + path + "')");
  }
}

std::string emitParameters(const GyroParameters& p) {
  YAML::Emitter out;
  out << YAML::Comment(
             "hrg_gyro parameter file (schema 1). Read by the processor, written by the calibrator.\n"
             "Units SI. theta: electrical wave angle, rad (antinode at case angle theta/2).\n"
             "K(theta, f) = d theta / d alpha (alpha: body angle, REP-103 sign); K0 = -2k < 0.\n"
             "D(theta, f): drift of theta, rad/s. Compensation: dalpha = (dtheta - D dt) / K.\n"
             "Each model: mean + sum over orders k of cos[k] cos(k theta) + sin[k] sin(k theta).")
      << YAML::Newline;
  out << YAML::BeginMap;
  out << YAML::Key << "schema_version" << YAML::Value << kParameterSchemaVersion;
  out << YAML::Key << "scale_factor" << YAML::Comment("K(theta[, f]), dimensionless") << YAML::Value;
  emitModel(out, p.scale_factor);
  out << YAML::Key << "drift" << YAML::Comment("D(theta[, f]), rad/s of electrical angle") << YAML::Value;
  emitModel(out, p.drift);
  out << YAML::Key << "correction_matrix" << YAML::Comment("(E - P) Z on Z = (Ac, Bc, As, Bs)") << YAML::Value
      << YAML::BeginMap;
  out << YAML::Key << "p" << YAML::Value << YAML::Flow << YAML::BeginSeq;
  for (double v : p.correction.p) out << formatDouble(v);
  out << YAML::EndSeq << YAML::Comment("p1 p2: cos/sin channel gain; p3 p4: misplacement");
  out << YAML::EndMap;
  out << YAML::Key << "earth_rate" << YAML::Value << YAML::BeginMap;
  out << YAML::Key << "enabled" << YAML::Value << p.earth_rate.enabled
      << YAML::Comment("true: Earth-fixed increment = dalpha - Omega_E sin(lat) dt");
  out << YAML::Key << "latitude" << YAML::Value << formatDouble(p.earth_rate.latitude)
      << YAML::Comment("rad; vertical Earth rate = 7.2921150e-5 sin(latitude) rad/s");
  out << YAML::EndMap;
  emitProvenance(out, p.calibration);
  out << YAML::EndMap;
  if (!out.good()) throw std::runtime_error("YAML emitter error: " + out.GetLastError());
  return std::string(out.c_str()) + "\n";
}

void saveParameterFile(const std::string& path, const GyroParameters& parameters, const SaveOptions& options) {
  const std::string text = emitParameters(parameters);
  try {
    if (parseParameterText(text) != parameters) throw std::runtime_error("parameters do not survive a round trip");
  } catch (const ConfigError& e) {
    throw std::runtime_error(std::string("refusing to write invalid parameters: ") + e.what());
  }
  OutputFileOptions file_options;
  file_options.keep_backup = options.keep_backup;
  AtomicOutputFile file(path, file_options);
  file.write(text);
  // What is on disk, read back through the same bounded reader the processor uses.
  file.commit([&](const std::string& temporary) {
    if (loadParameterFile(temporary) != parameters)
      throw std::runtime_error("written file reads back differently: " + temporary);
  });
}

}  // namespace core
}  // namespace hrg_gyro

#include "hrg_gyro/core/simulation/triad_simulation_config.h"

#include <Eigen/Geometry>
#include <cmath>
#include <set>

#include "hrg_gyro/core/common/number_format.h"
#include "hrg_gyro/core/common/units.h"
#include "hrg_gyro/core/model/earth_rate.h"
#include "hrg_gyro/core/simulation/gaussian_noise.h"

namespace hrg_gyro {
namespace core {
namespace {

// Limits of what the scenario calls small: beyond them the fixture is not the nominal one (and the
// triad file, which refuses |M - I| > 0.1, could not hold the result).
constexpr double kMaxMisalignment = 0.05;              // rad, and relative for the residual scale
constexpr double kMaxFixtureError = 0.1;               // rad per component
constexpr double kMaxFixtureErrorStd = 0.01;           // rad
constexpr double kMaxWobble = 0.01;                    // rad
constexpr double kMaxMove = 3600.0;                    // s
constexpr double kMaxAccelerometerBias = 1.0;          // m/s^2: an accelerometer off by 0.1 g is broken
constexpr double kMaxAccelerometerNoise = 1.0;         // m/s^2 per sample
constexpr double kMaxAccelerometerScale = 0.1;         // relative: beyond it the accelerometer is broken
constexpr double kMaxAccelerometerMisalignment = 0.1;  // rad per component: a small rotation
constexpr double kMaxAccelerometerQuantum = 1.0;       // m/s^2: a tenth of g

/// The stream the drawn fixture errors come from: switching it on changes no other draw.
constexpr std::uint64_t kFixtureErrorStream = 0x6a09e667f3bcc908ULL;

/// Axis i's seed: the scenario's, mixed with the axis index, so the three axes draw independent noise.
std::uint64_t axisSeed(std::uint64_t seed, int axis) {
  std::uint64_t z = seed + 0x9e3779b97f4a7c15ULL * static_cast<std::uint64_t>(axis + 1);
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
  return z ^ (z >> 31);
}

double finite(const YamlField& section, const char* key, double fallback, const char* unit) {
  const double v = section.getDouble(key, fallback);
  if (!std::isfinite(v)) section[key].fail(std::string("must be finite (") + unit + ")");
  return v;
}

std::string frameId(const YamlField& section, const std::string& fallback) {
  const std::string id = section.getString("frame_id", fallback);
  if (!isValidFrameId(id)) section["frame_id"].fail("must be a frame id: not empty, no leading '/', no blanks");
  return id;
}

TriadAxisConfig parseAxis(const YamlField& a) {
  a.requireMap();
  a.rejectUnknownKeys({"name", "resonator", "pickoff", "channels", "misalignment", "scale", "dynamics"});
  TriadAxisConfig c;
  c.name = a["name"].asString();
  if (!isValidAxisName(c.name)) {
    a["name"].fail("'" + c.name + "' is not a namespace: a letter, then letters, digits or '_'");
  }
  if (a.has("resonator")) c.resonator = parseResonatorSection(a["resonator"]);
  c.dynamics = parseDynamicsOf(a, &c.resonator);
  if (a.has("pickoff")) c.pickoff = parsePickoffSection(a["pickoff"], c.resonator.amplitude);
  if (a.has("channels")) c.channels = parseChannelDeliverySection(a["channels"]);
  if (a.has("misalignment")) {
    const std::vector<double> v = a["misalignment"].asDoubles(2);
    for (std::size_t j = 0; j < 2; ++j) {
      if (!(std::abs(v[j]) <= kMaxMisalignment)) {
        a["misalignment"].at(j).fail("a misalignment is a small angle: at most " + formatDouble(kMaxMisalignment) +
                                     " rad");
      }
      c.misalignment[j] = v[j];
    }
  }
  c.scale = a.getDouble("scale", 0.0);
  if (!(std::abs(c.scale) <= kMaxMisalignment)) {
    a["scale"].fail("a residual scale is small: at most " + formatDouble(kMaxMisalignment) + " in magnitude");
  }
  return c;
}

TriadTurntableConfig parseTurntable(const YamlField& t) {
  t.requireMap();
  t.rejectUnknownKeys({"latitude", "azimuth", "acceleration", "ripple", "log", "wobble"});
  TriadTurntableConfig c;
  c.latitude = t.getDouble("latitude", 0.0);
  if (!validLatitude(c.latitude)) t["latitude"].fail(kLatitudeRule);
  c.azimuth = finite(t, "azimuth", 0.0, "rad from North towards East");
  c.acceleration = t.getDouble("acceleration", c.acceleration);
  if (!(c.acceleration > 0.0)) t["acceleration"].fail("must be positive (rad/s^2)");
  if (t.has("ripple")) c.ripple = parseRippleSection(t["ripple"]);
  if (t.has("log")) c.log = TurntableLogConfig::parse(t["log"]);
  if (t.has("wobble")) {
    const YamlField w = t["wobble"];
    w.requireMap();
    w.rejectUnknownKeys({"amplitude", "direction"});
    c.wobble.amplitude = w.getDouble("amplitude", 0.0);
    if (!(c.wobble.amplitude >= 0.0 && c.wobble.amplitude <= kMaxWobble)) {
      w["amplitude"].fail("must be in [0, " + formatDouble(kMaxWobble) + "] rad: a wobble is a small tilt");
    }
    c.wobble.direction = finite(w, "direction", 0.0, "rad");
  }
  return c;
}

Eigen::Matrix3d parseOrientation(const YamlField& p) {
  const bool up = p.has("up"), explicit_rotation = p.has("body_to_table");
  if (up == explicit_rotation) {
    throw ConfigError(p.path() + ".up", up ? "give either up or body_to_table, not both"
                                           : "missing: give up (+x, -x, +y, -y, +z, -z) or body_to_table");
  }
  Eigen::Matrix3d r;
  if (up) {
    const std::string text = p["up"].asString();
    if (!rotationForUp(text, &r)) p["up"].fail("'" + text + "' is not one of +x, -x, +y, -y, +z, -z");
    return r;
  }
  const YamlField b = p["body_to_table"];
  b.requireMap();
  b.rejectUnknownKeys({"roll", "pitch", "yaw"});
  return rotationFromRollPitchYaw(finite(b, "roll", 0.0, "rad"), finite(b, "pitch", 0.0, "rad"),
                                  finite(b, "yaw", 0.0, "rad"));
}

/// Three numbers, each |v_j| <= limit, the element named when not.
Eigen::Vector3d smallVector(const YamlField& a, const char* key, double limit, const std::string& what) {
  const std::vector<double> v = a[key].asDoubles(3);
  for (std::size_t j = 0; j < 3; ++j) {
    if (!(std::abs(v[j]) <= limit)) a[key].at(j).fail(what + ": at most " + formatDouble(limit) + " in magnitude");
  }
  return Eigen::Vector3d(v[0], v[1], v[2]);
}

/// The accelerometer's own errors: scale, misalignment, axis signs, convention, quantum.
void parseAccelerometerErrors(const YamlField& a, TriadAccelerometerConfig* c) {
  if (a.has("scale")) c->scale = smallVector(a, "scale", kMaxAccelerometerScale, "a relative scale error");
  if (a.has("misalignment")) {
    c->misalignment = smallVector(a, "misalignment", kMaxAccelerometerMisalignment, "a small rotation, rad");
  }
  if (a.has("axis_signs")) {
    const std::vector<double> v = a["axis_signs"].asDoubles(3);
    for (std::size_t j = 0; j < 3; ++j) {
      if (v[j] != 1.0 && v[j] != -1.0) a["axis_signs"].at(j).fail("must be 1 or -1 (-1: the axis reversed)");
      c->axis_signs[static_cast<Eigen::Index>(j)] = v[j];
    }
  }
  const std::string convention = a.getString("convention", "specific_force");
  if (convention == "gravity") {
    c->convention = TriadAccelerometerConfig::Convention::kGravity;
  } else if (convention != "specific_force") {
    a["convention"].fail("'" + convention + "' is not specific_force (+g up at rest) or gravity (-g up)");
  }
  c->quantum = a.getDouble("quantum", 0.0);
  if (!(c->quantum >= 0.0 && c->quantum <= kMaxAccelerometerQuantum)) {
    a["quantum"].fail("must be in [0, " + formatDouble(kMaxAccelerometerQuantum) + "] m/s^2 (0: not quantised)");
  }
}

TriadAccelerometerConfig parseAccelerometer(const YamlField& a, double output_period) {
  a.requireMap();
  a.rejectUnknownKeys({"enabled", "frame_id", "bias", "noise", "noise_density", "mounting", "scale", "misalignment",
                       "axis_signs", "convention", "quantum"});
  TriadAccelerometerConfig c;
  c.enabled = a.getBool("enabled", true);
  c.frame_id = frameId(a, c.frame_id);
  if (a.has("bias")) {
    const std::vector<double> b = a["bias"].asDoubles(3);
    for (std::size_t j = 0; j < 3; ++j) {
      if (!(std::abs(b[j]) <= kMaxAccelerometerBias)) {
        a["bias"].at(j).fail("must be at most " + formatDouble(kMaxAccelerometerBias) + " m/s^2 in magnitude");
      }
      c.bias[static_cast<Eigen::Index>(j)] = b[j];
    }
  }
  if (a.has("noise") && a.has("noise_density")) {
    a["noise_density"].fail("give noise (m/s^2 per sample) or noise_density (m/s^2/sqrt(Hz)), not both");
  }
  // A density N sampled every dt (each sample the mean over its interval): N / sqrt(dt) per sample.
  const std::string noise_key = a.has("noise_density") ? "noise_density" : "noise";
  const double given = a.getDouble(noise_key, 0.0);
  c.noise = noise_key == "noise" ? given : given / std::sqrt(output_period);
  if (!(given >= 0.0 && c.noise <= kMaxAccelerometerNoise)) {
    a[noise_key].fail("must be >= 0 and at most " + formatDouble(kMaxAccelerometerNoise) + " m/s^2 per sample");
  }
  if (a.has("mounting")) {
    const YamlField m = a["mounting"];
    m.requireMap();
    m.rejectUnknownKeys({"roll", "pitch", "yaw"});
    c.accelerometer_to_body = rotationFromRollPitchYaw(finite(m, "roll", 0.0, "rad"), finite(m, "pitch", 0.0, "rad"),
                                                       finite(m, "yaw", 0.0, "rad"));
  }
  parseAccelerometerErrors(a, &c);
  return c;
}

std::vector<FixturePositionConfig> parsePositions(const YamlField& list, double acceleration) {
  list.requireSequence();
  if (list.size() == 0) list.fail("the session needs at least one position");
  std::set<std::string> names;
  std::vector<FixturePositionConfig> positions;
  for (std::size_t k = 0; k < list.size(); ++k) {
    const YamlField p = list.at(k);
    p.requireMap();
    p.rejectUnknownKeys({"name", "up", "body_to_table", "error", "profile", "move"});
    FixturePositionConfig c;
    c.name = p["name"].asString();
    if (c.name.empty()) p["name"].fail("must not be empty");
    if (!names.insert(c.name).second) p["name"].fail("position '" + c.name + "' is named twice");
    c.nominal = parseOrientation(p);
    if (p.has("error")) {
      const std::vector<double> e = p["error"].asDoubles(3);
      for (std::size_t j = 0; j < 3; ++j) {
        if (!(std::abs(e[j]) <= kMaxFixtureError)) {
          p["error"].at(j).fail("a fixture error is a small rotation: at most " + formatDouble(kMaxFixtureError) +
                                " rad");
        }
        c.error[static_cast<Eigen::Index>(j)] = e[j];
      }
      c.error_given = true;
    }
    c.profile = TurntableProfile::parse(p["profile"], acceleration);
    if (k == 0) {
      if (p.has("move")) p["move"].fail("the first position has no move: the session starts clamped in it");
    } else {
      c.move = p["move"].asDouble();
      if (!(c.move > 0.0 && c.move <= kMaxMove)) {
        p["move"].fail("must be in (0, " + formatDouble(kMaxMove) + "] s: the time the fixture takes to be moved");
      }
    }
    positions.push_back(std::move(c));
  }
  return positions;
}

}  // namespace

Eigen::Matrix3d rotationFromVector(const Eigen::Vector3d& rotation) {
  const double angle = rotation.norm();
  if (angle == 0.0) return Eigen::Matrix3d::Identity();
  return Eigen::AngleAxisd(angle, rotation / angle).toRotationMatrix();
}

Eigen::Matrix3d rotationFromRollPitchYaw(double roll, double pitch, double yaw) {
  return (Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()) * Eigen::AngleAxisd(pitch, Eigen::Vector3d::UnitY()) *
          Eigen::AngleAxisd(roll, Eigen::Vector3d::UnitX()))
      .toRotationMatrix();
}

bool rotationForUp(const std::string& up, Eigen::Matrix3d* body_to_table) {
  if (up.size() != 2 || (up[0] != '+' && up[0] != '-') || up[1] < 'x' || up[1] > 'z') return false;
  const double sign = up[0] == '+' ? 1.0 : -1.0;
  const int axis = up[1] - 'x';
  // Columns are the body axes in the table frame: the up axis along +-z, the next one (cyclically)
  // along x, the last along +-y, which keeps the rotation proper.
  Eigen::Matrix3d r = Eigen::Matrix3d::Zero();
  r.col(axis) = sign * Eigen::Vector3d::UnitZ();
  r.col((axis + 1) % 3) = Eigen::Vector3d::UnitX();
  r.col((axis + 2) % 3) = sign * Eigen::Vector3d::UnitY();
  *body_to_table = r;
  return true;
}

Eigen::Matrix3d TableWobbleConfig::platterToTable() const {
  // Turning z about (-sin d, cos d, 0) by the amplitude leans it towards (cos d, sin d, 0).
  return rotationFromVector(amplitude * Eigen::Vector3d(-std::sin(direction), std::cos(direction), 0.0));
}

Eigen::Vector3d TriadTurntableConfig::earthRateInTableZero() const {
  const double horizontal = horizontalEarthRate(latitude);
  return Eigen::Vector3d(horizontal * std::cos(azimuth), horizontal * std::sin(azimuth), verticalEarthRate(latitude));
}

Eigen::Matrix3d TriadTurntableConfig::tableZeroToEnu() const {
  return Eigen::AngleAxisd(kPi / 2 - azimuth, Eigen::Vector3d::UnitZ()).toRotationMatrix();
}

Eigen::Matrix3d FixturePositionConfig::bodyToPlatter() const { return rotationFromVector(error) * nominal; }

Eigen::Matrix3d TriadSimulationConfig::bodyToAxis() const {
  Eigen::Matrix3d a = Eigen::Matrix3d::Identity();
  for (int i = 0; i < 3; ++i) {
    a(i, i) = 1.0 + axes[i].scale;
    int n = 0;
    for (int j = 0; j < 3; ++j) {
      if (j != i) a(i, j) = axes[i].misalignment[n++];
    }
  }
  return a;
}

void TriadSimulationConfig::setSeed(std::uint64_t new_seed) {
  seed = new_seed;
  GaussianNoise draws(seed ^ kFixtureErrorStream);
  for (FixturePositionConfig& p : positions) {
    // Three draws for every position, given or not: giving one position's error changes no other's.
    Eigen::Vector3d drawn;
    for (int j = 0; j < 3; ++j) drawn[j] = draws.next();  // in order (arguments' order is unspecified)
    if (!p.error_given) p.error = fixture_error_std * drawn;
  }
}

TriadParameters TriadSimulationConfig::injectedTriad() const {
  TriadParameters t;
  for (int i = 0; i < 3; ++i) t.axes[i] = axes[i].name;
  t.frame_id = frame_id;
  t.axis_to_body = bodyToAxis().inverse();
  return t;
}

SimulationConfig TriadSimulationConfig::axisScenario(int axis) const {
  const TriadAxisConfig& a = axes[axis];
  SimulationConfig c;
  c.seed = axisSeed(seed, axis);
  c.start_time = start_time;
  c.resonator = a.resonator;
  c.pickoff = a.pickoff;
  c.channels = a.channels;
  c.dynamics = a.dynamics;
  c.latitude = turntable.latitude;
  c.acceleration = turntable.acceleration;
  c.profile = table_profile;  // the ripple already in it: the simulator must not add it again
  return c;
}

TriadSimulationConfig TriadSimulationConfig::parse(const YamlField& root, const std::vector<std::string>& extra_keys) {
  TriadSimulationConfig c;
  parseScenarioTopLevel(root, {"seed", "start_time", "triad"}, extra_keys, &c.seed, &c.start_time);

  const YamlField t = root["triad"];
  t.requireMap();
  t.rejectUnknownKeys(
      {"frame_id", "axes", "turntable", "positions", "fixture_error_std", "accelerometer", "base_motion"});
  c.frame_id = frameId(t, c.frame_id);

  const YamlField axes = t["axes"];
  axes.requireSequence();
  if (axes.size() != 3) axes.fail("a triad has 3 axes, in body-axis order x, y, z; got " + std::to_string(axes.size()));
  std::set<std::string> names;
  for (int i = 0; i < 3; ++i) {
    const YamlField a = axes.at(static_cast<std::size_t>(i));
    c.axes[i] = parseAxis(a);
    if (!names.insert(c.axes[i].name).second) a["name"].fail("axis '" + c.axes[i].name + "' is named twice");
    // The three share their output stamps, so their sample clocks must be one.
    const std::string resonator = a.path() + ".resonator";
    if (c.axes[i].resonator.frequency != c.axes[0].resonator.frequency) {
      throw ConfigError(resonator + ".frequency", "must equal the first axis's: the axes share the output stamps");
    }
    if (c.axes[i].resonator.periods_per_output != c.axes[0].resonator.periods_per_output) {
      throw ConfigError(resonator + ".periods_per_output",
                        "must equal the first axis's: the axes share the output stamps");
    }
  }

  if (t.has("turntable")) c.turntable = parseTurntable(t["turntable"]);
  c.fixture_error_std = t.getDouble("fixture_error_std", 0.0);
  if (!(c.fixture_error_std >= 0.0 && c.fixture_error_std <= kMaxFixtureErrorStd)) {
    t["fixture_error_std"].fail("must be in [0, " + formatDouble(kMaxFixtureErrorStd) + "] rad");
  }
  if (t.has("accelerometer")) c.accelerometer = parseAccelerometer(t["accelerometer"], c.outputPeriod());
  if (t.has("base_motion")) c.base_motion = parseBaseMotion(t["base_motion"]);
  c.positions = parsePositions(t["positions"], c.turntable.acceleration);
  c.setSeed(c.seed);

  // The session: each position's profile after its move, the table at rest during the move.
  for (FixturePositionConfig& p : c.positions) {
    p.move_start = c.table_profile.duration();
    c.table_profile.append(p.move, 0.0, 0.0, p.name + "/move");
    p.start = c.table_profile.duration();
    for (const TurntableProfile::Piece& piece : p.profile.pieces()) {
      c.table_profile.append(piece.duration, piece.rate0, piece.accel, p.name + "/" + piece.label);
    }
    p.end = c.table_profile.duration();
  }
  const TableRippleConfig& ripple = c.turntable.ripple;
  if (ripple.amplitude > 0.0) c.table_profile.setRipple(ripple.amplitude, ripple.frequency, ripple.phase);
  return c;
}

TriadSimulationConfig TriadSimulationConfig::load(const std::string& path, const std::vector<std::string>& extra_keys) {
  return parse(YamlField(loadScenarioDocument(path), ""), extra_keys);
}

bool isTriadScenario(const YAML::Node& root) { return root.IsMap() && root["triad"].IsDefined(); }

}  // namespace core
}  // namespace hrg_gyro

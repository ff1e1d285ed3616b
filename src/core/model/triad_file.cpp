#include "hrg_gyro/core/model/triad_file.h"

#include <yaml-cpp/yaml.h>

#include <Eigen/Dense>
#include <cmath>
#include <cstdio>
#include <set>
#include <stdexcept>

#include "hrg_gyro/core/common/atomic_file.h"
#include "hrg_gyro/core/common/number_format.h"
#include "hrg_gyro/core/common/yaml_field.h"
#include "hrg_gyro/core/common/yaml_file.h"
#include "hrg_gyro/core/model/parameter_file.h"

namespace hrg_gyro {
namespace core {
namespace {

Eigen::Matrix3d readMatrix(const YamlField& f) {
  f.requireSequence();
  if (f.size() != 3) f.fail("must be 3 rows of 3 numbers, has " + std::to_string(f.size()) + " rows");
  Eigen::Matrix3d m;
  for (std::size_t i = 0; i < 3; ++i) {
    const std::vector<double> row = f.at(i).asDoubles(3);
    for (std::size_t j = 0; j < 3; ++j) m(i, j) = row[j];
  }
  return m;
}

Eigen::Vector3d readVector(const YamlField& f) {
  const std::vector<double> v = f.asDoubles(3);
  return Eigen::Vector3d(v[0], v[1], v[2]);
}

void emitMatrix(YAML::Emitter& out, const Eigen::Matrix3d& m) {
  out << YAML::BeginSeq;
  for (int i = 0; i < 3; ++i) {
    out << YAML::Flow << YAML::BeginSeq;
    for (int j = 0; j < 3; ++j) out << formatDouble(m(i, j));
    out << YAML::EndSeq;
  }
  out << YAML::EndSeq;
}

void emitVector(YAML::Emitter& out, const Eigen::Vector3d& v) {
  out << YAML::Flow << YAML::BeginSeq;
  for (int i = 0; i < 3; ++i) out << formatDouble(v(i));
  out << YAML::EndSeq;
}

/// `name` quoted for a message: its first 40 bytes, control characters as \xNN.
std::string quotedName(const std::string& name) {
  constexpr std::size_t kShown = 40;
  std::string out = "'";
  for (std::size_t i = 0; i < name.size() && i < kShown; ++i) {
    const unsigned char c = static_cast<unsigned char>(name[i]);
    if (c < 0x20 || c == 0x7f) {
      char hex[8];
      std::snprintf(hex, sizeof hex, "\\x%02X", c);
      out += hex;
    } else {
      out += name[i];
    }
  }
  return out + (name.size() > kShown ? "...'" : "'");
}

}  // namespace

TriadParameters parseTriadParameters(const YAML::Node& root) {
  const YamlField doc(root, "");
  doc.requireMap();
  doc.rejectUnknownKeys({"frame_id", "axes", "axis_to_body", "axis_to_body_std", "bias", "bias_std", "calibration"});
  TriadParameters t;
  t.frame_id = doc["frame_id"].asString();
  if (!isValidFrameId(t.frame_id)) doc["frame_id"].fail("must be a frame id: not empty, no leading '/', no blanks");
  const YamlField axes = doc["axes"];
  axes.requireSequence();
  if (axes.size() != 3) axes.fail("must name 3 axes, names " + std::to_string(axes.size()));
  std::set<std::string> seen;
  for (std::size_t i = 0; i < 3; ++i) {
    t.axes[i] = axes.at(i).asString();
    if (!isValidAxisName(t.axes[i])) {
      // Quoted as the YAML reader gives it; control characters and blanks shown as escapes.
      axes.at(i).fail(quotedName(t.axes[i]) +
                      " is not an axis name: its topics and namespace are made from it, so it is a ROS name "
                      "component, a letter, then letters, digits or '_'");
    }
    if (!seen.insert(t.axes[i]).second) axes.at(i).fail("axis '" + t.axes[i] + "' is named twice");
  }
  t.axis_to_body = readMatrix(doc["axis_to_body"]);
  const double largest = largestMisalignment(t.axis_to_body);
  if (!(largest <= kMaxTriadMisalignment)) {
    char buf[160];
    std::snprintf(buf, sizeof buf,
                  "differs from the identity by %.3g, more than %.3g: the axes are not the body axes in order and "
                  "sign (or a unit slip)",
                  largest, kMaxTriadMisalignment);
    doc["axis_to_body"].fail(buf);
  }
  t.bias = readVector(doc["bias"]);
  if (!(t.bias.cwiseAbs().maxCoeff() <= kMaxDriftMagnitude)) {
    doc["bias"].fail("above the plausible limit of " + formatDouble(kMaxDriftMagnitude) + " rad/s (a unit slip?)");
  }
  if (doc.has("axis_to_body_std")) {
    t.axis_to_body_std = readMatrix(doc["axis_to_body_std"]);
    if (!(t.axis_to_body_std.minCoeff() >= 0.0)) doc["axis_to_body_std"].fail("standard errors must be >= 0");
  }
  if (doc.has("bias_std")) {
    t.bias_std = readVector(doc["bias_std"]);
    if (!(t.bias_std.minCoeff() >= 0.0)) doc["bias_std"].fail("standard errors must be >= 0");
  }
  if (doc.has("calibration")) t.calibration = parseProvenance(doc["calibration"]);
  return t;
}

TriadParameters loadTriadFile(const std::string& path) {
  const YAML::Node root = loadYamlFile(path, kMaxParameterFileBytes, "triad file");
  try {
    return parseTriadParameters(root);
  } catch (const ConfigError& e) {
    throw ConfigError(e.key(), e.problem() + " (in '" + path + "')");
  } catch (const YAML::Exception& e) {
    throw ConfigError("", std::string("unreadable YAML structure in '") + path + "': " + e.what());
  }
}

std::string emitTriadParameters(const TriadParameters& t) {
  YAML::Emitter out;
  out << YAML::Comment(
             "hrg_gyro triad file: three gyros as one IMU. Each axis keeps its own parameter file.\n"
             "omega_body = M omega_axis - bias   (rad/s; REP-103 right-handed frames)\n"
             "omega_axis: the axes' compensated inertial rates dalpha/dt in the order of `axes`;\n"
             "omega_body: the inertial angular velocity of frame_id, in frame_id.\n"
             "Increments: delta_angle_body = M dalpha - bias dt. Covariance: M diag(sigma_i^2) M^T.")
      << YAML::Newline;
  out << YAML::BeginMap;
  out << YAML::Key << "frame_id" << YAML::Value << t.frame_id << YAML::Comment("the body frame");
  out << YAML::Key << "axes" << YAML::Value << YAML::Flow << YAML::BeginSeq;
  for (const std::string& a_name : t.axes) out << a_name;
  out << YAML::EndSeq << YAML::Comment("the columns of M: each axis's name and namespace");
  out << YAML::Key << "axis_to_body" << YAML::Comment("M, dimensionless, rows: body x, y, z") << YAML::Value;
  emitMatrix(out, t.axis_to_body);
  out << YAML::Comment(describeAlignment(t.bodyToAxis()));
  out << YAML::Key << "axis_to_body_std" << YAML::Comment("standard errors of M (0: not known)") << YAML::Value;
  emitMatrix(out, t.axis_to_body_std);
  out << YAML::Key << "bias" << YAML::Value;
  emitVector(out, t.bias);
  out << YAML::Comment("rad/s, body frame");
  out << YAML::Key << "bias_std" << YAML::Value;
  emitVector(out, t.bias_std);
  emitProvenance(out, t.calibration);
  out << YAML::EndMap;
  return std::string(out.c_str()) + "\n";
}

void saveTriadFile(const std::string& path, const TriadParameters& triad, bool keep_backup) {
  const std::string text = emitTriadParameters(triad);
  try {
    if (parseTriadParameters(YAML::Load(text)) != triad)
      throw std::runtime_error("triad does not survive a round trip");
  } catch (const ConfigError& e) {
    throw std::runtime_error(std::string("refusing to write an invalid triad: ") + e.what());
  }
  OutputFileOptions options;
  options.keep_backup = keep_backup;
  AtomicOutputFile file(path, options);
  file.write(text);
  file.commit([&](const std::string& temporary) {
    if (loadTriadFile(temporary) != triad)
      throw std::runtime_error("written file reads back differently: " + temporary);
  });
}

}  // namespace core
}  // namespace hrg_gyro

#include "hrg_gyro/core/calibration/triad/triad_outcome.h"

#include <yaml-cpp/yaml.h>

#include "hrg_gyro/core/common/number_format.h"
#include "hrg_gyro/core/common/yaml_field.h"
#include "hrg_gyro/core/model/triad_file.h"

namespace hrg_gyro {
namespace core {
namespace {

void emitVector(YAML::Emitter& out, const Eigen::Vector3d& v) {
  out << YAML::Flow << YAML::BeginSeq;
  for (int i = 0; i < 3; ++i) out << formatDouble(v(i));
  out << YAML::EndSeq;
}

void emitMatrix(YAML::Emitter& out, const Eigen::Matrix3d& m) {
  out << YAML::BeginSeq;
  for (int i = 0; i < 3; ++i) emitVector(out, m.row(i).transpose());
  out << YAML::EndSeq;
}

void emitPair(YAML::Emitter& out, const Eigen::Vector2d& v) {
  out << YAML::Flow << YAML::BeginSeq << formatDouble(v(0)) << formatDouble(v(1)) << YAML::EndSeq;
}

void emitTilts(YAML::Emitter& out, const std::vector<TriadAxisTilt>& tilts) {
  out << YAML::Key << "axis_tilts"
      << YAML::Comment("stage 1: each axis's horizontal component in the platter frame, rad, from the Earth's rate")
      << YAML::Value << YAML::BeginSeq;
  for (const TriadAxisTilt& t : tilts) {
    out << YAML::BeginMap;
    out << YAML::Key << "axis" << YAML::Value << t.axis;
    out << YAML::Key << "position" << YAML::Value << t.position;
    out << YAML::Key << "name" << YAML::Value << YAML::DoubleQuoted << t.name;
    out << YAML::Key << "tilt" << YAML::Value;
    emitPair(out, t.tilt);
    out << YAML::Key << "tilt_std" << YAML::Value;
    emitPair(out, t.tilt_std);
    if (t.from_directions_known) {
      out << YAML::Key << "from_directions" << YAML::Comment("A's row in the platter frame, the plan's orientation")
          << YAML::Value;
      emitPair(out, t.from_directions);
    }
    out << YAML::EndMap;
  }
  out << YAML::EndSeq;
}

}  // namespace

void TriadOutcome::gate(const std::string& name, bool passed, double value, double limit, const std::string& message) {
  gates.push_back({name, passed, value, limit, message});
  if (!passed && reason.empty()) reason = name + ": " + message;
}

void TriadOutcome::decide() {
  accepted = !gates.empty();
  for (const GateResult& g : gates) accepted = accepted && g.passed;
  if (gates.empty() && reason.empty()) reason = "no quality gate was evaluated";
}

std::string emitTriadReport(const TriadOutcome& o) {
  YAML::Emitter out;
  out << YAML::Comment(
      "hrg_gyro triad calibration report. omega_body = M omega_axis - bias; A = M^-1 (rows: the axes'\n"
      "directions in the body frame). Rates rad/s, angles rad.");
  out << YAML::BeginMap;
  out << YAML::Key << "method" << YAML::Value << "triad";
  out << YAML::Key << "accepted" << YAML::Value << o.accepted;
  out << YAML::Key << "reason" << YAML::Value << YAML::DoubleQuoted << o.reason;
  out << YAML::Key << "frame_id" << YAML::Value << o.triad.frame_id;
  out << YAML::Key << "axes" << YAML::Value << YAML::Flow << YAML::BeginSeq;
  for (const std::string& a : o.axis_names) out << a;
  out << YAML::EndSeq;
  out << YAML::Key << "axis_to_body" << YAML::Comment("M") << YAML::Value;
  emitMatrix(out, o.triad.axis_to_body);
  out << YAML::Key << "axis_to_body_std" << YAML::Value;
  emitMatrix(out, o.triad.axis_to_body_std);
  out << YAML::Key << "body_to_axis" << YAML::Comment("A = M^-1") << YAML::Value;
  emitMatrix(out, o.body_to_axis);
  out << YAML::Key << "body_to_axis_std" << YAML::Value;
  emitMatrix(out, o.body_to_axis_std);
  out << YAML::Key << "fit_chi_square" << YAML::Comment("per axis, over the positions") << YAML::Value;
  emitVector(out, o.fit_chi_square);
  out << YAML::Key << "positions_fitted" << YAML::Value << o.positions_fitted;
  out << YAML::Key << "bias_estimated" << YAML::Value << o.bias_estimated;
  out << YAML::Key << "bias" << YAML::Comment("rad/s, body frame") << YAML::Value;
  emitVector(out, o.triad.bias);
  out << YAML::Key << "bias_std" << YAML::Value;
  emitVector(out, o.triad.bias_std);
  out << YAML::Key << "positions" << YAML::Value << YAML::BeginSeq;
  for (const TriadPositionResponse& p : o.positions) {
    out << YAML::BeginMap;
    out << YAML::Key << "position" << YAML::Value << p.position;
    out << YAML::Key << "name" << YAML::Value << YAML::DoubleQuoted << p.name;
    out << YAML::Key << "table_axis" << YAML::Comment("in the body frame") << YAML::Value;
    emitVector(out, p.table_axis);
    out << YAML::Key << "response" << YAML::Comment("per axis, d alpha / d table angle") << YAML::Value;
    emitVector(out, p.response);
    out << YAML::Key << "response_std" << YAML::Value;
    emitVector(out, p.response_std);
    out << YAML::Key << "duration" << YAML::Value << formatDouble(p.duration);
    out << YAML::Key << "increments" << YAML::Value << p.increments;
    out << YAML::EndMap;
  }
  out << YAML::EndSeq;
  out << YAML::Key << "rests" << YAML::Value << YAML::BeginSeq;
  for (const TriadRest& r : o.rests) {
    out << YAML::BeginMap;
    out << YAML::Key << "position" << YAML::Value << r.position;
    out << YAML::Key << "name" << YAML::Value << YAML::DoubleQuoted << r.name;
    out << YAML::Key << "table_angle" << YAML::Value << formatDouble(r.table_angle);
    out << YAML::Key << "axis_rates" << YAML::Value;
    emitVector(out, r.axis_rates);
    out << YAML::Key << "axis_rates_std" << YAML::Value;
    emitVector(out, r.axis_rates_std);
    out << YAML::Key << "axis_drift_std" << YAML::Comment("from D(theta)'s uncertainty at the rest") << YAML::Value;
    emitVector(out, r.axis_drift_std);
    out << YAML::Key << "earth_body" << YAML::Value;
    emitVector(out, r.earth_body);
    out << YAML::Key << "bias" << YAML::Value;
    emitVector(out, r.bias);
    out << YAML::Key << "duration" << YAML::Value << formatDouble(r.duration);
    out << YAML::EndMap;
  }
  out << YAML::EndSeq;
  emitTilts(out, o.tilts);
  emitGatesAndNotes(out, o.gates, o.notes);
  // Each axis's own calibration report, as `hrg_bag calibrate` writes it for one axis.
  out << YAML::Key << "axis_reports" << YAML::Value << YAML::BeginMap;
  for (int i = 0; i < 3; ++i) {
    out << YAML::Key << o.axis_names[i] << YAML::Value << YAML::Load(emitCalibrationReport(o.axes[i]));
  }
  out << YAML::EndMap;
  out << YAML::Key << "triad_file" << YAML::Value << YAML::Literal
      << (o.accepted ? emitTriadParameters(o.triad) : std::string("not accepted"));
  out << YAML::EndMap;
  return std::string(out.c_str()) + "\n";
}

}  // namespace core
}  // namespace hrg_gyro

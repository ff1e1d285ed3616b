#include "hrg_gyro/core/simulation/triad_motion.h"

#include <Eigen/Geometry>
#include <cmath>

#include "hrg_gyro/core/common/units.h"
#include "hrg_gyro/core/model/earth_rate.h"

namespace hrg_gyro {
namespace core {

TriadMotion::TriadMotion(const TriadSimulationConfig& config)
    : profile_(config.table_profile),
      wobble_(config.turntable.wobble.platterToTable()),
      table_zero_to_enu_(config.turntable.tableZeroToEnu()),
      earth_zero_(config.turntable.earthRateInTableZero()),
      earth_enu_(earthRateEnu(config.turntable.latitude)),
      base_(config.base_motion, config.seed) {
  Eigen::Matrix3d previous =
      config.positions.empty() ? Eigen::Matrix3d::Identity() : config.positions[0].bodyToPlatter();
  for (const FixturePositionConfig& p : config.positions) {
    Span s;
    s.move_start = p.move_start;
    s.start = p.start;
    s.move = p.move;
    s.from = previous;
    s.to = p.bodyToPlatter();
    s.table_to_body = (wobble_ * s.to).transpose();
    // The smallest rotation from one orientation to the next (for a half turn, Eigen's choice of axis).
    const Eigen::AngleAxisd relative(Eigen::Matrix3d(s.from.transpose() * s.to));
    s.rho = relative.angle() * relative.axis();
    spans_.push_back(s);
    previous = s.to;
  }
}

const TriadMotion::Span& TriadMotion::spanAt(double t) const {
  if (cursor_ >= spans_.size() || t < spans_[cursor_].move_start) cursor_ = 0;
  while (cursor_ + 1 < spans_.size() && t >= spans_[cursor_ + 1].move_start) ++cursor_;
  return spans_[cursor_];
}

void TriadMotion::moving(const Span& span, double t, Eigen::Matrix3d* body_to_platter, Eigen::Vector3d* rate) const {
  // s(u) = u - sin(2 pi u) / (2 pi): at rest at both ends, its rate (1 - cos 2 pi u) / move smooth.
  const double u = (t - span.move_start) / span.move;
  const double s = u - std::sin(kTwoPi * u) / kTwoPi;
  const double sdot = (1.0 - std::cos(kTwoPi * u)) / span.move;
  const double angle = span.rho.norm();
  *body_to_platter = span.from;
  if (angle > 0.0) *body_to_platter = span.from * Eigen::AngleAxisd(s * angle, span.rho / angle).toRotationMatrix();
  *rate = sdot * span.rho;
}

Eigen::Vector3d TriadMotion::baseShareInTable(double t, double phi) const {
  Eigen::Matrix3d d;
  Eigen::Vector3d w;
  base_.stateAt(t, &d, &w);
  // C^T (Omega + w) - C_nominal^T Omega with C = D C_nominal: the still base's Earth rate replaced.
  const Eigen::Vector3d enu = d.transpose() * (earth_enu_ + w) - earth_enu_;
  return Eigen::AngleAxisd(-phi, Eigen::Vector3d::UnitZ()) * (table_zero_to_enu_.transpose() * enu);
}

Eigen::Vector3d TriadMotion::tableFrameRateAt(double t) const {
  double phi, phidot;
  profile_.evaluate(t, &phi, &phidot);
  const double c = std::cos(phi), s = std::sin(phi);
  // Rz(phi)^T omega_E0: the Earth's rate seen from the turned platter, plus the table's own rate.
  const Eigen::Vector3d still(c * earth_zero_.x() + s * earth_zero_.y(), -s * earth_zero_.x() + c * earth_zero_.y(),
                              earth_zero_.z() + phidot);
  if (!base_.enabled()) return still;
  return still + baseShareInTable(t, phi);
}

Eigen::Vector3d TriadMotion::angularVelocityAt(double t) const {
  const Eigen::Vector3d table = tableFrameRateAt(t);
  const Span& span = spanAt(t);
  if (t >= span.start || span.move <= 0.0) return span.table_to_body * table;
  Eigen::Matrix3d body_to_platter;
  Eigen::Vector3d move_rate;
  moving(span, t, &body_to_platter, &move_rate);
  return (wobble_ * body_to_platter).transpose() * table + move_rate;
}

TriadBodyState TriadMotion::stateAt(double t) const {
  TriadBodyState b;
  profile_.evaluate(t, &b.table_angle, &b.table_rate);
  const Span& span = spanAt(t);
  b.position = cursor_;
  b.locked = t >= span.start || span.move <= 0.0;
  Eigen::Vector3d move_rate = Eigen::Vector3d::Zero();
  if (b.locked) {
    b.body_to_platter = span.to;
  } else {
    moving(span, t, &b.body_to_platter, &move_rate);
  }
  b.body_to_table = wobble_ * b.body_to_platter;
  b.body_to_enu = table_zero_to_enu_ * Eigen::AngleAxisd(b.table_angle, Eigen::Vector3d::UnitZ()) * b.body_to_table;
  if (base_.enabled()) {
    b.base_rotation = base_.rotationAt(t);
    b.body_to_enu = b.base_rotation * b.body_to_enu;
  }
  b.angular_velocity = b.body_to_table.transpose() * tableFrameRateAt(t) + move_rate;
  return b;
}

}  // namespace core
}  // namespace hrg_gyro

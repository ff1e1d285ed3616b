// Straight-line fit theta(t) over one static dwell, streamed: its slope is the rest rate
// K Omega_E + D(theta), and its ends anchor the angle steps of the step method.
#pragma once

#include <cmath>
#include <cstdint>

#include "hrg_gyro/core/common/units.h"

namespace hrg_gyro {
namespace core {

class DwellFit {
 public:
  void add(Nanoseconds stamp, double theta, double table_angle);

  /// When the table came to rest (the plateau's first state); the settled samples start later.
  void setRestSince(Nanoseconds t) { rest_since_ = t; }
  Nanoseconds restSince() const { return rest_since_ != 0 ? rest_since_ : start_; }

  std::uint64_t samples() const { return n_; }
  Nanoseconds start() const { return start_; }
  Nanoseconds end() const { return end_; }
  double duration() const { return toSeconds(end_ - start_); }
  double slope() const;                 ///< rad/s
  double slopeStd() const;              ///< rad/s, from the residual scatter
  double valueAt(Nanoseconds t) const;  ///< fitted theta, rad
  double meanTheta() const { return n_ ? theta0_ + th_ / n_ : 0.0; }
  double meanTableAngle() const { return n_ ? angle_ / n_ : 0.0; }
  double residualStd() const;  ///< rad

 private:
  Nanoseconds start_ = 0, end_ = 0, rest_since_ = 0;
  double theta0_ = 0.0;  // first theta: keeps the sums small when theta is ~1e3 rad
  double t_ = 0.0, th_ = 0.0, tt_ = 0.0, tth_ = 0.0, thth_ = 0.0, angle_ = 0.0;
  std::uint64_t n_ = 0;
};

}  // namespace core
}  // namespace hrg_gyro

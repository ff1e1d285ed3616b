// The turntable motion of a scenario: a list of segments turned into pieces of constant
// acceleration, so that the table angle and rate are known exactly at any time.
//
// Segment types (keys as in config/scenarios/*.yaml, under turntable.profile):
//   dwell      {duration}                      come to rest (at the acceleration limit), then hold
//   rate       {rate, duration[, settle]}      change to `rate` rad/s, hold settle + duration s
//   steps      {angle, rate, dwell, count}     `count` moves of `angle` rad (trapezoidal, cruise
//                                              `rate`), each followed by a `dwell` s rest
//   dual_rate  {rates: [w1, w2], duration[, settle, repeat]}  plateaus at w1 then w2, repeated
//   piecewise  {points: [[t, rate], ...]}      rate linear between points (t from segment start)
// Every segment may carry a `label` (ground truth reports it). Rate changes use
// turntable.acceleration (rad/s^2).
#pragma once

#include <string>
#include <vector>

#include "hrg_gyro/core/common/yaml_field.h"

namespace hrg_gyro {
namespace core {

class TurntableProfile {
 public:
  struct Piece {
    double start = 0.0;     ///< s from the profile start
    double duration = 0.0;  ///< s
    double angle0 = 0.0;    ///< rad at start
    double rate0 = 0.0;     ///< rad/s at start
    double accel = 0.0;     ///< rad/s^2 during the piece
    std::string label;
  };

  TurntableProfile() = default;
  /// Parses turntable.profile; `acceleration` > 0 rad/s^2. Throws ConfigError naming the key.
  static TurntableProfile parse(const YamlField& profile, double acceleration);

  /// Appends a piece (builders and tests).
  void append(double duration, double rate0, double accel, const std::string& label);

  double duration() const { return pieces_.empty() ? 0.0 : pieces_.back().start + pieces_.back().duration; }
  double finalRate() const;
  const std::vector<Piece>& pieces() const { return pieces_; }

  /// Table angle (rad), rate (rad/s) and segment label at time t (s); held constant after the end.
  void evaluate(double t, double* angle, double* rate, const std::string** label = nullptr) const;

 private:
  const Piece& pieceAt(double t) const;
  void rampTo(double target_rate, double acceleration, const std::string& label);
  void moveBy(double angle, double cruise_rate, double acceleration, const std::string& label);

  std::vector<Piece> pieces_;
  mutable std::size_t cursor_ = 0;  // evaluation is nearly always monotonic in t
};

}  // namespace core
}  // namespace hrg_gyro

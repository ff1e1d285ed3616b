// The turntable motion of a scenario: a list of segments turned into pieces of constant
// acceleration, so that the table angle and rate are known exactly at any time.
//
// Segment types (keys as in config/scenarios/*.yaml, under turntable.profile):
//   dwell      {duration}                      come to rest (at the acceleration limit), then hold
//   rate       {rate, duration[, settle]}      change to `rate` rad/s, hold settle + duration s
//   steps      {angle, rate, dwell, count}     `count` moves of `angle` rad (trapezoidal, cruise
//                                              `rate`), each followed by a `dwell` s rest
//   dual_rate  {rates: [w1, w2], duration[, settle, repeat, order]}  2 x repeat plateaus at w1 and w2;
//              order `alternating` (default): w1 w2 w1 w2 ...; `balanced`: the Thue-Morse order
//              w1 w2 w2 w1 w2 w1 w1 w2 ..., which cancels a linear bias trend between the two rates
//              over every 4 plateaus and a quadratic one over every 8 (two plateaus of one rate in a
//              row hold it through the time a reversal takes, keeping the plateaus evenly spaced)
//   piecewise  {points: [[t, rate], ...]}      rate linear between points (t from segment start)
// Every segment may carry a `label` (ground truth reports it). Rate changes use
// turntable.acceleration (rad/s^2).
//
// Optional drive ripple (turntable.ripple): the true rate is r(t) (1 + a sin(2 pi f t + phi)), a
// fraction `a` of the commanded rate r(t), as a drive's speed ripple scales with its speed. The angle
// holds its exact integral (closed form over each piece), so the gyro senses the ripple and a logged
// table angle carries it; at rest there is none.
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
    double ripple0 = 0.0;   ///< integral of r(t) sin(2 pi f t + phi) up to the piece start, rad
    std::string label;
  };

  TurntableProfile() = default;
  /// Parses turntable.profile; `acceleration` > 0 rad/s^2. Throws ConfigError naming the key.
  static TurntableProfile parse(const YamlField& profile, double acceleration);

  /// Appends a piece (builders and tests).
  void append(double duration, double rate0, double accel, const std::string& label);

  /// Drive ripple: `fraction` of the commanded rate at `frequency` Hz, phase `phase` rad at t = 0.
  /// fraction 0 (the default): none, and the motion is exactly the commanded one.
  void setRipple(double fraction, double frequency, double phase = 0.0);
  double rippleFraction() const { return ripple_fraction_; }
  double rippleFrequency() const { return ripple_frequency_; }

  double duration() const { return pieces_.empty() ? 0.0 : pieces_.back().start + pieces_.back().duration; }
  double finalRate() const;
  const std::vector<Piece>& pieces() const { return pieces_; }

  /// Table angle (rad), rate (rad/s) and segment label at time t (s); held constant after the end.
  void evaluate(double t, double* angle, double* rate, const std::string** label = nullptr) const;

 private:
  const Piece& pieceAt(double t) const;
  void rampTo(double target_rate, double acceleration, const std::string& label);
  void moveBy(double angle, double cruise_rate, double acceleration, const std::string& label);
  /// Integral over [0, tau] of the piece's commanded rate times the ripple's sine.
  double rippleIntegral(const Piece& p, double tau) const;
  void updateRippleOrigins();

  std::vector<Piece> pieces_;
  double ripple_fraction_ = 0.0;
  double ripple_frequency_ = 0.0;   // Hz
  double ripple_phase_ = 0.0;       // rad
  mutable std::size_t cursor_ = 0;  // evaluation is nearly always monotonic in t
};

}  // namespace core
}  // namespace hrg_gyro

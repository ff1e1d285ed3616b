// The resonator temperature over a simulated session (scenario key thermal.profile).
//
// Why: the resonance frequency and every defect of a real HRG move with temperature, and a
// calibration across temperature needs sessions in which the temperature is known at every instant.
// The profile starts at a given temperature; each segment continues from where the previous one
// ended, so the temperature is continuous unless a step says otherwise:
//   hold  {duration}                          constant (a soak)
//   ramp  {to, duration} or {to, rate}        linear to `to` degC in `duration` s (or at `rate` degC/s)
//   step  {to, duration[, time_constant]}     the chamber set point jumps to `to`; the resonator follows
//                                             as a first-order lag (time_constant s; 0: at once) and
//                                             the segment lasts `duration` s
// Every segment may carry a `label` (for the reader; not reported). After the last segment the
// temperature holds.
#pragma once

#include <string>
#include <vector>

#include "hrg_gyro/core/common/yaml_field.h"

namespace hrg_gyro {
namespace core {

class TemperatureProfile {
 public:
  struct Piece {
    double start = 0.0;          ///< s from the session start
    double duration = 0.0;       ///< s
    double from = 0.0;           ///< degC at the piece start
    double to = 0.0;             ///< degC: the end of a ramp, the set point of a step
    double time_constant = 0.0;  ///< s: > 0 for a lagged step (from -> to exponentially), 0 linear
  };

  /// A constant temperature.
  explicit TemperatureProfile(double start_temperature = 25.0) : start_temperature_(start_temperature) {}
  /// Parses thermal.profile (a list of segments). Throws ConfigError naming the key.
  static TemperatureProfile parse(const YamlField& profile, double start_temperature);

  /// Appends pieces (builders and tests).
  void appendRamp(double duration, double to);
  void appendStep(double duration, double to, double time_constant);

  double startTemperature() const { return start_temperature_; }
  double finalTemperature() const;
  double duration() const { return pieces_.empty() ? 0.0 : pieces_.back().start + pieces_.back().duration; }
  const std::vector<Piece>& pieces() const { return pieces_; }

  /// Temperature (degC) at t s from the session start; the start value before 0, the final value
  /// after the end.
  double evaluate(double t) const;
  /// Lowest and highest temperature reached (the extremes of a piece are at its ends).
  double minimum() const;
  double maximum() const;

 private:
  static double valueIn(const Piece& p, double dt);

  double start_temperature_;
  std::vector<Piece> pieces_;
  mutable std::size_t cursor_ = 0;  // evaluation is nearly always monotonic in t
};

}  // namespace core
}  // namespace hrg_gyro

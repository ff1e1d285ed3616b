// Makes the wave angle continuous across revolutions.
//
// atan2(S, R)/2 returns theta modulo pi; consecutive samples are joined by the step of pi that keeps
// the change smallest, which is right as long as the wave turns by less than pi/2 per sample
// (at 1 kHz that is 1500 rad/s of electrical angle). The continuous angle is kept as its principal
// value plus a whole number of half turns, and each step adds to that count the half turns between
// two principal values: the count does not depend on the rounding of an ever larger continuous
// angle, and the per-sample chain from one sample to the next is a single addition (the processor's
// hot path is bound by such chains).
#pragma once

#include "hrg_gyro/core/common/units.h"

namespace hrg_gyro {
namespace core {

class ThetaUnwrapper {
 public:
  /// The continuous angle for a principal value (any branch of theta modulo pi), without taking it:
  /// *half_turns receives the count to pass to accept(). The first angle after a reset is its own
  /// continuous value.
  double peek(double principal, double* half_turns) const {
    // Two principal values are less than a half turn apart, and a tie (a step of exactly pi/2 either
    // way) has no shorter way to prefer: nearestWhole's shorter chain serves.
    *half_turns = initialized_ ? half_turns_ + nearestWhole((last_principal_ - principal) * kInversePi) : 0.0;
    return principal + kPi * *half_turns;
  }
  /// Takes principal + pi half_turns as the latest angle.
  void accept(double principal, double half_turns) {
    initialized_ = true;
    last_principal_ = principal;
    half_turns_ = half_turns;
    last_ = principal + kPi * half_turns;
  }
  /// After the angle has been measured another way (a new correction matrix): takes the branch of
  /// `principal` nearest to the latest continuous angle as the new anchor; *half_turns receives its
  /// count. Returns the continuous angle.
  double reanchor(double principal, double* half_turns) {
    *half_turns = roundHalfAway((last_ - principal) * kInversePi);
    accept(principal, *half_turns);
    return last_;
  }
  /// peek() and accept() in one.
  double unwrap(double principal) {
    double half_turns;
    peek(principal, &half_turns);
    accept(principal, half_turns);
    return last_;
  }
  void reset() { initialized_ = false; }
  bool initialized() const { return initialized_; }
  /// The latest continuous angle.
  double last() const { return last_; }

 private:
  static constexpr double kInversePi = 1.0 / kPi;
  bool initialized_ = false;
  double last_principal_ = 0.0;
  double half_turns_ = 0.0;  // a whole number
  double last_ = 0.0;
};

}  // namespace core
}  // namespace hrg_gyro

// Makes the wave angle continuous across revolutions.
//
// atan2(S, R)/2 returns theta modulo pi; consecutive samples are joined by the step of pi that keeps
// the change smallest, which is right as long as the wave turns by less than pi/2 per sample
// (at 1 kHz that is 1500 rad/s of electrical angle).
#pragma once

#include "hrg_gyro/core/common/units.h"

namespace hrg_gyro {
namespace core {

class ThetaUnwrapper {
 public:
  /// Returns the continuous angle for a principal value (any branch of theta modulo pi).
  double unwrap(double theta) {
    if (initialized_) theta += kPi * roundHalfAway((last_ - theta) / kPi);
    initialized_ = true;
    last_ = theta;
    return theta;
  }
  void reset() { initialized_ = false; }
  bool initialized() const { return initialized_; }
  double last() const { return last_; }

 private:
  bool initialized_ = false;
  double last_ = 0.0;
};

}  // namespace core
}  // namespace hrg_gyro

#include "hrg_gyro/core/signal/theta_unwrapper.h"

#include <cmath>

#include "hrg_gyro/core/common/units.h"

namespace hrg_gyro {
namespace core {

double ThetaUnwrapper::unwrap(double theta) {
  if (initialized_) theta += kPi * std::round((last_ - theta) / kPi);
  initialized_ = true;
  last_ = theta;
  return theta;
}

}  // namespace core
}  // namespace hrg_gyro

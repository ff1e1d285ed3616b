#include "hrg_gyro/core/model/earth_rate.h"

#include "hrg_gyro/core/common/units.h"

namespace hrg_gyro {
namespace core {

Eigen::Vector3d earthRateEnu(double latitude) {
  return Eigen::Vector3d(0.0, horizontalEarthRate(latitude), verticalEarthRate(latitude));
}

bool validLatitude(double latitude) { return std::isfinite(latitude) && std::abs(latitude) <= 0.5 * kPi; }

}  // namespace core
}  // namespace hrg_gyro

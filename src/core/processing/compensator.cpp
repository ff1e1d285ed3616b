#include "hrg_gyro/core/processing/compensator.h"

namespace hrg_gyro {
namespace core {

Compensator::Compensator(std::shared_ptr<const GyroParameters> parameters)
    : parameters_(std::move(parameters)),
      models_(parameters_->scale_factor, parameters_->drift),
      earth_rate_(parameters_->earth_rate.verticalRate()) {}

}  // namespace core
}  // namespace hrg_gyro

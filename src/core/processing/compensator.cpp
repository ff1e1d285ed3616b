#include "hrg_gyro/core/processing/compensator.h"

#include <cstring>

#include "hrg_gyro/core/common/double_lanes.h"

namespace hrg_gyro {
namespace core {

Compensator::Compensator(std::shared_ptr<const GyroParameters> parameters)
    : parameters_(std::move(parameters)),
      models_(parameters_->scale_factor, parameters_->drift),
      earth_rate_(parameters_->earth_rate.verticalRate()) {}

namespace {

DoubleLanes4 load(const double* four) {
  DoubleLanes4 v;
  std::memcpy(&v, four, sizeof v);
  return v;
}

}  // namespace

// The lanes go through step()'s operations in its order (the formulas are shared; compensator_test
// checks the bits against step()).
HRG_GYRO_CLONES_FOR_AVX2 void Compensator::steps(StepBatch* batch) {
  const std::size_t n = batch->size;
  std::size_t i = 0;
  if (stepsInLanes()) {
    for (; i + 4 <= n; i += 4) {
      const DoubleLanes4 theta_previous = load(batch->theta_previous + i), theta = load(batch->theta + i);
      const DoubleLanes4 dt = load(batch->dt + i);
      const DoubleLanes4 cos_previous = load(batch->cos_previous + i), sin_previous = load(batch->sin_previous + i);
      const DoubleLanes4 cos_theta = load(batch->cos_theta + i), sin_theta = load(batch->sin_theta + i);
      const DoubleLanes4 dtheta = theta - theta_previous;
      const DoubleLanes4 theta_mid = 0.5 * (theta + theta_previous);
      DoubleLanes4 c2, s2, k, d, dalpha, dalpha_earth_fixed;
      doubleMidAngle(cos_previous, sin_previous, cos_theta, sin_theta, &c2, &s2);
      models_.evaluateLanes(c2, s2, &k, &d);
      compensate(dtheta, k, d, dt, &dalpha, &dalpha_earth_fixed);
      for (int l = 0; l < 4; ++l) {
        AngleIncrement& inc = *batch->out[i + l];
        inc.dt = dt[l];
        inc.dtheta = dtheta[l];
        inc.theta_mid = theta_mid[l];
        inc.frequency = batch->frequency_mid[i + l];
        inc.scale_factor = k[l];
        inc.drift = d[l];
        inc.dalpha = dalpha[l];
        inc.dalpha_earth_fixed = dalpha_earth_fixed[l];
      }
    }
  }
  for (; i < n; ++i) {
    *batch->out[i] = step(batch->theta_previous[i], batch->theta[i], batch->dt[i], batch->frequency_mid[i],
                          batch->cos_previous[i], batch->sin_previous[i], batch->cos_theta[i], batch->sin_theta[i]);
  }
  batch->size = 0;
}

}  // namespace core
}  // namespace hrg_gyro

// The compensation step: from two consecutive wave angles to the body-angle increment.
//
//   dalpha = (dtheta - D(theta_mid, f) dt) / K(theta_mid, f)
// (docs/math.md, 'Dynamics and compensation').
// theta_mid is the midpoint of the step, f the resonator frequency at the midpoint. dalpha is the
// inertial increment (what a gyro measures); the increment of the Earth-fixed turntable angle is
// dalpha - Omega_E sin(latitude) dt. The self-consistent sign has no leading minus: the paper's
// -(...)/K belongs to its convention where K is quoted as a positive magnitude.
#pragma once

#include <memory>

#include "hrg_gyro/core/model/gyro_parameters.h"
#include "hrg_gyro/core/model/model_pair_evaluator.h"

namespace hrg_gyro {
namespace core {

struct AngleIncrement {
  double dt = 0.0;                  ///< s
  double dtheta = 0.0;              ///< measured electrical-angle increment, rad
  double theta_mid = 0.0;           ///< rad, where K and D were evaluated
  double frequency = 0.0;           ///< Hz used for the models (NaN if unknown)
  double scale_factor = 0.0;        ///< K used
  double drift = 0.0;               ///< D used, rad/s
  double dalpha = 0.0;              ///< inertial body-angle increment, rad
  double dalpha_earth_fixed = 0.0;  ///< increment relative to the Earth-fixed table, rad
};

class Compensator {
 public:
  explicit Compensator(std::shared_ptr<const GyroParameters> parameters);

  const GyroParameters& parameters() const { return *parameters_; }
  const std::shared_ptr<const GyroParameters>& sharedParameters() const { return parameters_; }

  AngleIncrement step(double theta_previous, double theta, double dt, double frequency_mid) {
    AngleIncrement inc;
    inc.dt = dt;
    inc.dtheta = theta - theta_previous;
    inc.theta_mid = 0.5 * (theta + theta_previous);
    inc.frequency = frequency_mid;
    models_.evaluate(inc.theta_mid, frequency_mid, &inc.scale_factor, &inc.drift);
    inc.dalpha = (inc.dtheta - inc.drift * dt) / inc.scale_factor;
    inc.dalpha_earth_fixed = inc.dalpha - earth_rate_ * dt;
    return inc;
  }
  /// The same with the unit vectors (cos, sin) of both angles supplied: cos and sin of
  /// 2 theta_mid = theta_previous + theta are their complex product, so no sincos per sample.
  AngleIncrement step(double theta_previous, double theta, double dt, double frequency_mid, double cos_previous,
                      double sin_previous, double cos_theta, double sin_theta) {
    AngleIncrement inc;
    inc.dt = dt;
    inc.dtheta = theta - theta_previous;
    inc.theta_mid = 0.5 * (theta + theta_previous);
    inc.frequency = frequency_mid;
    const double c2 = cos_previous * cos_theta - sin_previous * sin_theta;
    const double s2 = sin_previous * cos_theta + cos_previous * sin_theta;
    models_.evaluate(inc.theta_mid, c2, s2, frequency_mid, &inc.scale_factor, &inc.drift);
    inc.dalpha = (inc.dtheta - inc.drift * dt) / inc.scale_factor;
    inc.dalpha_earth_fixed = inc.dalpha - earth_rate_ * dt;
    return inc;
  }

 private:
  std::shared_ptr<const GyroParameters> parameters_;
  ModelPairEvaluator models_;
  double earth_rate_;
};

}  // namespace core
}  // namespace hrg_gyro

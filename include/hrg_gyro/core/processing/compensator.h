// The compensation step: from two consecutive wave angles to the body-angle increment.
//
//   dalpha = (dtheta - D(theta_mid, f) dt) / K(theta_mid, f)
// (docs/math.md, 'Dynamics and compensation').
// theta_mid is the midpoint of the step, f the resonator frequency at the midpoint. dalpha is the
// inertial increment (what a gyro measures); the increment of the Earth-fixed turntable angle is
// dalpha - Omega_E sin(latitude) dt. The self-consistent sign has no leading minus: the paper's
// -(...)/K belongs to its convention where K is quoted as a positive magnitude.
#pragma once

#include <cstddef>
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

/// The inputs of a run of compensation steps, field by field (so four of each load at once), and
/// where each result goes. GyroProcessor::processBatch fills one per block of samples.
struct StepBatch {
  static constexpr std::size_t kCapacity = 32;
  std::size_t size = 0;
  alignas(32) double theta_previous[kCapacity];
  alignas(32) double theta[kCapacity];
  alignas(32) double dt[kCapacity];
  alignas(32) double frequency_mid[kCapacity];
  alignas(32) double cos_previous[kCapacity];
  alignas(32) double sin_previous[kCapacity];
  alignas(32) double cos_theta[kCapacity];
  alignas(32) double sin_theta[kCapacity];
  AngleIncrement* out[kCapacity];

  /// The arguments of Compensator::step (the form with the unit vectors), in its order.
  void add(double theta_previous_, double theta_, double dt_, double frequency_mid_, double cos_previous_,
           double sin_previous_, double cos_theta_, double sin_theta_, AngleIncrement* out_) {
    theta_previous[size] = theta_previous_;
    theta[size] = theta_;
    dt[size] = dt_;
    frequency_mid[size] = frequency_mid_;
    cos_previous[size] = cos_previous_;
    sin_previous[size] = sin_previous_;
    cos_theta[size] = cos_theta_;
    sin_theta[size] = sin_theta_;
    out[size] = out_;
    ++size;
  }
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
    compensate(inc.dtheta, inc.scale_factor, inc.drift, dt, &inc.dalpha, &inc.dalpha_earth_fixed);
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
    double c2, s2;
    doubleMidAngle(cos_previous, sin_previous, cos_theta, sin_theta, &c2, &s2);
    models_.evaluate(inc.theta_mid, c2, s2, frequency_mid, &inc.scale_factor, &inc.drift);
    compensate(inc.dtheta, inc.scale_factor, inc.drift, dt, &inc.dalpha, &inc.dalpha_earth_fixed);
    return inc;
  }
  /// Whether steps() computes four at a time (ModelPairEvaluator::lanesApply); otherwise it is
  /// step() one by one.
  bool stepsInLanes() const { return models_.lanesApply(); }
  /// *batch.out[i] = step(the inputs i) for every step of the batch, bit for bit; empties the batch.
  void steps(StepBatch* batch);

 private:
  // The two formulas of a step, written once for one step (V = double) and for the lanes of steps().
  /// cos and sin of 2 theta_mid = theta_previous + theta: the complex product of the unit vectors.
  template <class V>
  static void doubleMidAngle(V cos_previous, V sin_previous, V cos_theta, V sin_theta, V* c2, V* s2) {
    *c2 = cos_previous * cos_theta - sin_previous * sin_theta;
    *s2 = sin_previous * cos_theta + cos_previous * sin_theta;
  }
  /// dalpha = (dtheta - D dt) / K, and the same less the Earth's rotation.
  template <class V>
  void compensate(V dtheta, V scale_factor, V drift, V dt, V* dalpha, V* dalpha_earth_fixed) const {
    *dalpha = (dtheta - drift * dt) / scale_factor;
    *dalpha_earth_fixed = *dalpha - earth_rate_ * dt;
  }

  std::shared_ptr<const GyroParameters> parameters_;
  ModelPairEvaluator models_;
  double earth_rate_;
};

}  // namespace core
}  // namespace hrg_gyro

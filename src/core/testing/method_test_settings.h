// Test support: what the calibration methods' and the session's unit tests share -- the chosen
// method with K fitted to orders 2 and 4 and D to order 2, a prior whose Earth rate is taken at
// latitude 0.9 rad (the angle-level reference gyro's: referencePrior, angle_level_session.h), and a
// constant-rate table profile.
#pragma once

#include "core/testing/angle_level_session.h"
#include "hrg_gyro/core/calibration/calibration_settings.h"
#include "hrg_gyro/core/model/gyro_parameters.h"
#include "hrg_gyro/core/simulation/turntable_profile.h"

namespace hrg_gyro {
namespace core {
namespace testing {

inline CalibrationSettings methodSettings(CalibrationMethodKind method) {
  CalibrationSettings s;
  s.method = method;
  s.scale_factor_orders = {2, 4};
  s.drift_orders = {2};
  return s;
}

/// A constant-rate session: a rest, 250 s at 0.05 rad/s, a rest.
inline TurntableProfile constantRateProfile() {
  TurntableProfile p;
  p.append(30.0, 0.0, 0.0, "rest");
  p.append(0.1, 0.0, 0.5, "ramp");
  p.append(250.0, 0.05, 0.0, "turn");
  p.append(0.1, 0.05, -0.5, "ramp");
  p.append(25.0, 0.0, 0.0, "rest");
  return p;
}

}  // namespace testing
}  // namespace core
}  // namespace hrg_gyro

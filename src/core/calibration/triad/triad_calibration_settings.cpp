#include "hrg_gyro/core/calibration/triad/triad_calibration_settings.h"

#include <cmath>

#include "hrg_gyro/core/common/units.h"

namespace hrg_gyro {
namespace core {

std::vector<std::string> TriadCalibrationSettings::keys() {
  return {"azimuth", "window", "store_rate", "vertical_tolerance", "min_rest", "min_position_time", "max_misalignment"};
}

TriadCalibrationSettings TriadCalibrationSettings::parse(const YamlField& f) {
  f.requireMap();
  f.rejectUnknownKeys(keys());
  TriadCalibrationSettings s;
  s.azimuth = f.getDouble("azimuth", s.azimuth);
  if (!(std::abs(s.azimuth) <= 2.0 * kPi)) f["azimuth"].fail("must be in [-2 pi, 2 pi] rad");
  auto positive = [&](const char* key, double* value) {
    *value = f.getDouble(key, *value);
    if (!(*value > 0.0)) f[key].fail("must be positive");
  };
  positive("window", &s.window);
  positive("store_rate", &s.store_rate);
  positive("vertical_tolerance", &s.vertical_tolerance);
  positive("min_rest", &s.min_rest);
  positive("min_position_time", &s.min_position_time);
  positive("max_misalignment", &s.max_misalignment);
  if (s.vertical_tolerance >= 0.5) f["vertical_tolerance"].fail("must be below 0.5");
  return s;
}

}  // namespace core
}  // namespace hrg_gyro

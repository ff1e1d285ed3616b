#include "hrg_gyro/core/alignment/earth_checks.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "hrg_gyro/core/common/units.h"
#include "hrg_gyro/core/model/earth_rate.h"

namespace hrg_gyro {
namespace core {
namespace {

// Below these the checks do not judge: a noiseless session's own rounding and model approximations.
constexpr double kRateFloor = 1e-6 * kEarthRotationRate, kAngleFloor = 1e-6;  // rad/s, rad

EarthCheck make(const char* name, double measured, double expected, double variance, double sigmas, double floor) {
  EarthCheck c;
  c.name = name;
  c.measured = measured;
  c.expected = expected;
  c.sigma = std::sqrt(std::max(variance, 0.0) + floor * floor);
  c.passed = std::isfinite(measured) && std::abs(measured - expected) <= sigmas * c.sigma;
  return c;
}

}  // namespace

std::string EarthCheck::describe() const {
  char buffer[512];
  const double z = sigma > 0.0 ? (measured - expected) / sigma : INFINITY;
  if (name == "length") {
    std::snprintf(buffer, sizeof buffer,
                  "the Earth's rate measured is %.5g rad/s long, the Earth's is %.5g (sigma %.2g, %.1f sigmas): "
                  "a gyro bias or scale far beyond the calibration's, or a base that turns",
                  measured, expected, sigma, z);
  } else if (name == "vertical") {
    std::snprintf(buffer, sizeof buffer,
                  "the Earth's rate's part along the measured up is %.5g rad/s, Omega sin(latitude) is %.5g "
                  "(sigma %.2g, %.1f sigmas): a wrong latitude or its sign, an accelerometer that reports "
                  "gravity (-g up) instead of the specific force, or a gross vertical bias",
                  measured, expected, sigma, z);
  } else {
    std::snprintf(buffer, sizeof buffer,
                  "the angle between the Earth's rate and the measured up is %.5g rad, 90 deg - latitude is "
                  "%.5g (sigma %.2g, %.1f sigmas): an accelerometer axis reversed or swapped, its mounting "
                  "far from the one set, or a wrong latitude",
                  measured, expected, sigma, z);
  }
  return buffer;
}

std::vector<EarthCheck> checkAgainstTheEarth(const Eigen::Vector3d& w, const Eigen::Matrix3d& wc,
                                             const Eigen::Vector3d& up, const Eigen::Matrix3d& uc, double latitude,
                                             double sigmas, bool vertical_measured) {
  std::vector<EarthCheck> out;
  const double length = w.norm();
  const Eigen::Vector3d wh = length > 0.0 ? Eigen::Vector3d(w / length) : Eigen::Vector3d::Zero();
  out.push_back(make("length", length, kEarthRotationRate, wh.dot(wc * wh), sigmas, kRateFloor));
  if (!vertical_measured) return out;
  const Eigen::Vector3d u = up.normalized();
  out.push_back(
      make("vertical", w.dot(u), verticalEarthRate(latitude), u.dot(wc * u) + w.dot(uc * w), sigmas, kRateFloor));
  const double cosine = std::clamp(wh.dot(u), -1.0, 1.0), sine = std::sqrt(std::max(1.0 - cosine * cosine, 1e-300));
  const Eigen::Vector3d by_rate = -(u - cosine * wh) / (length * sine), by_up = -wh / sine;
  out.push_back(make("angle", std::acos(cosine), 0.5 * kPi - latitude,
                     by_rate.dot(wc * by_rate) + by_up.dot(uc * by_up), sigmas, kAngleFloor));
  return out;
}

std::optional<EarthCheck> firstFailed(const std::vector<EarthCheck>& checks) {
  for (const EarthCheck& c : checks) {
    if (!c.passed) return c;
  }
  return std::nullopt;
}

Eigen::Matrix3d upCovarianceFromLevel(double roll, double pitch, const Eigen::Matrix2d& level_covariance) {
  const double sr = std::sin(roll), cr = std::cos(roll), sp = std::sin(pitch), cp = std::cos(pitch);
  Eigen::Matrix<double, 3, 2> j;
  j.col(0) << 0.0, cp * cr, -cp * sr;
  j.col(1) << -cp, -sp * sr, -sp * cr;
  return j * level_covariance * j.transpose();
}

}  // namespace core
}  // namespace hrg_gyro

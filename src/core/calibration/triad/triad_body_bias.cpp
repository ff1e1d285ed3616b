#include "hrg_gyro/core/calibration/triad/triad_body_bias.h"

#include <cmath>

#include "hrg_gyro/core/common/number_format.h"
#include "hrg_gyro/core/model/earth_rate.h"

namespace hrg_gyro {
namespace core {
namespace {

/// Axis `i`'s mean rate over the rest [begin, end) of `points`, the slope of its alpha, with its
/// standard error from the residuals.
void restRate(const std::vector<TriadPositionSample>& points, std::size_t begin, std::size_t end, int i, double* rate,
              double* rate_std) {
  double st = 0, sa = 0, stt = 0, sta = 0;
  const double n = static_cast<double>(end - begin);
  for (std::size_t k = begin; k < end; ++k) {
    const double t = toSeconds(points[k].stamp - points[begin].stamp);
    st += t;
    sa += points[k].alpha[i];
    stt += t * t;
    sta += t * points[k].alpha[i];
  }
  const double var_t = stt - st * st / n;
  const double slope = (sta - st * sa / n) / var_t;
  double squares = 0.0;
  for (std::size_t k = begin; k < end; ++k) {
    const double t = toSeconds(points[k].stamp - points[begin].stamp);
    const double e = points[k].alpha[i] - (sa / n + slope * (t - st / n));
    squares += e * e;
  }
  *rate = slope;
  *rate_std = std::sqrt(squares / (n - 2.0) / var_t);
}

/// Stage 1's D(theta) is uncertain where the wave rests: that error enters the rate as -dD / K, the
/// same in every rest at this angle (not averaged away by more rests). 0 when the axis has no fit.
double driftStdAt(const CalibrationOutcome& axis, double theta) {
  if (axis.drift.empty() || axis.scale_factor.empty()) return 0.0;
  const HarmonicFitResult& d = axis.drift.front();
  double variance = d.mean_std * d.mean_std;
  for (std::size_t h = 0; h < d.orders.size(); ++h) {
    variance += std::pow(d.cos_std[h] * std::cos(d.orders[h] * theta), 2) +
                std::pow(d.sin_std[h] * std::sin(d.orders[h] * theta), 2);
  }
  return std::sqrt(variance) / std::abs(axis.scale_factor.front().mean);
}

}  // namespace

Eigen::Vector3d earthInPlatter(double latitude, double azimuth, double table_angle) {
  const double heading = azimuth - table_angle;
  const double horizontal = horizontalEarthRate(latitude);
  return Eigen::Vector3d(horizontal * std::cos(heading), horizontal * std::sin(heading), verticalEarthRate(latitude));
}

void measureRests(const TriadLockedPosition& position, double latitude, const TriadCalibrationSettings& settings,
                  TriadOutcome* o) {
  const std::vector<TriadPositionSample>& points = position.samples;
  for (const auto& [begin, end] : plateauRuns(points)) {
    const double duration = toSeconds(points[end - 1].stamp - points[begin].stamp);
    if (!points[begin].is_static || !(duration >= settings.min_rest)) continue;
    TriadRest rest;
    rest.position = position.index;
    rest.name = position.name;
    rest.duration = duration;
    double phi = 0.0;
    for (std::size_t k = begin; k < end; ++k) phi += points[k].phi / (end - begin);
    rest.table_angle = phi;
    for (int i = 0; i < 3; ++i) {
      restRate(points, begin, end, i, &rest.axis_rates(i), &rest.axis_rates_std(i));
      const double n = static_cast<double>(end - begin);
      double theta_mean = 0.0;
      for (std::size_t k = begin; k < end; ++k) theta_mean += points[k].theta[i] / n;
      rest.axis_drift_std(i) = driftStdAt(o->axes[i], theta_mean);
    }
    rest.earth_body = position.body_to_table.transpose() * earthInPlatter(latitude, settings.azimuth, phi);
    o->rests.push_back(rest);
  }
}

void estimateBodyBias(const TriadCalibrationSettings& settings, TriadOutcome* o) {
  if (o->rests.empty()) {
    o->notes.push_back("no rest of " + formatShort(settings.min_rest, 3) +
                       " s or more in a locked position: the body bias was not estimated (the prior's kept)");
    return;
  }
  const Eigen::Matrix3d& m = o->triad.axis_to_body;
  Eigen::Vector3d sum = Eigen::Vector3d::Zero(), noise = Eigen::Vector3d::Zero();
  for (TriadRest& r : o->rests) {
    r.bias = m * r.axis_rates - r.earth_body;
    sum += r.bias;
    noise += (m * r.axis_rates_std.asDiagonal()).rowwise().norm().cwiseAbs2();
  }
  const double n = static_cast<double>(o->rests.size());
  const Eigen::Vector3d mean = sum / n;
  Eigen::Vector3d scatter = Eigen::Vector3d::Zero();
  Eigen::Vector3d drift_variance = Eigen::Vector3d::Zero();  // per axis, mean over the rests
  for (const TriadRest& r : o->rests) {
    scatter += (r.bias - mean).cwiseAbs2();
    drift_variance += r.axis_drift_std.cwiseAbs2() / n;
  }
  Eigen::Vector3d std = (noise / (n * n)).cwiseSqrt();
  if (n >= 3.0) std = std.cwiseMax((scatter / ((n - 1.0) * n)).cwiseSqrt());
  // Plus the axes' D(theta) uncertainty at the rests, through M: common to the rests, so it is
  // added, not divided by their number.
  const Eigen::Vector3d drift_part = (m.cwiseAbs2() * drift_variance).cwiseSqrt();
  std = (std.cwiseAbs2() + drift_part.cwiseAbs2()).cwiseSqrt();
  o->triad.bias = mean;
  o->triad.bias_std = std;
  o->bias_estimated = true;
}

}  // namespace core
}  // namespace hrg_gyro

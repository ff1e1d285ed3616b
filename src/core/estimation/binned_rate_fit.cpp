#include "hrg_gyro/core/estimation/binned_rate_fit.h"

#include <algorithm>
#include <cmath>

#include "hrg_gyro/core/common/units.h"

namespace hrg_gyro {
namespace core {

HarmonicFitResult fitBinnedRates(const ThetaBinnedRates& group, const std::vector<int>& orders, double min_bin_time,
                                 double max_condition) {
  std::vector<FitPoint> points;
  std::vector<int> used;
  for (int b = 0; b < group.binCount(); ++b) {
    if (group.binTime(b) < min_bin_time || group.binTime(b) <= 0.0) continue;
    FitPoint p{group.binCenter(b), group.binRate(b), group.binTime(b), group.binWidth(), {}};
    for (int k : orders) p.averaged_basis.emplace_back(group.basisMean(b, k, false), group.basisMean(b, k, true));
    points.push_back(std::move(p));
    used.push_back(b);
  }
  const Eigen::MatrixXd covariance = group.rateCovariance(used);
  // Window smoothing: the difference of consecutive window means weights the rate by a triangle.
  std::vector<double> window(orders.size());
  for (std::size_t j = 0; j < orders.size(); ++j) {
    const double s = sinc(0.5 * orders[j] * group.windowSpan());
    window[j] = s * s;
  }
  return fitHarmonics(points, orders, window, max_condition, &covariance);
}

BinnedTwoRateFit fitBinnedTwoRates(const ThetaBinnedRates& g1, double r1, const ThetaBinnedRates& g2, double r2,
                                   const std::vector<int>& k_orders, const std::vector<int>& d_orders,
                                   double min_bin_time, double max_condition) {
  BinnedTwoRateFit e;
  if (!(std::abs(r1 - r2) > 0.0)) {
    e.reason = "the two plateau rates are equal";
    return e;
  }
  const std::vector<int> orders = mergeOrders(k_orders, d_orders);
  e.group_fit[0] = fitBinnedRates(g1, orders, min_bin_time, max_condition);
  e.group_fit[1] = fitBinnedRates(g2, orders, min_bin_time, max_condition);
  for (int g = 0; g < 2; ++g) {
    if (!e.group_fit[g].ok) {
      e.reason = "plateau group " + std::to_string(g + 1) + ": " + e.group_fit[g].reason;
      return e;
    }
  }
  e.smoothing_factor = std::min(e.group_fit[0].smallest_attenuation, e.group_fit[1].smallest_attenuation);
  const double dr = r1 - r2;
  const std::vector<double> c1 = e.group_fit[0].terms(), c2 = e.group_fit[1].terms();
  const std::vector<double> s1 = e.group_fit[0].termStds(), s2 = e.group_fit[1].termStds();
  HarmonicFitResult k = e.group_fit[0], d = e.group_fit[0];
  const std::size_t h = orders.size();
  auto assign = [h](HarmonicFitResult* f, std::size_t t, double value, double sd) {
    if (t == 0) {
      f->mean = value;
      f->mean_std = sd;
    } else if (t <= h) {
      f->cos[t - 1] = value;
      f->cos_std[t - 1] = sd;
    } else {
      f->sin[t - 1 - h] = value;
      f->sin_std[t - 1 - h] = sd;
    }
  };
  for (std::size_t t = 0; t < c1.size(); ++t) {
    assign(&k, t, (c1[t] - c2[t]) / dr, std::hypot(s1[t], s2[t]) / std::abs(dr));
    assign(&d, t, (c2[t] * r1 - c1[t] * r2) / dr, std::hypot(s2[t] * r1, s1[t] * r2) / std::abs(dr));
  }
  k.condition_number = d.condition_number = std::max(e.group_fit[0].condition_number, e.group_fit[1].condition_number);

  // Binned K and D where both groups have data; residuals against the (equally smoothed) fit.
  double k_ss = 0.0, d_ss = 0.0;
  for (int b = 0; b < g1.binCount(); ++b) {
    const double t1 = g1.binTime(b), t2 = g2.binTime(b);
    if (t1 < min_bin_time || t2 < min_bin_time || t1 <= 0.0 || t2 <= 0.0) continue;
    BinnedCurvePoint p;
    p.theta = g1.binCenter(b);
    p.k = (g1.binRate(b) - g2.binRate(b)) / dr;
    p.d = (g2.binRate(b) * r1 - g1.binRate(b) * r2) / dr;
    p.weight = std::min(t1, t2);
    e.binned.push_back(p);
    // Compare with the model seen the way the data see it: averaged over each group's increments
    // and smoothed by its window.
    double r1_model = e.group_fit[0].mean, r2_model = e.group_fit[1].mean;
    for (std::size_t j = 0; j < h; ++j) {
      const int order = orders[j];
      const double w1 = std::pow(sinc(0.5 * order * g1.windowSpan()), 2);
      const double w2 = std::pow(sinc(0.5 * order * g2.windowSpan()), 2);
      r1_model += w1 * (e.group_fit[0].cos[j] * g1.basisMean(b, order, false) +
                        e.group_fit[0].sin[j] * g1.basisMean(b, order, true));
      r2_model += w2 * (e.group_fit[1].cos[j] * g2.basisMean(b, order, false) +
                        e.group_fit[1].sin[j] * g2.basisMean(b, order, true));
    }
    const double k_smooth = (r1_model - r2_model) / dr, d_smooth = (r2_model * r1 - r1_model * r2) / dr;
    k_ss += (p.k - k_smooth) * (p.k - k_smooth);
    d_ss += (p.d - d_smooth) * (p.d - d_smooth);
  }
  const double n = static_cast<double>(e.binned.size());
  k.residual_rms = n > 0 ? std::sqrt(k_ss / n) : 0.0;
  d.residual_rms = n > 0 ? std::sqrt(d_ss / n) : 0.0;
  k.points = d.points = e.binned.size();
  e.k = selectOrders(k, k_orders);
  e.d = selectOrders(d, d_orders);
  e.ok = true;
  return e;
}

}  // namespace core
}  // namespace hrg_gyro

#include "hrg_gyro/core/estimation/increment_bins.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <utility>

#include "hrg_gyro/core/common/units.h"

namespace hrg_gyro {
namespace core {

IncrementBins::IncrementBins(int bins, int columns) : bins_(bins), m_(columns) {
  if (bins_ <= 0) throw std::invalid_argument("increment regression: bins must be positive");
}

int IncrementBins::binOf(double theta) const {
  double folded = std::fmod(theta, kPi);
  if (folded < 0.0) folded += kPi;
  return std::min(bins_ - 1, static_cast<int>(folded / (kPi / bins_)));
}

void IncrementBins::add(const WindowIncrement& increment) {
  const int bin = binOf(increment.theta_mid);
  auto& group_bins = bins_by_group_[increment.group];
  if (group_bins.empty()) group_bins.assign(bins_, BinSums{Eigen::VectorXd::Zero(m_ + 1), 0.0, 0.0});
  group_bins[bin].w += increment.dw;
  group_bins[bin].dt += increment.dt;
  group_bins[bin].dphi += increment.dphi;
  group_time_[increment.group] += increment.dt;
}

IncrementBinnedCurves IncrementBins::curves(const std::vector<int>& sel, const Eigen::VectorXd& beta,
                                            const Eigen::MatrixXd& map, const HarmonicModel& k_model,
                                            const HarmonicModel& d_model, double earth_rate,
                                            double min_bin_time) const {
  const int p = static_cast<int>(sel.size());
  std::vector<std::pair<double, int>> by_time;
  for (const auto& gt : group_time_) by_time.emplace_back(gt.second, gt.first);
  std::sort(by_time.rbegin(), by_time.rend());
  IncrementBinnedCurves out;
  double k_ss = 0.0, d_ss = 0.0;
  if (by_time.size() >= 2) {
    const auto& b1 = bins_by_group_.at(by_time[0].second);
    const auto& b2 = bins_by_group_.at(by_time[1].second);
    auto residualRate = [&](const BinSums& s) {
      const Eigen::VectorXd w = map * s.w;
      double model = 0.0;
      for (int i = 0; i < p; ++i) model += w(sel[i]) * beta(i);
      return (w(m_) - model) / s.dt;
    };
    for (int b = 0; b < bins_; ++b) {
      if (b1[b].dt < min_bin_time || b2[b].dt < min_bin_time || b1[b].dt <= 0.0 || b2[b].dt <= 0.0) continue;
      const double r1 = residualRate(b1[b]), r2 = residualRate(b2[b]);
      const double w1 = b1[b].dphi / b1[b].dt + earth_rate, w2 = b2[b].dphi / b2[b].dt + earth_rate;
      if (!(std::abs(w1 - w2) > 0.0)) continue;
      BinnedCurvePoint point;
      point.theta = (b + 0.5) * kPi / bins_;
      const double k_residual = (r1 - r2) / (w1 - w2), d_residual = (r2 * w1 - r1 * w2) / (w1 - w2);
      point.k = k_model(point.theta) + k_residual;
      point.d = d_model(point.theta) + d_residual;
      point.weight = std::min(b1[b].dt, b2[b].dt);
      out.points.push_back(point);
      k_ss += k_residual * k_residual;
      d_ss += d_residual * d_residual;
    }
  }
  const double shown = static_cast<double>(out.points.size());
  out.k_residual_rms = shown > 0 ? std::sqrt(k_ss / shown) : 0.0;
  out.d_residual_rms = shown > 0 ? std::sqrt(d_ss / shown) : 0.0;
  return out;
}

}  // namespace core
}  // namespace hrg_gyro

#include "hrg_gyro/core/calibration/increment_chains.h"

#include <algorithm>
#include <cmath>

#include "hrg_gyro/core/estimation/rate_groups.h"

namespace hrg_gyro {
namespace core {

IncrementChains::IncrementChains(const CalibrationSettings& s, int top_order, double theta_per_rate)
    : window_(s.window),
      window_span_(s.window_span),
      max_gap_(s.plateau.max_gap),
      group_tolerance_(s.group_tolerance),
      top_order_(top_order),
      theta_per_rate_(theta_per_rate) {}

double IncrementChains::window(double plateau_rate) const {
  const double sweep = std::abs(theta_per_rate_ * plateau_rate);
  const double span = std::min(window_span_, top_order_ > 0 ? 1.0 / top_order_ : window_span_);
  return sweep > 0.0 ? std::min(window_, span / sweep) : window_;
}

bool IncrementChains::follow(const PlateauSample& s, IncrementRegression* regression) {
  since_last_ = toSeconds(s.stamp - last_stamp_);
  const bool gap = in_chain_ && since_last_ > max_gap_;
  const bool starts = !in_chain_ || s.plateau.id != chain_plateau_ || gap || s.stamp <= last_stamp_;
  if (starts) {
    const int group = regressionGroupOf(&group_rates_, s.plateau.rate, group_tolerance_);
    regression->startChain(group, window(s.plateau.rate));
    in_chain_ = true;
    chain_plateau_ = s.plateau.id;
  }
  last_stamp_ = s.stamp;
  return starts;
}

}  // namespace core
}  // namespace hrg_gyro

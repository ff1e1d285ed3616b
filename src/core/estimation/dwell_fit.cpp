#include "hrg_gyro/core/estimation/dwell_fit.h"

#include <algorithm>

namespace hrg_gyro {
namespace core {

void DwellFit::add(Nanoseconds stamp, double theta, double table_angle) {
  if (n_ == 0) {
    start_ = stamp;
    theta0_ = theta;
  }
  end_ = stamp;
  const double t = toSeconds(stamp - start_), th = theta - theta0_;
  t_ += t;
  th_ += th;
  tt_ += t * t;
  tth_ += t * th;
  thth_ += th * th;
  angle_ += table_angle;
  ++n_;
}

double DwellFit::slope() const {
  const double n = static_cast<double>(n_);
  const double sxx = tt_ - t_ * t_ / n;
  return n_ > 1 && sxx > 0.0 ? (tth_ - t_ * th_ / n) / sxx : 0.0;
}

double DwellFit::residualStd() const {
  if (n_ < 3) return 0.0;
  const double n = static_cast<double>(n_);
  const double sxx = tt_ - t_ * t_ / n, syy = thth_ - th_ * th_ / n, sxy = tth_ - t_ * th_ / n;
  const double rss = std::max(0.0, syy - (sxx > 0.0 ? sxy * sxy / sxx : 0.0));
  return std::sqrt(rss / (n - 2.0));
}

double DwellFit::slopeStd() const {
  const double n = static_cast<double>(n_);
  const double sxx = tt_ - t_ * t_ / n;
  return sxx > 0.0 ? residualStd() / std::sqrt(sxx) : 0.0;
}

double DwellFit::valueAt(Nanoseconds stamp) const {
  if (n_ == 0) return 0.0;
  const double n = static_cast<double>(n_);
  const double t_mean = t_ / n, th_mean = th_ / n;
  return theta0_ + th_mean + slope() * (toSeconds(stamp - start_) - t_mean);
}

}  // namespace core
}  // namespace hrg_gyro

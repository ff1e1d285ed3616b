#include "hrg_gyro/core/estimation/theta_binned_rates.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace hrg_gyro {
namespace core {

ThetaBinnedRates::ThetaBinnedRates(int bins, double window_seconds, int max_order)
    : bins_(bins > 0 ? bins : throw std::invalid_argument("bins must be positive")),
      max_order_(max_order),
      basis_(static_cast<std::size_t>(bins) * 2 * (max_order / 2), 0.0),
      window_ns_(toNanoseconds(window_seconds)),
      basis_eval_(2, max_order) {
  if (window_seconds < 0.0) throw std::invalid_argument("window must be >= 0");
  if (max_order < 2 || max_order % 2 != 0) throw std::invalid_argument("max order must be even and >= 2");
}

void ThetaBinnedRates::breakChain() {
  block_ = Block();
  has_previous_mean_ = false;
  previous_bin_ = -1;
  history_ = 0;
}

void ThetaBinnedRates::add(Nanoseconds stamp, double theta, double y, double tag) {
  if (!has_origin_) {
    has_origin_ = true;
    origin_ = stamp;
  }
  ++samples_;
  // Noise of y: the deviation of each sample from the straight line through its two neighbours,
  // r = y1 - (w0 y0 + w2 y2), has variance sigma^2 (1 + w0^2 + w2^2) for white noise and any
  // spacing, so a missing sample (uneven dt) does not pass the signal's slope off as noise.
  if (history_ >= 2) {
    const double span = toSeconds(stamp - t2_);
    if (span > 0.0) {
      const double w0 = toSeconds(stamp - t1_) / span, w2 = toSeconds(t1_ - t2_) / span;
      const double r = y1_ - (w0 * y2_ + w2 * y);
      d2_sum_ += r * r / (1.0 + w0 * w0 + w2 * w2);
      ++d2_n_;
    }
  }
  y2_ = y1_;
  y1_ = y;
  t2_ = t1_;
  t1_ = stamp;
  if (history_ < 2) ++history_;

  if (block_.n == 0) block_.start = stamp;
  block_.t_sum += toSeconds(stamp - origin_);
  block_.theta_sum += theta;
  block_.y_sum += y;
  block_.tag_sum += tag;
  ++block_.n;
  if (stamp - block_.start >= window_ns_) closeBlock();
}

void ThetaBinnedRates::closeBlock() {
  const double n = static_cast<double>(block_.n);
  const double t = block_.t_sum / n, theta = block_.theta_sum / n, y = block_.y_sum / n, tag = block_.tag_sum / n;
  window_samples_ += block_.n;
  block_ = Block();
  if (has_previous_mean_) {
    const double dt = t - previous_t_;
    if (dt > 0.0) {
      const double mid = 0.5 * (theta + previous_theta_);
      int b = static_cast<int>(positiveModulo(mid, kPi) / binWidth());
      if (b >= binCount()) b = binCount() - 1;
      bins_[b].dy += y - previous_y_;
      bins_[b].dt += dt;
      bins_[b].tag += dt * 0.5 * (tag + previous_tag_);
      if (b != previous_bin_) {
        ++bins_[b].runs;
        if (previous_bin_ >= 0) {
          const int n = binCount();
          if ((previous_bin_ + 1) % n == b) {
            ++bins_[previous_bin_].shared_next;
          } else if ((b + 1) % n == previous_bin_) {
            ++bins_[b].shared_next;
          } else {
            ++shared_far_[std::minmax(b, previous_bin_)];
          }
        }
        previous_bin_ = b;
      }
      basis_eval_.evaluate(mid);
      double* row = &basis_[static_cast<std::size_t>(b) * 2 * (max_order_ / 2)];
      for (int k = 2; k <= max_order_; k += 2) {
        row[2 * (k / 2 - 1)] += dt * basis_eval_.cosOf(k);
        row[2 * (k / 2 - 1) + 1] += dt * basis_eval_.sinOf(k);
      }
      total_time_ += dt;
      theta_swept_ += std::abs(theta - previous_theta_);
      sweep(std::min(theta, previous_theta_), std::max(theta, previous_theta_), dt);
      ++increments_;
    }
  }
  has_previous_mean_ = true;
  previous_t_ = t;
  previous_theta_ = theta;
  previous_y_ = y;
  previous_tag_ = tag;
}

void ThetaBinnedRates::sweep(double lo, double hi, double dt) {
  const double w = binWidth();
  const double span = hi - lo;
  if (span <= 0.0 || span >= kPi) {
    // At rest in angle, or a full half-turn in one increment: time goes to the bin(s) evenly.
    if (span <= 0.0) {
      bins_[std::min(binCount() - 1, static_cast<int>(positiveModulo(lo, kPi) / w))].swept += dt;
    } else {
      for (Bin& b : bins_) b.swept += dt / binCount();
    }
    return;
  }
  // Whole bins by index (the angle is continuous; bin i covers [i w, (i + 1) w) modulo pi).
  const long first = static_cast<long>(std::floor(lo / w)), last = static_cast<long>(std::floor(hi / w));
  const long n = binCount();
  for (long i = first; i <= last; ++i) {
    const double overlap = std::min(hi, (i + 1) * w) - std::max(lo, i * w);
    if (overlap > 0.0) bins_[((i % n) + n) % n].swept += dt * overlap / span;
  }
}

double ThetaBinnedRates::coverage(double min_time) const {
  int covered = 0;
  for (const Bin& b : bins_) covered += b.swept >= min_time && b.swept > 0.0 ? 1 : 0;
  return static_cast<double>(covered) / binCount();
}

Eigen::MatrixXd ThetaBinnedRates::rateCovariance(const std::vector<int>& bins) const {
  const double s2 = windowNoise() * windowNoise();
  const std::size_t m = bins.size();
  Eigen::MatrixXd cov = Eigen::MatrixXd::Zero(m, m);
  std::map<int, std::size_t> index;
  for (std::size_t i = 0; i < m; ++i) index[bins[i]] = i;
  const int n = binCount();
  for (std::size_t i = 0; i < m; ++i) {
    const Bin& bi = bins_[bins[i]];
    cov(i, i) = 2.0 * bi.runs * s2 / (bi.dt * bi.dt);
    const auto next = index.find((bins[i] + 1) % n);
    if (next != index.end() && next->second != i) {
      const Bin& bj = bins_[bins[next->second]];
      const double c = -static_cast<double>(bi.shared_next) * s2 / (bi.dt * bj.dt);
      cov(i, next->second) += c;
      cov(next->second, i) += c;
    }
  }
  for (const auto& kv : shared_far_) {
    const auto a = index.find(kv.first.first), b = index.find(kv.first.second);
    if (a == index.end() || b == index.end()) continue;
    const double c = -static_cast<double>(kv.second) * s2 / (bins_[kv.first.first].dt * bins_[kv.first.second].dt);
    cov(a->second, b->second) += c;
    cov(b->second, a->second) += c;
  }
  return cov;
}

double ThetaBinnedRates::sampleNoise() const { return d2_n_ > 0 ? std::sqrt(d2_sum_ / d2_n_) : 0.0; }

double ThetaBinnedRates::windowNoise() const {
  if (increments_ == 0) return sampleNoise();
  const double per_window = static_cast<double>(window_samples_) / static_cast<double>(increments_ + 1);
  return sampleNoise() / std::sqrt(std::max(1.0, per_window));
}

}  // namespace core
}  // namespace hrg_gyro

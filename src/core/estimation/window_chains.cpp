#include "hrg_gyro/core/estimation/window_chains.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>
#include <utility>

namespace hrg_gyro {
namespace core {
namespace {

// rad^2: table errors below a nanoradian are rounding, not noise (two exact logs stay on the angle).
constexpr double kNegligibleTableNoise = 1e-18;
// Window increments seen before the two table sources are weighed (until then, the angle alone).
constexpr std::size_t kMinSourceIncrements = 16;

}  // namespace

WindowChains::WindowChains(const IncrementModel& model) : basis_(model.basis()) {
  const int n_all = static_cast<int>(model.allOrders().size());
  slot_seen_.assign(model.horizontalSlots(), false);
  cos_prev_ = sin_prev_ = cos_now_ = sin_now_ = Eigen::VectorXd::Zero(n_all);
  integrals_ = Eigen::VectorXd::Zero(model.rawY());
  sum_.w = Eigen::VectorXd::Zero(model.rawY() + 1);
}

void WindowChains::start(int group, double window) {
  if (!(window > 0.0)) throw std::invalid_argument("increment regression: window must be positive");
  in_chain_ = true;
  group_ = group;
  window_ = window;
}

void WindowChains::add(const IncrementModel& model, Nanoseconds stamp, double theta, double phi, double phi_rate,
                       int horizontal_slot, double psi) {
  if (!in_chain_) throw std::logic_error("increment regression: add() outside a chain");
  if (horizontal_slot >= model.horizontalSlots())
    throw std::invalid_argument("increment regression: horizontal slot " + std::to_string(horizontal_slot) +
                                " beyond the " + std::to_string(model.horizontalSlots()) + " asked for");
  if (!has_sample_) origin_ = stamp;
  if (!has_origin_) {
    has_origin_ = true;
    session_origin_ = stamp;
  }
  const double t = toSeconds(stamp - origin_);
  const double t_session = toSeconds(stamp - session_origin_);
  last_session_time_ = std::max(last_session_time_, t_session);
  basis_.evaluate(theta);
  const std::vector<int>& orders = model.allOrders();
  for (std::size_t u = 0; u < orders.size(); ++u) {
    cos_now_(u) = basis_.cosOf(orders[u]);
    sin_now_(u) = basis_.sinOf(orders[u]);
  }
  if (!std::isfinite(phi_rate)) chain_has_rate_ = false;
  if (has_sample_) {
    integrate(model, t, t_session, phi, phi_rate, horizontal_slot, psi);
  } else {
    integrals_.setZero();
    theta_start_ = theta;
    window_index_ = 0;
  }
  noise_.add(t, theta);
  sumIntoWindow(t, t_session, theta, phi, phi_rate);

  has_sample_ = true;
  t_prev_ = t;
  session_t_prev_ = t_session;
  phi_prev_ = phi;
  phi_rate_prev_ = phi_rate;
  slot_prev_ = horizontal_slot;
  psi_prev_ = psi;
  cos_prev_.swap(cos_now_);
  sin_prev_.swap(sin_now_);
}

void WindowChains::integrate(const IncrementModel& model, double t, double t_session, double phi, double phi_rate,
                             int horizontal_slot, double psi) {
  IncrementStep step{&cos_now_, &sin_now_, &cos_prev_, &sin_prev_};
  step.dt = t - t_prev_;
  step.dphi = phi - phi_prev_;
  step.has_rate = chain_has_rate_;
  if (chain_has_rate_) step.drate = phi_rate - phi_rate_prev_;
  step.t_session = t_session;
  step.t_session_before = session_t_prev_;
  model.integrate(step, &integrals_);
  if (horizontal_slot >= 0) {
    // Trapezoid within the slot; a sample that starts a slot inside a chain counts from itself.
    const bool same = slot_prev_ == horizontal_slot;
    model.integrateHorizontal(horizontal_slot, psi, same ? psi_prev_ : psi, step.dt, &integrals_);
    slot_seen_[horizontal_slot] = true;
  }
}

void WindowChains::sumIntoWindow(double t, double t_session, double theta, double phi, double phi_rate) {
  const long index = static_cast<long>(std::floor(t / window_));
  if (index != window_index_ && sum_.count > 0.0) closeWindow();
  window_index_ = index;
  const int raw_y = static_cast<int>(integrals_.size());
  sum_.w.head(raw_y) += integrals_;
  sum_.w(raw_y) += theta - theta_start_;
  sum_.t += t;
  sum_.t_session += t_session;
  sum_.theta += theta;
  sum_.phi += phi;
  if (chain_has_rate_) {
    sum_.phi_rate += phi_rate;
    const double x = phi - phi_rate;
    line_.n += 1.0;
    line_.t += t;
    line_.tt += t * t;
    line_.x += x;
    line_.tx += t * x;
  }
  sum_.count += 1.0;
}

void WindowChains::closeWindow() {
  // Held until the chain ends: the table's slope on the chain and the two sources' weights are
  // known only then.
  WindowMean mean;
  mean.w = sum_.w / sum_.count;
  mean.t = sum_.t / sum_.count;
  mean.t_session = sum_.t_session / sum_.count;
  mean.theta = sum_.theta / sum_.count;
  mean.phi = sum_.phi / sum_.count;
  mean.phi_rate = sum_.phi_rate / sum_.count;
  mean.x = mean.phi - mean.phi_rate;
  mean.count = sum_.count;
  chain_means_.push_back(std::move(mean));
  clearWindowSums();
}

void WindowChains::clearWindowSums() {
  sum_.w.setZero();
  sum_.t = sum_.t_session = sum_.theta = sum_.phi = sum_.phi_rate = sum_.count = 0.0;
}

double WindowChains::chainSlope() const {
  double slope = 0.0;
  const double stt = line_.tt - line_.t * line_.t / line_.n, stx = line_.tx - line_.t * line_.x / line_.n;
  if (line_.n >= 2.0 && stt > 0.0) slope = stx / stt;
  return slope;
}

double WindowChains::weighSources(double slope) {
  // What the session says of the two sources: on consecutive window means, the angle minus the rate
  // integral (the chain's slope removed) moves by the angle's white noise (differences
  // anti-correlated at lag one) and by the integral's wander (uncorrelated differences: rate noise,
  // ripple the logged rate misses). An increment's error from the angle is twice its noise per window
  // mean (plus what regularised stamps leave, smooth and so not in the scatter); from the integral,
  // the wander. The weighted sum with the least variance; both clean (a rate differenced from the
  // angle is the angle again, smoothed): the angle, as without a rate.
  double previous_difference = 0.0;
  for (std::size_t i = 1; chain_has_rate_ && i < chain_means_.size(); ++i) {
    const WindowMean& a = chain_means_[i - 1];
    const WindowMean& b = chain_means_[i];
    const double difference = (b.x - a.x) - slope * (b.t - a.t);
    source_squares_ += difference * difference;
    ++source_count_;
    if (i >= 2) {
      source_lag_ += difference * previous_difference;
      ++source_lag_count_;
    }
    previous_difference = difference;
  }
  double weight = 1.0;  // of the angle
  if (chain_has_rate_ && source_count_ >= kMinSourceIncrements && source_lag_count_ >= kMinSourceIncrements / 2) {
    const double variance = source_squares_ / source_count_, lag = source_lag_ / source_lag_count_;
    // Each part only where the data show it beyond their own scatter (a lag-one covariance of N
    // differences scatters by about variance / sqrt(N)): a clean source is not blamed for chance.
    const double resolution =
        std::max(kNegligibleTableNoise, 2.0 * variance / std::sqrt(static_cast<double>(source_lag_count_)));
    const double angle_noise = -lag > resolution ? -lag : 0.0;
    const double remainder = variance - 2.0 * angle_noise;
    const double wander = remainder > resolution ? remainder : 0.0;
    const double angle = 2.0 * (angle_noise + angle_smooth_error_);
    if (angle + wander > 0.0) weight = wander / (angle + wander);
  }
  return weight;
}

std::vector<WindowIncrement> WindowChains::end(const IncrementModel& model) {
  std::vector<WindowIncrement> increments;
  if (in_chain_ && !chain_means_.empty()) {
    const double slope = chainSlope();
    const double weight = weighSources(slope);
    const double chain_time = chain_means_.back().t - chain_means_.front().t;
    angle_weight_time_ += weight * chain_time;
    weighted_chain_time_ += chain_time;
    const int m = model.columns();
    for (std::size_t i = 0; i < chain_means_.size(); ++i) {
      WindowMean& mean = chain_means_[i];
      Eigen::VectorXd final_w(m + 1);
      final_w.head(m) = mean.w.head(m);
      if (weight < 1.0) {
        for (int j = 0; j < model.kTerms(); ++j) {
          final_w(j) = weight * mean.w(j) +
                       (1.0 - weight) * (mean.w(model.rateK0() + j) + slope * mean.w(model.timeColumnOfK(j)));
        }
        mean.phi = weight * mean.phi + (1.0 - weight) * (mean.phi_rate + slope * mean.t);
      }
      final_w(m) = mean.w(model.rawY());
      mean.w.swap(final_w);
      if (i == 0) continue;
      const WindowMean& a = chain_means_[i - 1];
      WindowIncrement increment;
      increment.dw = mean.w - a.w;
      increment.dt = mean.t - a.t;
      increment.t_mid = 0.5 * (a.t_session + mean.t_session);
      increment.theta_mid = 0.5 * (a.theta + mean.theta);
      increment.dphi = mean.phi - a.phi;
      increment.count_before = a.count;
      increment.count_after = mean.count;
      increment.follows = i >= 2;
      increment.group = group_;
      increments.push_back(std::move(increment));
    }
  }
  in_chain_ = has_sample_ = false;
  noise_.restart();
  clearWindowSums();
  chain_means_.clear();
  line_ = LineSums();
  chain_has_rate_ = true;
  return increments;
}

double WindowChains::angleWeight() const {
  return weighted_chain_time_ > 0.0 ? angle_weight_time_ / weighted_chain_time_ : 1.0;
}

}  // namespace core
}  // namespace hrg_gyro

#include "hrg_gyro/core/estimation/increment_regression.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <stdexcept>

#include "hrg_gyro/core/common/weighted_least_squares.h"

namespace hrg_gyro {
namespace core {
namespace {

constexpr std::size_t kMaxBlocks = 64;
constexpr int kMaxTrendOrder = 2;
// rad^2: table errors below a nanoradian are rounding, not noise (two exact logs stay on the angle).
constexpr double kNegligibleTableNoise = 1e-18;
// Window increments seen before the two table sources are weighed (until then, the angle alone).
constexpr std::size_t kMinSourceIncrements = 16;

Eigen::MatrixXd submatrix(const Eigen::MatrixXd& m, const std::vector<int>& rows, const std::vector<int>& cols) {
  Eigen::MatrixXd out(rows.size(), cols.size());
  for (std::size_t i = 0; i < rows.size(); ++i)
    for (std::size_t j = 0; j < cols.size(); ++j) out(i, j) = m(rows[i], cols[j]);
  return out;
}

Eigen::VectorXd column(const Eigen::MatrixXd& m, const std::vector<int>& rows, int col) {
  Eigen::VectorXd out(rows.size());
  for (std::size_t i = 0; i < rows.size(); ++i) out(i) = m(rows[i], col);
  return out;
}

int orderStep(const std::vector<int>& orders) {
  int g = 0;
  for (int k : orders) g = std::gcd(g, k);
  return g > 0 ? g : 1;
}

}  // namespace

IncrementRegression::IncrementRegression(const std::vector<int>& k_orders, const std::vector<int>& d_orders, int bins,
                                         int bias_trend_order, int horizontal_slots)
    : k_orders_(k_orders),
      d_orders_(d_orders),
      all_orders_(mergeOrders(k_orders, d_orders)),
      bins_(bins),
      trend_order_(bias_trend_order),
      horizontal_slots_(horizontal_slots) {
  for (int k : all_orders_)
    if (k <= 0) throw std::invalid_argument("increment regression: harmonic orders must be positive");
  if (bins_ <= 0) throw std::invalid_argument("increment regression: bins must be positive");
  if (trend_order_ < 0 || trend_order_ > kMaxTrendOrder)
    throw std::invalid_argument("increment regression: the bias trend order must be 0, 1 or 2");
  if (horizontal_slots_ < 0) throw std::invalid_argument("increment regression: horizontal slots must be >= 0");
  const int n_k = static_cast<int>(k_orders_.size()), n_all = static_cast<int>(all_orders_.size());
  horizontal0_ = 1 + 2 * n_k + 1 + 2 * n_all + trend_order_;
  m_ = horizontal0_ + 2 * horizontal_slots_;
  slot_seen_.assign(horizontal_slots_, false);
  // Accumulated per sample: the regression's columns with the K block taken along the table angle,
  // then the same K block along the rate integral, then y.
  k_terms_ = 1 + 2 * n_k;
  rate_k0_ = m_;
  raw_y_ = m_ + k_terms_;
  basis_ = HarmonicBasis(orderStep(all_orders_), all_orders_.empty() ? 0 : all_orders_.back());
  cos_prev_ = sin_prev_ = cos_now_ = sin_now_ = Eigen::VectorXd::Zero(n_all);
  for (int k : k_orders_)
    k_in_all_.push_back(
        static_cast<int>(std::lower_bound(all_orders_.begin(), all_orders_.end(), k) - all_orders_.begin()));
  // The T column of each K column's order (K0: T itself): b dt of the chain's slope correction.
  const int t0 = 1 + 2 * n_k;
  time_column_of_k_.push_back(t0);
  for (int j = 0; j < n_k; ++j) time_column_of_k_.push_back(t0 + 1 + k_in_all_[j]);
  for (int j = 0; j < n_k; ++j) time_column_of_k_.push_back(t0 + 1 + n_all + k_in_all_[j]);
  integrals_ = Eigen::VectorXd::Zero(raw_y_);
  sum_.w = Eigen::VectorXd::Zero(raw_y_ + 1);
  previous_mean_.w = Eigen::VectorXd::Zero(m_ + 1);
  open_block_.products = Eigen::MatrixXd::Zero(m_ + 1, m_ + 1);
  open_block_.sum = open_block_.sum_dt = open_block_.prefix_v = open_block_.prefix_p = Eigen::VectorXd::Zero(m_ + 1);
  walk_prefix_ = walk_prefix_integral_ = walk_prefix_v_ = Eigen::VectorXd::Zero(m_ + 1);
  walk_products_ = arw_products_ = Eigen::MatrixXd::Zero(m_ + 1, m_ + 1);
  white_lag0_ = white_lag1_ = Eigen::MatrixXd::Zero(m_, m_);
}

void IncrementRegression::startChain(int group, double window) {
  endChain();
  if (!(window > 0.0)) throw std::invalid_argument("increment regression: window must be positive");
  in_chain_ = true;
  group_ = group;
  window_ = window;
}

void IncrementRegression::endChain() {
  if (in_chain_) flushChain();
  in_chain_ = has_sample_ = has_mean_ = has_previous_dz_ = false;
  history_ = 0;
  sum_.w.setZero();
  sum_.t = sum_.t_session = sum_.theta = sum_.phi = sum_.phi_rate = sum_.count = 0.0;
  chain_means_.clear();
  line_ = LineSums();
  chain_has_rate_ = true;
}

void IncrementRegression::flushChain() {
  if (chain_means_.empty()) return;
  // The table's slope on this chain, from the angle: the rate integral keeps only its shape.
  double slope = 0.0;
  const double stt = line_.tt - line_.t * line_.t / line_.n, stx = line_.tx - line_.t * line_.x / line_.n;
  if (line_.n >= 2.0 && stt > 0.0) slope = stx / stt;
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
  const double chain_time = chain_means_.back().t - chain_means_.front().t;
  angle_weight_time_ += weight * chain_time;
  weighted_chain_time_ += chain_time;
  for (WindowMean& m : chain_means_) {
    Eigen::VectorXd final_w(m_ + 1);
    final_w.head(m_) = m.w.head(m_);
    if (weight < 1.0) {
      for (int j = 0; j < k_terms_; ++j) {
        final_w(j) = weight * m.w(j) + (1.0 - weight) * (m.w(rate_k0_ + j) + slope * m.w(time_column_of_k_[j]));
      }
      m.phi = weight * m.phi + (1.0 - weight) * (m.phi_rate + slope * m.t);
    }
    final_w(m_) = m.w(raw_y_);
    m.w.swap(final_w);
    if (has_mean_) addIncrement(previous_mean_, m);
    previous_mean_ = m;
    has_mean_ = true;
  }
  chain_means_.clear();
}

void IncrementRegression::add(Nanoseconds stamp, double theta, double phi, double phi_rate, int horizontal_slot,
                              double psi) {
  if (!in_chain_) throw std::logic_error("increment regression: add() outside a chain");
  if (horizontal_slot >= horizontal_slots_)
    throw std::invalid_argument("increment regression: horizontal slot " + std::to_string(horizontal_slot) +
                                " beyond the " + std::to_string(horizontal_slots_) + " asked for");
  if (!has_sample_) origin_ = stamp;
  if (!has_origin_) {
    has_origin_ = true;
    session_origin_ = stamp;
  }
  const double t = toSeconds(stamp - origin_);
  const double t_session = toSeconds(stamp - session_origin_);
  last_session_time_ = std::max(last_session_time_, t_session);
  basis_.evaluate(theta);
  const int n_k = static_cast<int>(k_orders_.size()), n_all = static_cast<int>(all_orders_.size());
  const int t0 = 1 + 2 * n_k;
  Eigen::VectorXd& c = cos_now_;
  Eigen::VectorXd& s = sin_now_;
  for (int u = 0; u < n_all; ++u) {
    c(u) = basis_.cosOf(all_orders_[u]);
    s(u) = basis_.sinOf(all_orders_[u]);
  }
  if (!std::isfinite(phi_rate)) chain_has_rate_ = false;
  if (has_sample_) {
    // Trapezoid of each integrand between the previous sample and this one.
    const double dt = t - t_prev_, dphi = phi - phi_prev_;
    integrals_(0) += dphi;
    for (int j = 0; j < n_k; ++j) {
      const int u = k_in_all_[j];
      integrals_(1 + j) += 0.5 * (c(u) + cos_prev_(u)) * dphi;
      integrals_(1 + n_k + j) += 0.5 * (s(u) + sin_prev_(u)) * dphi;
    }
    if (chain_has_rate_) {
      const double drate = phi_rate - phi_rate_prev_;
      integrals_(rate_k0_) += drate;
      for (int j = 0; j < n_k; ++j) {
        const int u = k_in_all_[j];
        integrals_(rate_k0_ + 1 + j) += 0.5 * (c(u) + cos_prev_(u)) * drate;
        integrals_(rate_k0_ + 1 + n_k + j) += 0.5 * (s(u) + sin_prev_(u)) * drate;
      }
    }
    integrals_(t0) += dt;
    for (int u = 0; u < n_all; ++u) {
      integrals_(t0 + 1 + u) += 0.5 * (c(u) + cos_prev_(u)) * dt;
      integrals_(t0 + 1 + n_all + u) += 0.5 * (s(u) + sin_prev_(u)) * dt;
    }
    // The trend's integrals of t^j dt, exact (a polynomial needs no trapezoid).
    double now_power = t_session, before_power = session_t_prev_;
    for (int j = 1; j <= trend_order_; ++j) {
      now_power *= t_session;
      before_power *= session_t_prev_;
      integrals_(t0 + 1 + 2 * n_all + j - 1) += (now_power - before_power) / (j + 1);
    }
    if (horizontal_slot >= 0) addHorizontal(horizontal_slot, psi, dt);
    addNoiseSample(t, theta);
  } else {
    integrals_.setZero();
    theta_start_ = theta;
    window_index_ = 0;
  }
  h_theta_[0] = h_theta_[1];
  h_t_[0] = h_t_[1];
  h_theta_[1] = theta;
  h_t_[1] = t;
  history_ = std::min(history_ + 1, 2);

  const long index = static_cast<long>(std::floor(t / window_));
  if (index != window_index_ && sum_.count > 0.0) closeWindow();
  window_index_ = index;
  sum_.w.head(raw_y_) += integrals_;
  sum_.w(raw_y_) += theta - theta_start_;
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

void IncrementRegression::addNoiseSample(double t, double theta) {
  // Angle noise: deviation of the previous sample from the line through its neighbours.
  if (history_ < 2) return;
  const double span = t - h_t_[0];
  if (span > 0.0) {
    const double a = (t - h_t_[1]) / span, b = 1.0 - a;
    const double deviation = h_theta_[1] - (a * h_theta_[0] + b * theta);
    noise_sum_ += deviation * deviation / (1.0 + a * a + b * b);
    ++noise_count_;
  }
}

void IncrementRegression::addHorizontal(int slot, double psi, double dt) {
  // Trapezoid within the slot; a sample that starts a slot inside a chain counts from itself.
  const bool same = slot_prev_ == slot;
  const int col = horizontal0_ + 2 * slot;
  integrals_(col) += 0.5 * (std::cos(psi) + std::cos(same ? psi_prev_ : psi)) * dt;
  integrals_(col + 1) += 0.5 * (std::sin(psi) + std::sin(same ? psi_prev_ : psi)) * dt;
  slot_seen_[slot] = true;
}

void IncrementRegression::closeWindow() {
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
  sum_.w.setZero();
  sum_.t = sum_.t_session = sum_.theta = sum_.phi = sum_.phi_rate = sum_.count = 0.0;
}

void IncrementRegression::addIncrement(const WindowMean& a, const WindowMean& b) {
  const Eigen::VectorXd dw = b.w - a.w;
  const double dt = b.t - a.t;
  const double t_mid = 0.5 * (a.t_session + b.t_session);
  open_block_.products.noalias() += dw * dw.transpose();
  // A bias walk b(t) leaves this increment dt b(t_mid): the prefix sums of its covariances.
  if (walk_started_) {
    const double ds = t_mid - walk_time_;
    walk_prefix_integral_ += ds * walk_prefix_;
    walk_products_.noalias() += ds * walk_prefix_ * walk_prefix_.transpose();
  }
  walk_started_ = true;
  walk_time_ = t_mid;
  walk_prefix_ += dt * dw;
  walk_prefix_v_ += dt * t_mid * dw;
  arw_products_.noalias() += dt * dw * dw.transpose();
  open_block_.self += 2.0 * dt * open_block_.moment + dt * dt * t_mid;  // the earlier increments are older
  open_block_.sum += dw;
  open_block_.sum_dt += dt * dw;
  open_block_.prefix_v += dt * walk_prefix_v_;
  open_block_.prefix_p += dt * t_mid * walk_prefix_;
  open_block_.time += dt;
  open_block_.moment += dt * t_mid;
  if (++open_block_.count >= block_size_) {
    blocks_.push_back(open_block_);
    open_block_.products.setZero();
    open_block_.sum.setZero();
    open_block_.sum_dt.setZero();
    open_block_.prefix_v.setZero();
    open_block_.prefix_p.setZero();
    open_block_.time = open_block_.moment = open_block_.self = 0.0;
    open_block_.count = 0;
    if (blocks_.size() >= kMaxBlocks) {
      // Merge neighbours: the sums add, so this is the same data in half as many, longer blocks.
      std::vector<Block> merged;
      for (std::size_t i = 0; i + 1 < blocks_.size(); i += 2) {
        Block m = blocks_[i];
        const Block& next = blocks_[i + 1];
        m.products += next.products;
        m.self += next.self + 2.0 * next.time * m.moment;  // every increment of m is older
        m.sum += next.sum;
        m.sum_dt += next.sum_dt;
        m.prefix_v += next.prefix_v;
        m.prefix_p += next.prefix_p;
        m.time += next.time;
        m.moment += next.moment;
        m.count += blocks_[i + 1].count;
        merged.push_back(m);
      }
      if (blocks_.size() % 2) merged.push_back(blocks_.back());
      blocks_.swap(merged);
      block_size_ *= 2;
    }
  }
  // White wave-angle noise of variance v per sample: a window mean of n samples has v / n; the
  // increment b - a has v (1/n_a + 1/n_b) and shares -v / n_a with the increment before it.
  const Eigen::VectorXd dz = dw.head(m_);
  white_lag0_.noalias() += (1.0 / a.count + 1.0 / b.count) * dz * dz.transpose();
  if (has_previous_dz_) white_lag1_.noalias() += (1.0 / a.count) * dz * previous_dz_.transpose();
  previous_dz_ = dz;
  has_previous_dz_ = true;

  const double theta_mid = 0.5 * (a.theta + b.theta);
  double folded = std::fmod(theta_mid, kPi);
  if (folded < 0.0) folded += kPi;
  const int bin = std::min(bins_ - 1, static_cast<int>(folded / (kPi / bins_)));
  auto& group_bins = bins_by_group_[group_];
  if (group_bins.empty()) group_bins.assign(bins_, BinSums{Eigen::VectorXd::Zero(m_ + 1), 0.0, 0.0});
  group_bins[bin].w += dw;
  group_bins[bin].dt += dt;
  group_bins[bin].dphi += b.phi - a.phi;
  group_time_[group_] += dt;
  ++increments_;
  increment_time_ += dt;
  increment_time_moment_ += dt * 0.5 * (a.t_session + b.t_session);
}

Eigen::MatrixXd IncrementRegression::regressorMap(double earth_rate, double reference_time) const {
  const int n_k = static_cast<int>(k_orders_.size()), n_all = static_cast<int>(all_orders_.size());
  const int t0 = 1 + 2 * n_k, trend0 = t0 + 1 + 2 * n_all;
  auto orderIndex = [&](int k) {
    return static_cast<int>(std::lower_bound(all_orders_.begin(), all_orders_.end(), k) - all_orders_.begin());
  };
  Eigen::MatrixXd map = Eigen::MatrixXd::Identity(m_ + 1, m_ + 1);
  // The Earth rate enters phi as earth_rate * t, so each K regressor gains earth_rate times the T
  // regressor of the same order.
  map(0, t0) = earth_rate;
  for (int j = 0; j < n_k; ++j) {
    map(1 + j, t0 + 1 + orderIndex(k_orders_[j])) = earth_rate;
    map(1 + n_k + j, t0 + 1 + n_all + orderIndex(k_orders_[j])) = earth_rate;
  }
  // The trend's integrals of t^j dt become those of (t - t_ref)^j dt: the binomial expansion over
  // the lower powers (power 0 is the T column).
  for (int j = 1; j <= trend_order_; ++j) {
    double binomial = 1.0;  // C(j, i), from i = 0
    for (int i = 0; i < j; ++i) {
      map(trend0 + j - 1, i == 0 ? t0 : trend0 + i - 1) = binomial * std::pow(-reference_time, j - i);
      binomial = binomial * (j - i) / (i + 1);
    }
  }
  return map;
}

IncrementRegression::Solved IncrementRegression::solveColumns(const std::vector<int>& sel, const Eigen::MatrixXd& map,
                                                              const std::vector<Block>& blocks,
                                                              const Eigen::MatrixXd& total, double angle_noise,
                                                              double max_condition) const {
  Solved out;
  const Eigen::MatrixXd s = map * total * map.transpose();
  out.solution =
      solveNormalEquations(submatrix(s, sel, sel), column(s, sel, m_), ColumnScaling::kUnitNorm, max_condition);
  if (!out.solution.ok) return out;
  const Eigen::VectorXd& beta = out.solution.coefficients;
  const Eigen::MatrixXd& inverse = out.solution.normal_inverse;
  const int p = static_cast<int>(sel.size());
  // Block sandwich: the score of each block at the solution. Neighbouring blocks share the window
  // mean at their boundary (with opposite signs), and that shared term is most of a block's score
  // for white angle noise, so the products of neighbouring scores are kept as well (a lag-one
  // block estimate); blocks further apart share nothing.
  std::vector<Eigen::VectorXd> scores;
  for (const Block& b : blocks) {
    const Eigen::MatrixXd sb = map * b.products * map.transpose();
    scores.push_back(column(sb, sel, m_) - submatrix(sb, sel, sel) * beta);
  }
  Eigen::MatrixXd meat = Eigen::MatrixXd::Zero(p, p);
  for (std::size_t c = 0; c < scores.size(); ++c) {
    meat.noalias() += scores[c] * scores[c].transpose();
    if (c + 1 < scores.size()) {
      const Eigen::MatrixXd cross = scores[c] * scores[c + 1].transpose();
      meat += cross + cross.transpose();
    }
  }
  const double g = static_cast<double>(blocks.size()), n = static_cast<double>(increments_);
  out.sandwich = (g / (g - 1.0)) * ((n - 1.0) / (n - p)) * inverse * meat * inverse;
  // What white wave-angle noise alone predicts (a floor: a few blocks can understate by chance).
  const Eigen::MatrixXd zmap = map.topLeftCorner(m_, m_);
  const Eigen::MatrixXd white_full =
      zmap * (white_lag0_ - white_lag1_ - white_lag1_.transpose()) * zmap.transpose() * (angle_noise * angle_noise);
  out.white = inverse * submatrix(white_full, sel, sel) * inverse;
  return out;
}

BiasWalkFit IncrementRegression::estimateWalk(const std::vector<Block>& blocks, const std::vector<int>& sel,
                                              const Eigen::MatrixXd& map, const LeastSquaresSolution& solution) const {
  // The blocks' residual sums r = s - X_b beta, s the sums of the increments' errors and X_b the
  // blocks' regressor sums. Their covariance for a unit bias walk and for a unit angle random walk,
  // exactly through the fit (which takes much of a walk into K, D and the trend):
  //   Cov(r) = C_ss - X_b inv C_xs - (X_b inv C_xs)^T + X_b inv C_xx inv X_b^T.
  std::vector<const Block*> used;
  for (const Block& b : blocks)
    if (b.time > 0.0) used.push_back(&b);
  const int g = static_cast<int>(used.size()), p = static_cast<int>(sel.size());
  BiasWalkFit walk;
  if (g < 8) return walk;
  const Eigen::MatrixXd& inverse = solution.normal_inverse;
  const Eigen::VectorXd& beta = solution.coefficients;
  auto selected = [&](const Eigen::VectorXd& raw) {
    const Eigen::VectorXd w = map * raw;
    Eigen::VectorXd out(p);
    for (int i = 0; i < p; ++i) out(i) = w(sel[i]);
    return out;
  };
  Eigen::MatrixXd xb(g, p), cxs_walk(p, g), cxs_arw(p, g);
  Eigen::MatrixXd css_walk = Eigen::MatrixXd::Zero(g, g), css_arw = Eigen::MatrixXd::Zero(g, g);
  Eigen::VectorXd r(g);
  for (int k = 0; k < g; ++k) {
    const Block& b = *used[k];
    const Eigen::VectorXd w = map * b.sum;
    xb.row(k) = selected(b.sum).transpose();
    r(k) = w(m_) - xb.row(k).dot(beta);
    cxs_walk.col(k) = selected(b.prefix_v - b.prefix_p + walk_prefix_ * b.moment);
    cxs_arw.col(k) = selected(b.sum_dt);
    css_walk(k, k) = b.self;
    css_arw(k, k) = b.time;
    for (int j = 0; j < k; ++j) css_walk(j, k) = css_walk(k, j) = used[j]->moment * b.time;
  }
  const Eigen::MatrixXd full_walk = map * walkScoreCovariance() * map.transpose();
  const Eigen::MatrixXd full_arw = map * arw_products_ * map.transpose();
  auto residualCovariance = [&](const Eigen::MatrixXd& css, const Eigen::MatrixXd& cxs, const Eigen::MatrixXd& full) {
    const Eigen::MatrixXd projected = xb * inverse;
    const Eigen::MatrixXd cross = projected * cxs;
    return Eigen::MatrixXd(css - cross - cross.transpose() +
                           projected * submatrix(full, sel, sel) * projected.transpose());
  };
  const Eigen::MatrixXd cov_walk = residualCovariance(css_walk, cxs_walk, full_walk);
  const Eigen::MatrixXd cov_arw = residualCovariance(css_arw, cxs_arw, full_arw);
  // Moment equations: the difference of the mean residual rates of neighbouring groups of 1, 2 and
  // 4 blocks, E[d^2] = q^2 v^T Cov_walk v + N^2 v^T Cov_arw v (v the difference's weights).
  std::vector<double> d2, a, c;
  for (int scale = 1; scale <= 4; scale *= 2) {
    for (int first = 0; first + 2 * scale <= g; first += scale) {
      Eigen::VectorXd v = Eigen::VectorXd::Zero(g);
      double t1 = 0.0, t2 = 0.0;
      for (int k = first; k < first + scale; ++k) t1 += used[k]->time;
      for (int k = first + scale; k < first + 2 * scale; ++k) t2 += used[k]->time;
      for (int k = first; k < first + scale; ++k) v(k) = -1.0 / t1;
      for (int k = first + scale; k < first + 2 * scale; ++k) v(k) = 1.0 / t2;
      const double d = v.dot(r);
      d2.push_back(d * d);
      a.push_back(std::max(0.0, v.dot(cov_walk * v)));
      c.push_back(std::max(0.0, v.dot(cov_arw * v)));
    }
  }
  const std::size_t n = d2.size();
  // Weighted least squares, the weights 1 / (2 E^2) of a chi-square of one degree from the previous
  // pass's prediction E (first pass: the mean square); N^2 dropped where it comes out negative.
  double q2 = 0.0, n2 = 0.0, q2_var = 0.0;
  double mean_square = 0.0;
  for (double v : d2) mean_square += v / n;
  if (!(mean_square > 0.0)) return walk;
  for (int pass = 0; pass < 4; ++pass) {
    Eigen::Matrix2d normal = Eigen::Matrix2d::Zero();
    Eigen::Vector2d rhs = Eigen::Vector2d::Zero();
    for (std::size_t i = 0; i < n; ++i) {
      const double e = pass == 0 ? mean_square : std::max(q2 * a[i] + n2 * c[i], 1e-3 * mean_square);
      const double weight = 1.0 / (2.0 * e * e);
      const Eigen::Vector2d row(a[i], c[i]);
      normal.noalias() += weight * row * row.transpose();
      rhs += weight * d2[i] * row;
    }
    const Eigen::Vector2d both = normal.ldlt().solve(rhs);
    if (both(1) >= 0.0 && normal.determinant() > 0.0) {
      q2 = both(0);
      n2 = both(1);
      q2_var = normal.inverse()(0, 0);
    } else {
      q2 = normal(0, 0) > 0.0 ? rhs(0) / normal(0, 0) : 0.0;
      n2 = 0.0;
      q2_var = normal(0, 0) > 0.0 ? 1.0 / normal(0, 0) : 0.0;
    }
    q2 = std::max(q2, 0.0);
  }
  if (!(q2 > 0.0) || !std::isfinite(q2)) return walk;
  walk.rate_random_walk = std::sqrt(q2);
  walk.rate_random_walk_std = std::sqrt(q2_var) / (2.0 * walk.rate_random_walk);
  walk.angle_random_walk = std::sqrt(n2);
  walk.carried = true;
  return walk;
}

Eigen::MatrixXd IncrementRegression::walkScoreCovariance() const {
  // integral over [0, last] of (U - P)(U - P)^T ds, U the whole sum (P = 0 before the first increment).
  const Eigen::VectorXd& u = walk_prefix_;
  const Eigen::VectorXd& integral = walk_prefix_integral_;
  return u * u.transpose() * walk_time_ - u * integral.transpose() - integral * u.transpose() + walk_products_;
}

Eigen::MatrixXd IncrementRegression::walkCovariance(const BiasWalkFit& walk, const std::vector<int>& sel,
                                                    const Eigen::MatrixXd& map, const Eigen::MatrixXd& inverse) const {
  const double q2 = walk.rate_random_walk * walk.rate_random_walk;
  const double n2 = walk.angle_random_walk * walk.angle_random_walk;
  const Eigen::MatrixXd meat = map * (q2 * walkScoreCovariance() + n2 * arw_products_) * map.transpose();
  return inverse * submatrix(meat, sel, sel) * inverse;
}

IncrementRegression::Columns IncrementRegression::fittedColumns() const {
  const int n_k = static_cast<int>(k_orders_.size()), n_all = static_cast<int>(all_orders_.size());
  const int t0 = 1 + 2 * n_k, n_kterms = 1 + 2 * n_k, trend0 = t0 + 1 + 2 * n_all;
  auto orderIndex = [&](int k) {
    return static_cast<int>(std::lower_bound(all_orders_.begin(), all_orders_.end(), k) - all_orders_.begin());
  };
  Columns c;
  for (int j = 0; j < n_kterms; ++j) c.sel.push_back(j);
  c.sel.push_back(t0);
  for (int k : d_orders_) c.sel.push_back(t0 + 1 + orderIndex(k));
  for (int k : d_orders_) c.sel.push_back(t0 + 1 + n_all + orderIndex(k));
  c.without_trend = c.sel;
  c.trend_at = static_cast<int>(c.sel.size());
  for (int j = 0; j < trend_order_; ++j) c.sel.push_back(trend0 + j);
  c.horizontal_at = static_cast<int>(c.sel.size());
  for (int slot = 0; slot < horizontal_slots_; ++slot) {
    if (!slot_seen_[slot]) continue;  // no data: the columns are zero
    c.horizontal.push_back(slot);
    for (int j = 0; j < 2; ++j) {
      c.sel.push_back(horizontal0_ + 2 * slot + j);
      c.without_trend.push_back(horizontal0_ + 2 * slot + j);
    }
  }
  return c;
}

Eigen::VectorXd IncrementRegression::earthRateShift(const std::vector<int>& sel, const Eigen::VectorXd& beta,
                                                    const Eigen::MatrixXd& total, double earth_rate,
                                                    double earth_rate_std, double reference_time,
                                                    double max_condition) const {
  const int p = static_cast<int>(sel.size());
  Eigen::VectorXd earth_shift = Eigen::VectorXd::Zero(p);
  if (earth_rate_std > 0.0) {
    const Eigen::MatrixXd s = regressorMap(earth_rate + earth_rate_std, reference_time) * total *
                              regressorMap(earth_rate + earth_rate_std, reference_time).transpose();
    const LeastSquaresSolution moved =
        solveNormalEquations(submatrix(s, sel, sel), column(s, sel, m_), ColumnScaling::kUnitNorm, max_condition);
    if (moved.ok) earth_shift = (moved.coefficients - beta).cwiseAbs();
  }
  return earth_shift;
}

IncrementRegression::Terms IncrementRegression::correctedTerms(const Solved& solved, const Eigen::VectorXd& earth_shift,
                                                               IncrementFit* fit) const {
  const int n_k = static_cast<int>(k_orders_.size()), n_d = static_cast<int>(d_orders_.size());
  const int n_kterms = 1 + 2 * n_k;
  const Eigen::VectorXd& beta = solved.solution.coefficients;
  const Eigen::MatrixXd& sandwich = solved.sandwich;
  const Eigen::MatrixXd& white = solved.white;
  const Eigen::MatrixXd& walk = solved.walk;
  const int p = static_cast<int>(beta.size());
  // Noise of theta inside the basis attenuates order k by exp(-k^2 s^2 / 2); undo it. A tenth of the
  // correction is taken as its uncertainty: the noise is estimated well (0.05 % at 0.2 rad), but
  // noise correlated from sample to sample would make the estimate off by more.
  auto attenuation = [&](int k) { return std::exp(-0.5 * k * k * fit->angle_noise * fit->angle_noise); };
  std::vector<double> scale(p, 1.0);
  for (int j = 0; j < n_k; ++j) scale[1 + j] = scale[1 + n_k + j] = attenuation(k_orders_[j]);
  for (int j = 0; j < n_d; ++j) scale[n_kterms + 1 + j] = scale[n_kterms + 1 + n_d + j] = attenuation(d_orders_[j]);

  Terms terms;
  terms.value.resize(p);
  terms.total_std.resize(p);
  for (int i = 0; i < p; ++i) {
    terms.value[i] = beta(i) * scale[i];
    const double statistical = std::sqrt(std::max(sandwich(i, i), white(i, i) + walk(i, i))) * scale[i];
    const double noise = std::sqrt(std::max(0.0, white(i, i))) * scale[i];
    const double beyond = std::sqrt(std::max(0.0, sandwich(i, i) - white(i, i))) * scale[i];
    const double earth = earth_shift(i);
    const double basis = 0.1 * std::abs(beta(i)) * (1.0 - scale[i]);
    terms.total_std[i] = std::sqrt(statistical * statistical + earth * earth + basis * basis);
    IncrementErrorBudget* part =
        i < n_kterms ? &fit->budget : (i < n_kterms + 1 + 2 * n_d ? &fit->drift_budget : nullptr);
    if (part) {
      part->statistical.push_back(statistical);
      part->angle_noise.push_back(noise);
      part->beyond_noise.push_back(beyond);
      part->earth_rate.push_back(earth);
      part->basis_noise.push_back(basis);
      part->bias_walk.push_back(std::sqrt(std::max(0.0, walk(i, i))) * scale[i]);
    }
  }
  return terms;
}

void IncrementRegression::fillFit(const Terms& terms, const std::vector<int>& orders, int offset,
                                  double condition_number, HarmonicFitResult* f) const {
  const int h = static_cast<int>(orders.size());
  f->ok = true;
  f->orders = orders;
  f->mean = terms.value[offset];
  f->mean_std = terms.total_std[offset];
  for (int j = 0; j < h; ++j) {
    f->cos.push_back(terms.value[offset + 1 + j]);
    f->cos_std.push_back(terms.total_std[offset + 1 + j]);
    f->sin.push_back(terms.value[offset + 1 + h + j]);
    f->sin_std.push_back(terms.total_std[offset + 1 + h + j]);
  }
  f->condition_number = condition_number;
  f->points = increments_;
}

void IncrementRegression::fitTrend(const Columns& columns, const Terms& terms, const LeastSquaresSolution& solution,
                                   const Eigen::MatrixXd& map, const Eigen::MatrixXd& total, double reference_time,
                                   BiasTrendFit* trend) const {
  const int trend_at = columns.trend_at;
  trend->order = trend_order_;
  for (int j = 0; j < trend_order_; ++j) {
    trend->coefficients.push_back(terms.value[trend_at + j]);
    trend->stds.push_back(terms.total_std[trend_at + j]);
  }
  trend->reference_time = reference_time;
  trend->reference_stamp = session_origin_ + toNanoseconds(reference_time);
  trend->span = last_session_time_;
  // How the design confuses the trend with K0, from its geometry alone (the normal inverse): the
  // same fit without the trend, and the correlation of K0 with the linear term.
  const std::vector<int>& sel_without_trend = columns.without_trend;
  const Eigen::MatrixXd s = map * total * map.transpose();
  const LeastSquaresSolution without =
      solveNormalEquations(submatrix(s, sel_without_trend, sel_without_trend), column(s, sel_without_trend, m_),
                           ColumnScaling::kUnitNorm, std::numeric_limits<double>::infinity());
  const Eigen::MatrixXd& inv = solution.normal_inverse;
  if (without.ok && without.normal_inverse(0, 0) > 0.0) {
    trend->k0_inflation = std::sqrt(inv(0, 0) / without.normal_inverse(0, 0));
  }
  trend->k0_correlation = inv(0, trend_at) / std::sqrt(inv(0, 0) * inv(trend_at, trend_at));
}

void IncrementRegression::binCurves(const std::vector<int>& sel, const Eigen::VectorXd& beta,
                                    const Eigen::MatrixXd& map, double earth_rate, double min_bin_time,
                                    IncrementFit* fit) const {
  const int p = static_cast<int>(sel.size());
  // Binned curves of the two groups with the most data: the fitted model at the bin centre plus the
  // bin's mean residual rate, separated into K and D by the two groups' rates.
  std::vector<std::pair<double, int>> by_time;
  for (const auto& gt : group_time_) by_time.emplace_back(gt.second, gt.first);
  std::sort(by_time.rbegin(), by_time.rend());
  double k_ss = 0.0, d_ss = 0.0;
  if (by_time.size() >= 2) {
    const auto& b1 = bins_by_group_.at(by_time[0].second);
    const auto& b2 = bins_by_group_.at(by_time[1].second);
    const HarmonicModel k_model = toModel(fit->k), d_model = toModel(fit->d);
    for (int b = 0; b < bins_; ++b) {
      if (b1[b].dt < min_bin_time || b2[b].dt < min_bin_time || b1[b].dt <= 0.0 || b2[b].dt <= 0.0) continue;
      auto residualRate = [&](const BinSums& s) {
        const Eigen::VectorXd w = map * s.w;
        double model = 0.0;
        for (int i = 0; i < p; ++i) model += w(sel[i]) * beta(i);
        return (w(m_) - model) / s.dt;
      };
      const double r1 = residualRate(b1[b]), r2 = residualRate(b2[b]);
      const double w1 = b1[b].dphi / b1[b].dt + earth_rate, w2 = b2[b].dphi / b2[b].dt + earth_rate;
      if (!(std::abs(w1 - w2) > 0.0)) continue;
      BinnedCurvePoint point;
      point.theta = (b + 0.5) * kPi / bins_;
      const double k_residual = (r1 - r2) / (w1 - w2), d_residual = (r2 * w1 - r1 * w2) / (w1 - w2);
      point.k = k_model(point.theta) + k_residual;
      point.d = d_model(point.theta) + d_residual;
      point.weight = std::min(b1[b].dt, b2[b].dt);
      fit->binned.push_back(point);
      k_ss += k_residual * k_residual;
      d_ss += d_residual * d_residual;
    }
  }
  const double shown = static_cast<double>(fit->binned.size());
  fit->k.residual_rms = shown > 0 ? std::sqrt(k_ss / shown) : 0.0;
  fit->d.residual_rms = shown > 0 ? std::sqrt(d_ss / shown) : 0.0;
}

IncrementFit IncrementRegression::solve(double earth_rate, double earth_rate_std, double min_bin_time,
                                        double max_condition) const {
  if (in_chain_ && !chain_means_.empty()) {
    // The open chain's window means wait for its end: close it on a copy.
    IncrementRegression closed = *this;
    closed.endChain();
    return closed.solve(earth_rate, earth_rate_std, min_bin_time, max_condition);
  }
  IncrementFit fit;
  fit.angle_weight = weighted_chain_time_ > 0.0 ? angle_weight_time_ / weighted_chain_time_ : 1.0;
  const int n_kterms = 1 + 2 * static_cast<int>(k_orders_.size());
  const Columns columns = fittedColumns();
  const std::vector<int>& sel = columns.sel;
  const int p = static_cast<int>(sel.size());

  std::vector<Block> blocks = blocks_;
  if (open_block_.count > 0) blocks.push_back(open_block_);
  fit.increments = increments_;
  fit.blocks = blocks.size();
  fit.mean_window = increments_ > 0 ? increment_time_ / increments_ : 0.0;
  fit.angle_noise = noise_count_ > 0 ? std::sqrt(noise_sum_ / noise_count_) : 0.0;
  if (increments_ < static_cast<std::size_t>(3 * p) || blocks.size() < 4) {
    fit.reason = std::to_string(increments_) + " window increments in " + std::to_string(blocks.size()) +
                 " blocks; need at least " + std::to_string(3 * p) + " in 4 blocks";
    return fit;
  }
  Eigen::MatrixXd total = Eigen::MatrixXd::Zero(m_ + 1, m_ + 1);
  for (const Block& b : blocks) total += b.products;

  // The trend is centred on the mean time of the increments: D0 is then the session's mean bias.
  const double reference_time = increment_time_ > 0.0 ? increment_time_moment_ / increment_time_ : 0.0;
  const Eigen::MatrixXd map = regressorMap(earth_rate, reference_time);
  Solved solved = solveColumns(sel, map, blocks, total, fit.angle_noise, max_condition);
  if (!solved.solution.ok) {
    fit.reason = "increment regression condition number " + std::to_string(solved.solution.condition_number) +
                 " above " + std::to_string(max_condition);
    return fit;
  }
  const LeastSquaresSolution& solution = solved.solution;
  const Eigen::VectorXd& beta = solution.coefficients;
  fit.walk = estimateWalk(blocks, sel, map, solution);
  solved.walk =
      fit.walk.carried ? walkCovariance(fit.walk, sel, map, solution.normal_inverse) : Eigen::MatrixXd::Zero(p, p);
  // Earth-rate uncertainty: refit with the rate moved by its standard deviation.
  const Eigen::VectorXd earth_shift =
      earthRateShift(sel, beta, total, earth_rate, earth_rate_std, reference_time, max_condition);
  const Terms terms = correctedTerms(solved, earth_shift, &fit);
  fillFit(terms, k_orders_, 0, solution.condition_number, &fit.k);
  fillFit(terms, d_orders_, n_kterms, solution.condition_number, &fit.d);
  if (trend_order_ > 0) fitTrend(columns, terms, solution, map, total, reference_time, &fit.trend);
  for (std::size_t j = 0; j < columns.horizontal.size(); ++j) {
    const int at = columns.horizontal_at + 2 * static_cast<int>(j);
    fit.horizontal.push_back(
        {columns.horizontal[j], terms.value[at], terms.value[at + 1], terms.total_std[at], terms.total_std[at + 1]});
  }
  binCurves(sel, beta, map, earth_rate, min_bin_time, &fit);
  fit.ok = true;
  return fit;
}

}  // namespace core
}  // namespace hrg_gyro

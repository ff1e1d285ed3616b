#include "hrg_gyro/core/alignment/integrated_angle_fit.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <cstdio>

#include "hrg_gyro/core/common/weighted_least_squares.h"

namespace hrg_gyro {
namespace core {
namespace {

std::string format(const char* pattern, double a, double b = 0.0) {
  char buffer[256];
  std::snprintf(buffer, sizeof buffer, pattern, a, b);
  return buffer;
}

}  // namespace

IntegratedAngleFit::IntegratedAngleFit(std::size_t parameters, std::vector<AngleSeries> channels)
    : parameters_(parameters), channels_(std::move(channels)) {}

bool IntegratedAngleFit::validate() {
  segments_.assign(channels_.size(), {});
  std::size_t points = 0, intercepts = 0;
  for (std::size_t c = 0; c < channels_.size(); ++c) {
    const AngleSeries& s = channels_[c];
    const std::size_t n = s.size();
    if (s.segment.size() != n || s.angle.size() != n || s.regressors.size() != s.columns.size()) {
      result_.problem = "malformed series (sizes differ)";
      return false;
    }
    for (std::size_t k = 0; k < s.columns.size(); ++k) {
      if (s.columns[k] < 0 || static_cast<std::size_t>(s.columns[k]) >= parameters_ || s.regressors[k].size() != n) {
        result_.problem = "malformed series (a regressor column)";
        return false;
      }
    }
    if (!std::isfinite(s.angle_random_walk) || s.angle_random_walk < 0.0 || !std::isfinite(s.rate_random_walk) ||
        s.rate_random_walk < 0.0 || !std::isfinite(s.white_noise) || !std::isfinite(s.angle_quantum) ||
        s.angle_quantum < 0.0) {
      result_.problem = "noise terms must be finite and not negative";
      return false;
    }
    for (std::size_t i = 0; i < n; ++i) {
      bool finite = std::isfinite(s.time[i]) && std::isfinite(s.angle[i]);
      for (const auto& column : s.regressors) finite = finite && std::isfinite(column[i]);
      if (!finite) {
        result_.problem = "a value that is not finite in the series";
        return false;
      }
      if (i > 0 && (!(s.time[i] > s.time[i - 1]) || s.segment[i] < s.segment[i - 1])) {
        result_.problem = "the series' times must increase and its segments not go back";
        return false;
      }
      if (i == 0 || s.segment[i] != s.segment[i - 1]) {
        segments_[c].push_back(Segment());
        segments_[c].back().begin = i;
      }
      segments_[c].back().end = i + 1;
    }
    for (Segment& g : segments_[c]) {
      const double count = static_cast<double>(g.end - g.begin);
      g.mean_regressors.assign(s.columns.size(), 0.0);
      for (std::size_t i = g.begin; i < g.end; ++i) {
        g.mean_time += s.time[i];
        g.mean_angle += s.angle[i];
        for (std::size_t k = 0; k < s.columns.size(); ++k) g.mean_regressors[k] += s.regressors[k][i];
      }
      g.mean_time /= count;
      g.mean_angle /= count;
      for (double& m : g.mean_regressors) m /= count;
    }
    points += n;
    intercepts += segments_[c].size();
  }
  if (points < intercepts + parameters_ + 1) {
    result_.problem = format("too few points (%.0f) for the unknowns (%.0f)", static_cast<double>(points),
                             static_cast<double>(intercepts + parameters_));
    return false;
  }
  return true;
}

double IntegratedAngleFit::measureWhiteNoise(const AngleSeries& s, const std::vector<Segment>& segments) const {
  std::vector<double> departures;
  departures.reserve(s.size());
  double walk_share = 0.0;
  for (const Segment& g : segments) {
    for (std::size_t i = g.begin + 1; i + 1 < g.end; ++i) {
      const double tm = s.time[i - 1], t0 = s.time[i], tp = s.time[i + 1];
      const double a = (tp - t0) / (tp - tm), b = (t0 - tm) / (tp - tm);
      const double e = s.angle[i] - (a * s.angle[i - 1] + b * s.angle[i + 1]);
      const double v = 1.0 + a * a + b * b;  // its variance per s^2 of white angle noise
      departures.push_back(std::abs(e) / std::sqrt(v));
      walk_share += (tp - t0) * (t0 - tm) / (tp - tm) / v;  // per N^2 of an angle random walk
    }
  }
  if (departures.size() < 10) return NAN;
  const std::size_t middle = departures.size() / 2;
  std::nth_element(departures.begin(), departures.begin() + middle, departures.end());
  const double mad = 1.482602218505602 * departures[middle];
  const double walk = s.angle_random_walk * s.angle_random_walk * walk_share / static_cast<double>(departures.size());
  const double white2 = std::max(mad * mad - walk, 0.01 * mad * mad);
  return std::max(std::sqrt(white2), kMinimumWhiteNoise);
}

const AngleFitResult& IntegratedAngleFit::solve(double max_condition) {
  result_ = AngleFitResult();
  if (!validate()) return result_;
  const std::size_t q = parameters_;
  result_.white_noise.assign(channels_.size(), 0.0);
  weights_.assign(channels_.size(), 0.0);
  for (std::size_t c = 0; c < channels_.size(); ++c) {
    double s = channels_[c].white_noise;
    const double quantisation = channels_[c].angle_quantum * channels_[c].angle_quantum / 12.0;
    if (s < 0.0) {
      s = measureWhiteNoise(channels_[c], segments_[c]);
      if (!std::isfinite(s)) {
        result_.problem = "too few points to measure the white angle noise";
        return result_;
      }
      s = std::sqrt(s * s + quantisation);
    } else {
      s = std::max(s, std::sqrt(quantisation));
    }
    s = std::max(s, kMinimumWhiteNoise);
    result_.white_noise[c] = s;
    weights_[c] = 1.0 / (s * s);
  }
  // The normal equations of the points centred within their segments (the intercepts eliminated).
  Eigen::MatrixXd normal = Eigen::MatrixXd::Zero(q, q);
  Eigen::VectorXd rhs = Eigen::VectorXd::Zero(q);
  for (std::size_t c = 0; c < channels_.size(); ++c) {
    const AngleSeries& s = channels_[c];
    const std::size_t qc = s.columns.size();
    Eigen::MatrixXd local = Eigen::MatrixXd::Zero(qc, qc);
    Eigen::VectorXd local_rhs = Eigen::VectorXd::Zero(qc);
    Eigen::VectorXd x(qc);
    for (const Segment& g : segments_[c]) {
      for (std::size_t i = g.begin; i < g.end; ++i) {
        for (std::size_t k = 0; k < qc; ++k) x(k) = s.regressors[k][i] - g.mean_regressors[k];
        local.selfadjointView<Eigen::Lower>().rankUpdate(x);
        local_rhs += x * (s.angle[i] - g.mean_angle);
      }
    }
    local = local.selfadjointView<Eigen::Lower>();
    for (std::size_t a = 0; a < qc; ++a) {
      rhs(s.columns[a]) += weights_[c] * local_rhs(a);
      for (std::size_t b = 0; b < qc; ++b) normal(s.columns[a], s.columns[b]) += weights_[c] * local(a, b);
    }
  }
  const LeastSquaresSolution solution = solveNormalEquations(normal, rhs, ColumnScaling::kUnitNorm, max_condition);
  result_.condition_number = solution.condition_number;
  if (!solution.ok) {
    result_.problem = format("the data cannot separate the parameters (condition number %.3g, limit %.3g)",
                             solution.condition_number, max_condition);
    return result_;
  }
  result_.parameters = solution.coefficients;
  result_.normal_inverse = solution.normal_inverse;
  result_.white = Eigen::MatrixXd::Zero(q, q);
  result_.angle_random_walk = Eigen::MatrixXd::Zero(q, q);
  result_.rate_random_walk = Eigen::MatrixXd::Zero(q, q);
  result_.constant_rate.assign(channels_.size(), Eigen::VectorXd::Zero(q));
  result_.scatter.assign(channels_.size(), 0.0);
  for (std::size_t c = 0; c < channels_.size(); ++c) propagate(c);
  result_.ok = true;
  return result_;
}

void IntegratedAngleFit::propagate(std::size_t c) {
  const AngleSeries& s = channels_[c];
  const std::size_t q = parameters_, qc = s.columns.size(), n = s.size();
  const double w = weights_[c], white = result_.white_noise[c];
  Eigen::MatrixXd gain(q, qc);  // R_i = gain * xcentred_i
  Eigen::VectorXd beta(qc);
  for (std::size_t k = 0; k < qc; ++k) {
    gain.col(k) = w * result_.normal_inverse.col(s.columns[k]);
    beta(k) = result_.parameters(s.columns[k]);
  }
  std::vector<std::size_t> segment_of(n);
  for (std::size_t g = 0; g < segments_[c].size(); ++g) {
    for (std::size_t i = segments_[c][g].begin; i < segments_[c][g].end; ++i) segment_of[i] = g;
  }
  Eigen::MatrixXd unweighted = Eigen::MatrixXd::Zero(qc, qc);  // sum of x x^T (centred)
  Eigen::MatrixXd arw = Eigen::MatrixXd::Zero(q, q), rrw = Eigen::MatrixXd::Zero(q, q);
  Eigen::VectorXd x(qc), r(q), g_sum = Eigen::VectorXd::Zero(q), h_next = Eigen::VectorXd::Zero(q), h(q);
  Eigen::VectorXd rate_response = Eigen::VectorXd::Zero(q);
  std::vector<double> residual(n);
  // Backwards: G_l = sum_{i >= l} R_i is the weight of the angle noise over the interval ending at point l.
  for (std::size_t i = n; i-- > 0;) {
    const Segment& g = segments_[c][segment_of[i]];
    for (std::size_t k = 0; k < qc; ++k) x(k) = s.regressors[k][i] - g.mean_regressors[k];
    residual[i] = (s.angle[i] - g.mean_angle) - x.dot(beta);
    unweighted.selfadjointView<Eigen::Lower>().rankUpdate(x);
    r.noalias() = gain * x;
    rate_response += r * s.time[i];
    if (i + 1 < n) {
      // The interval (t_i, t_{i+1}]: G constant (g_sum before adding R_i), H linear from h to h_next.
      const double dt = s.time[i + 1] - s.time[i];
      arw.selfadjointView<Eigen::Lower>().rankUpdate(g_sum, dt);
      h = h_next + dt * g_sum;
      rrw.noalias() += (dt / 3.0) * (h * h.transpose() + 0.5 * (h * h_next.transpose() + h_next * h.transpose()) +
                                     h_next * h_next.transpose());
      h_next = h;
    }
    g_sum += r;
  }
  unweighted = unweighted.selfadjointView<Eigen::Lower>();
  arw = arw.selfadjointView<Eigen::Lower>();
  const double n_walk = s.angle_random_walk, k_walk = s.rate_random_walk;
  result_.white += white * white * gain * unweighted * gain.transpose();
  result_.angle_random_walk += n_walk * n_walk * arw;
  result_.rate_random_walk += k_walk * k_walk * 0.5 * (rrw + rrw.transpose());
  result_.constant_rate[c] = rate_response;
  // Residuals by segment, against what the noise model predicts.
  double squares = 0.0, predicted = 0.0;
  for (std::size_t gi = 0; gi < segments_[c].size(); ++gi) {
    const Segment& g = segments_[c][gi];
    SegmentResidual out;
    out.channel = c;
    out.segment = s.segment[g.begin];
    out.start = s.time[g.begin];
    out.end = s.time[g.end - 1];
    out.points = g.end - g.begin;
    const double length = out.end - out.start, count = static_cast<double>(out.points);
    double e2 = 0.0, tt = 0.0, te = 0.0;
    for (std::size_t i = g.begin; i < g.end; ++i) {
      e2 += residual[i] * residual[i];
      tt += (s.time[i] - g.mean_time) * (s.time[i] - g.mean_time);
      te += (s.time[i] - g.mean_time) * residual[i];
    }
    const double per_point =
        white * white + n_walk * n_walk * length / 15.0 + k_walk * k_walk * length * length * length / 420.0;
    out.rms = std::sqrt(e2 / count);
    out.predicted_rms = std::sqrt(per_point * std::max(count - 1.0, 1.0) / count);
    if (tt > 0.0) {
      out.residual_rate = te / tt;
      out.residual_rate_std = white / std::sqrt(tt);
    }
    squares += e2;
    predicted += per_point * std::max(count - 1.0, 1.0);
    result_.segments.push_back(out);
  }
  predicted = std::max(predicted - white * white * static_cast<double>(qc), white * white);
  result_.scatter[c] = std::sqrt(squares / predicted);
}

std::vector<double> IntegratedAngleFit::residuals(std::size_t channel) const {
  const AngleSeries& s = channels_.at(channel);
  const std::size_t qc = s.columns.size();
  std::vector<double> out(s.size(), 0.0);
  for (const Segment& g : segments_[channel]) {
    for (std::size_t i = g.begin; i < g.end; ++i) {
      double model = 0.0;
      for (std::size_t k = 0; k < qc; ++k) {
        model += (s.regressors[k][i] - g.mean_regressors[k]) * result_.parameters(s.columns[k]);
      }
      out[i] = (s.angle[i] - g.mean_angle) - model;
    }
  }
  return out;
}

Eigen::VectorXd IntegratedAngleFit::response(std::size_t channel, const std::vector<double>& angle) const {
  const AngleSeries& s = channels_.at(channel);
  const std::size_t qc = s.columns.size();
  Eigen::VectorXd local = Eigen::VectorXd::Zero(qc), x(qc);
  for (const Segment& g : segments_[channel]) {
    for (std::size_t i = g.begin; i < g.end; ++i) {
      for (std::size_t k = 0; k < qc; ++k) x(k) = s.regressors[k][i] - g.mean_regressors[k];
      local += x * angle.at(i);
    }
  }
  Eigen::VectorXd out = Eigen::VectorXd::Zero(parameters_);
  for (std::size_t k = 0; k < qc; ++k) out += weights_[channel] * local(k) * result_.normal_inverse.col(s.columns[k]);
  return out;
}

}  // namespace core
}  // namespace hrg_gyro

#include "hrg_gyro/core/alignment/base_motion_scan.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <vector>

namespace hrg_gyro {
namespace core {
namespace {

constexpr double kScanNoiseFloor = 1e-9;  // rad
constexpr int kMaxChannels = 3, kMaxParameters = 16;
using Parameters = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, kMaxParameters, kMaxParameters>;
using Projection = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, kMaxParameters, kMaxChannels>;
using Square = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, kMaxChannels, kMaxChannels>;
using Column = Eigen::Matrix<double, Eigen::Dynamic, 1, 0, kMaxChannels, 1>;

bool sharePoints(const std::vector<AngleSeries>& channels) {
  for (const AngleSeries& s : channels) {
    if (s.size() != channels[0].size() || s.segment != channels[0].segment || s.time != channels[0].time) return false;
  }
  return !channels.empty() && channels[0].size() > 2;
}

// The running sums of one channel over the points after a candidate step, within its segment.
struct Suffix {
  double residual = 0.0;
  Eigen::VectorXd regressors;  // centred, one per column of the channel
};

}  // namespace

BaseStep strongestStep(const IntegratedAngleFit& fit, double margin) {
  BaseStep best;
  const AngleFitResult& r = fit.result();
  const std::vector<AngleSeries>& ch = fit.channels();
  if (!r.ok || !sharePoints(ch) || ch.size() > static_cast<std::size_t>(kMaxChannels) ||
      r.parameters.size() > static_cast<Eigen::Index>(kMaxParameters)) {
    return best;
  }
  const Eigen::Index channels = static_cast<Eigen::Index>(ch.size()), q = r.parameters.size();
  std::vector<std::vector<double>> e(ch.size());
  std::vector<double> w(ch.size());
  for (std::size_t c = 0; c < ch.size(); ++c) {
    e[c] = fit.residuals(c);
    // A noiseless series' rounding is not a step: no weight beyond a nanoradian's.
    const double white = std::max(r.white_noise[c], kScanNoiseFloor);
    w[c] = 1.0 / (white * white);
  }
  // Fixed-capacity matrices: the scan visits every point, and must not allocate at each.
  const Parameters n_inverse = r.normal_inverse;
  const std::vector<double>& time = ch[0].time;
  for (std::size_t begin = 0, end = 0; begin < time.size(); begin = end) {
    end = begin;
    while (end < time.size() && ch[0].segment[end] == ch[0].segment[begin]) ++end;
    const double n = static_cast<double>(end - begin);
    std::vector<Eigen::VectorXd> mean(ch.size());
    std::vector<Suffix> suffix(ch.size());
    for (std::size_t c = 0; c < ch.size(); ++c) {
      mean[c] = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(ch[c].columns.size()));
      for (std::size_t k = 0; k < ch[c].columns.size(); ++k) {
        for (std::size_t i = begin; i < end; ++i) mean[c](k) += ch[c].regressors[k][i];
      }
      mean[c] /= n;
      suffix[c].regressors = Eigen::VectorXd::Zero(mean[c].size());
    }
    Projection p(q, channels);
    Square jm(channels, channels);
    Column z(channels), size(channels);
    for (std::size_t b = end - 1; b > begin; --b) {
      for (std::size_t c = 0; c < ch.size(); ++c) {
        suffix[c].residual += e[c][b];
        for (std::size_t k = 0; k < ch[c].columns.size(); ++k) {
          suffix[c].regressors(k) += ch[c].regressors[k][b] - mean[c](k);
        }
      }
      if (time[b - 1] - time[begin] < margin || time[end - 1] - time[b] < margin) continue;
      const double after = static_cast<double>(end - b), before = n - after;
      p.setZero();
      for (std::size_t c = 0; c < ch.size(); ++c) {
        z(c) = w[c] * suffix[c].residual;
        for (std::size_t k = 0; k < ch[c].columns.size(); ++k) p(ch[c].columns[k], c) += w[c] * suffix[c].regressors(k);
      }
      jm.noalias() = -(p.transpose() * n_inverse * p);
      for (Eigen::Index c = 0; c < channels; ++c) jm(c, c) += w[c] * before * after / n;
      const Eigen::LDLT<Square> solver(jm);
      if (solver.info() != Eigen::Success || !solver.isPositive()) continue;
      size = solver.solve(z);
      const double chi = z.dot(size);
      if (!(chi > best.chi_square)) continue;
      best.found = true;
      best.chi_square = chi;
      best.size = size;
      best.time = 0.5 * (time[b - 1] + time[b]);
      best.segment = ch[0].segment[begin];
    }
  }
  return best;
}

double chiSquareQuantile(int dof, double p) {
  // The normal quantile of 1 - p (Acklam's rational approximation's tail), then Wilson-Hilferty.
  const double q = std::sqrt(-2.0 * std::log(p));
  const double z =
      (((((-7.784894002430293e-03 * q - 3.223964580411365e-01) * q - 2.400758277161838e+00) * q -
         2.549732539343734e+00) *
            q +
        4.374664141464968e+00) *
           q +
       2.938163982698783e+00) /
      ((((7.784695709041462e-03 * q + 3.224671290700398e-01) * q + 2.445134137142996e+00) * q + 3.754408661907416e+00) *
           q +
       1.0);
  const double k = static_cast<double>(dof), c = 2.0 / (9.0 * k);
  const double cube = 1.0 - c - z * std::sqrt(c);
  return k * cube * cube * cube;
}

BlockScatter lowFrequencyScatter(const IntegratedAngleFit& fit, double block, double false_alarm) {
  BlockScatter worst;
  worst.limit = INFINITY;
  const AngleFitResult& r = fit.result();
  if (!r.ok) return worst;
  double worst_excess = -INFINITY;
  for (std::size_t c = 0; c < fit.channels().size(); ++c) {
    const AngleSeries& s = fit.channels()[c];
    const std::vector<double> e = fit.residuals(c);
    const double white2 = r.white_noise[c] * r.white_noise[c];
    const double n2 = s.angle_random_walk * s.angle_random_walk, k2 = s.rate_random_walk * s.rate_random_walk;
    // The white noise's share of each block is its own; a random walk's is one smooth curve per
    // segment, worth one degree of freedom however many blocks it spans (its few low-order shapes
    // taken as one, the cautious count): the statistic's
    // variance, and so its degrees of freedom, follow (Satterthwaite).
    double squares = 0.0, predicted = 0.0, variance = 0.0;
    int blocks = 0;
    for (std::size_t begin = 0, end = 0; begin < s.size(); begin = end) {
      end = begin;
      while (end < s.size() && s.segment[end] == s.segment[begin]) ++end;
      const double length = s.time[end - 1] - s.time[begin];
      const double walks = n2 * length / 15.0 + k2 * length * length * length / 420.0;
      double sum = 0.0, from = s.time[begin], walk_share = 0.0;
      std::size_t count = 0;
      for (std::size_t i = begin; i < end; ++i) {
        sum += e[i];
        ++count;
        if (s.time[i] - from < block && i + 1 < end) continue;
        if (s.time[i] - from >= 0.5 * block) {  // a short last block is left out
          const double m = sum / static_cast<double>(count), white = white2 / static_cast<double>(count);
          squares += m * m;
          predicted += white + walks;
          variance += 2.0 * white * white;
          walk_share += walks;
          ++blocks;
        }
        sum = 0.0;
        count = 0;
        from = s.time[i];
      }
      variance += 2.0 * walk_share * walk_share;
    }
    if (blocks < 4 || !(predicted > 0.0)) continue;
    const double ratio = std::sqrt(squares / predicted);
    const int dof = std::max(1, static_cast<int>(std::lround(2.0 * predicted * predicted / variance)));
    const double limit = std::sqrt(chiSquareQuantile(dof, false_alarm) / dof);
    if (ratio / limit > worst_excess) {
      worst_excess = ratio / limit;
      worst = BlockScatter{ratio, limit, blocks};
    }
  }
  return worst;
}

}  // namespace core
}  // namespace hrg_gyro

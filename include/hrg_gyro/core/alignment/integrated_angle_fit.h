// The statistics of north-finding. A whole-angle gyro's output is an angle with white angle noise (the
// wave angle is read anew each sample; the simulated gyro: 4.9e-6 rad of electrical theta per 200 Hz
// sample, about 8.8e-6 rad of body angle), not a rate with white noise. So rates are fitted on the
// integrated angle of each channel, not averaged from its increments: averaging increments keeps only
// the first and last angle, the fit uses every one.
//
// Model. Channel c (a body axis of the triad, or one gyro) has points (t_i, y_i): its integrated angle
// at the sample stamps, in segments (a gap, a new indexer position or a new commanded rate starts
// one). Within segment s
//     y_i = a_{c,s} + sum_k beta_{col(c,k)} X_{c,k}(t_i) + noise
// with a free intercept a_{c,s} per segment and X_{c,k}(t) the integral of the k-th rate regressor of
// the channel (dt for a constant rate, the integral of cos(psi) for an Earth component seen through
// an indexer at angle psi, the commanded virtual angle for the precession gain, ...). The shared
// parameters beta are solved by weighted least squares (common/weighted_least_squares) on the points
// centred within each segment (which eliminates the intercepts exactly), weights 1/s_c^2.
//
// The estimator is linear, beta^ = sum_c,i R_{c,i} y_{c,i}, so each noise process propagates exactly
// (not by a rule of thumb), channels being independent:
//   white angle noise, s^2 per point:     Cov = s^2 sum_i R_i R_i^T
//   angle random walk N (rad/sqrt(s)):    Cov = N^2 sum_l dt_l G_l G_l^T,        G_l = sum_{i >= l} R_i
//   rate random walk K (rad/s/sqrt(s)):   Cov = K^2 int H(u) H(u)^T du,          H(u) = int_u^T G
//                                         (H is piecewise linear: summed exactly interval by interval)
//   a constant rate b on channel c:       d beta = b sum_i R_i t_i                (the response `constant_rate`)
// the walks counted from the first point (a bias present then is the constant one). For one segment
// of length T, n = f T points, and the slope of a straight line (the static triad) these are the law
// of the rate's error against the window length:
//   white angle noise   12 s^2 / (f T^3)     (falls as T^-3: the line's slope from n points)
//   angle random walk   (6/5) N^2 / T        (falls as T^-1)
//   rate random walk    (13/35) K^2 T        (grows: the walk's weighted mean over the window)
//   constant bias       b^2                  (a floor)
// The residual scatter predicted for a segment of length T is s^2 + N^2 T / 15 + K^2 T^3 / 420 per
// point; `scatter` is the measured rms over that (a moving base, a bias that jumps: well above 1).
//
// s is measured, unless given, from the data alone: each point's departure from the line through its
// two neighbours (unit variance per s^2 for white angle noise), whose median absolute value is robust
// to the few points at a change of commanded rate and blind to any smooth rate, less the share of a
// given angle random walk; a quantised angle's q^2/12 added (AngleSeries::angle_quantum). No ROS.
#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace hrg_gyro {
namespace core {

/// One channel's integrated angle and the integrals of its rate regressors, point by point in time order.
struct AngleSeries {
  std::vector<double> time;                     ///< s, increasing
  std::vector<std::int32_t> segment;            ///< non-decreasing; each value has its own intercept
  std::vector<double> angle;                    ///< rad, the integrated angle at `time`
  std::vector<int> columns;                     ///< the fit's parameter index of each regressor
  std::vector<std::vector<double>> regressors;  ///< per regressor: its integral up to `time`
  double white_noise = -1.0;                    ///< rad per point; negative: measured from the data
  /// rad, the quantum of the angle the increments were differenced from (0: none). Its rounding is a
  /// white angle noise of q^2/12 that the measurement cannot see (most neighbours' departures are 0):
  /// added to a measured white noise, a floor under a given one (an Allan Q of the same data has it).
  double angle_quantum = 0.0;
  double angle_random_walk = 0.0;  ///< N, rad/sqrt(s)
  double rate_random_walk = 0.0;   ///< K, rad/s/sqrt(s)

  std::size_t size() const { return time.size(); }
  /// Appends a point; `x` holds one value per regressor.
  void push(double t, std::int32_t seg, double y, const double* x) {
    time.push_back(t);
    segment.push_back(seg);
    angle.push_back(y);
    for (std::size_t k = 0; k < regressors.size(); ++k) regressors[k].push_back(x[k]);
  }
};

/// One segment of one channel after the fit.
struct SegmentResidual {
  std::size_t channel = 0;
  std::int32_t segment = 0;
  double start = 0.0, end = 0.0;  ///< s
  std::size_t points = 0;
  double rms = 0.0;                ///< rad, rms residual angle
  double predicted_rms = 0.0;      ///< rad, what the noise model predicts
  double residual_rate = 0.0;      ///< rad/s, the slope of the residuals (the model's misfit there)
  double residual_rate_std = 0.0;  ///< rad/s, its standard error from the white angle noise
};

struct AngleFitResult {
  bool ok = false;
  std::string problem;  ///< why nothing was solved
  double condition_number = 0.0;
  Eigen::VectorXd parameters;
  Eigen::MatrixXd normal_inverse;  ///< (X^T W X)^-1 with the intercepts eliminated
  /// The parameters' covariance, one matrix per noise process.
  Eigen::MatrixXd white, angle_random_walk, rate_random_walk;
  /// Per channel: the parameters' response to a constant rate of 1 rad/s added to that channel.
  std::vector<Eigen::VectorXd> constant_rate;
  std::vector<double> white_noise;  ///< per channel, rad per point: the one used (measured or given)
  std::vector<double> scatter;      ///< per channel, rms residual over its prediction
  std::vector<SegmentResidual> segments;

  Eigen::MatrixXd covariance() const { return white + angle_random_walk + rate_random_walk; }
};

class IntegratedAngleFit {
 public:
  /// The smallest white angle noise taken, rad per point (a noiseless input keeps finite weights).
  static constexpr double kMinimumWhiteNoise = 1e-12;

  /// `parameters`: the number of shared parameters; every column index of every channel below it.
  IntegratedAngleFit(std::size_t parameters, std::vector<AngleSeries> channels);

  /// Fits; refused (ok false, problem said) for a malformed series, fewer points than unknowns, or a
  /// condition number above `max_condition` (a parameter the data cannot separate).
  const AngleFitResult& solve(double max_condition);
  const AngleFitResult& result() const { return result_; }

  /// The parameters' response to `angle` (rad, one value per point of the channel) added to channel
  /// `channel`'s data: for the budget's terms that are not noise (a residual drift harmonic, an
  /// indexer position off by a small angle). Valid after a successful solve().
  Eigen::VectorXd response(std::size_t channel, const std::vector<double>& angle) const;

  /// Each point's residual angle (rad) of channel `channel`, its segment's intercept removed. Valid
  /// after a successful solve().
  std::vector<double> residuals(std::size_t channel) const;

  const std::vector<AngleSeries>& channels() const { return channels_; }

 private:
  struct Segment {
    std::size_t begin = 0, end = 0;  // point indices [begin, end)
    double mean_time = 0.0, mean_angle = 0.0;
    std::vector<double> mean_regressors;
  };
  bool validate();
  double measureWhiteNoise(const AngleSeries& series, const std::vector<Segment>& segments) const;
  void propagate(std::size_t channel);

  std::size_t parameters_;
  std::vector<AngleSeries> channels_;
  std::vector<std::vector<Segment>> segments_;
  std::vector<double> weights_;
  AngleFitResult result_;
};

}  // namespace core
}  // namespace hrg_gyro

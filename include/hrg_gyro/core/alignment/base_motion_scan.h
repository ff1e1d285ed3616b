// What the base did during a still-base fit's window, as the gyros saw it: the steps it took (a lean,
// a knock: a rotation that stayed) and whether it swayed. Both read the residuals of a solved
// IntegratedAngleFit, whose model (the Earth's rate, one intercept per segment) is what a still base
// does; the rest is the base's own motion or noise.
//
// A step: the base turns by a (a vector, one entry per channel) between two points of a segment and
// stays. Its regressor within the segment is the centred indicator u_i = [i >= b] - n_after / n, so
// with the fit's residuals e, white-noise weights w_c and its normal matrix's inverse N^-1,
//   z_c = w_c sum_{i >= b} e_c,i,   J_cd = delta_cd w_c n_before n_after / n - p_c^T N^-1 p_d,
//   p_c = w_c sum_{i >= b} x~_c,i  (the centred regressors, mapped to the shared parameters),
// the step's estimate is J^-1 z and its chi-square z^T J^-1 z (a test of one step at b against none,
// every channel at once). strongestStep scans every point of every segment with at least `margin` s
// of points on each side, by suffix sums: one pass per segment. The channels must share their points
// (the static triad's body axes, the indexed channels). A step of a left undetected biases a rate by
// 6 a tau (T - tau) / T^3, at most 1.5 a / T at mid-window; its detection threshold fixes what the
// scan can miss.
//
// A sway: a slow oscillation of the base is not a step and not white noise. lowFrequencyScatter
// averages each channel's residuals over blocks of `block` s and compares their mean square with the
// noise model's prediction for a block mean (s^2 / points + the random walks' N^2 T / 15 + K^2 T^3 /
// 420): 1 for a still base, well above for a base that sways slower than the blocks, judged against
// the chi-square quantile of its number of blocks. No ROS.
#pragma once

#include <Eigen/Core>
#include <cstddef>

#include "hrg_gyro/core/alignment/integrated_angle_fit.h"

namespace hrg_gyro {
namespace core {

struct BaseStep {
  bool found = false;        ///< a candidate existed (enough points on both sides)
  double time = 0.0;         ///< s, between the points on either side of the step
  std::int32_t segment = 0;  ///< the segment it splits
  Eigen::VectorXd size;      ///< rad, per channel
  double chi_square = 0.0;   ///< of the step against none (as many degrees of freedom as channels)
};

/// The most significant step within any segment of a solved fit (channels sharing their points).
BaseStep strongestStep(const IntegratedAngleFit& fit, double margin);

/// The block means' test, for the channel that departs most from its own limit.
struct BlockScatter {
  double ratio = 0.0;  ///< rms of its block-mean residuals over the noise model's prediction
  double limit = 0.0;  ///< the ratio a still base exceeds with probability `false_alarm` (its blocks' count)
  int blocks = 0;
  bool still() const { return ratio <= limit; }
};

/// The residuals averaged over blocks of `block` s within segments against the noise model's
/// prediction, per channel; the limit is the chi-square quantile of 1 - false_alarm for the channel's
/// degrees of freedom (Wilson-Hilferty), so that a still window is refused as rarely whatever its
/// length (white noise: one per block, 15 blocks 1.72 at 1e-4, 60 1.35, 300 1.15; a random walk of
/// the noise model, one smooth curve per segment, counted as one for all its blocks). Fewer than 4
/// blocks: still.
BlockScatter lowFrequencyScatter(const IntegratedAngleFit& fit, double block, double false_alarm = 1e-4);

/// The chi-square quantile: the value a chi-square of `dof` degrees of freedom exceeds with
/// probability `p` (Wilson-Hilferty's cube, within 1 % for dof >= 4 and p >= 1e-6).
double chiSquareQuantile(int dof, double p);

}  // namespace core
}  // namespace hrg_gyro

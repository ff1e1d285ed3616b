// The gyrocompass solver's still-base estimator: the Earth's rate fitted on the integrated angles of
// the base's rests, the window cut at every step the base takes and (static) the rotation the gyros
// measured across it carried (gyrocompass_solver.h).
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>

#include "hrg_gyro/core/alignment/gyrocompass_solver.h"
#include "hrg_gyro/core/alignment/motion_gate.h"
#include "hrg_gyro/core/common/number_format.h"

namespace hrg_gyro {
namespace core {
namespace {

constexpr double kDegrees = 180.0 / kPi;

}  // namespace

void GyrocompassSolver::resetSeries() {
  series_.clear();
  segments_.clear();
  parameters_ = 0;
  worst_motion_ = 0.0;
  samples_ = 0;
  used_seconds_ = 0.0;
  indexer_time_.clear();
  indexer_angle_.clear();
  indexer_rate_.clear();
  rests_.clear();
  result_.notes.clear();
}

bool GyrocompassSolver::buildSeries() {
  switch (s_.mode) {
    case AlignmentMode::kStatic:
      return buildStatic();
    case AlignmentMode::kIndexed:
      return buildIndexed();
    case AlignmentMode::kSweep:
      return buildSweep();
  }
  return false;
}

bool GyrocompassSolver::excludedSample(double t_a, double t_b) const {
  for (const Interval& x : excluded_) {
    if (t_b >= x.from && t_a <= x.to) return true;
  }
  return false;
}

Eigen::Matrix3d GyrocompassSolver::carriedRotation(double t) const {
  Eigen::Matrix3d r = Eigen::Matrix3d::Identity();
  for (std::size_t k = 0; k < steps_.size() && steps_[k].time < t; ++k) r = carried_[k];
  return r;
}

bool GyrocompassSolver::carryStep(const BaseStep& step) {
  const double guard = s_.motion.step_guard;
  Interval cut{step.time - guard, step.time + guard};
  // Merged with a cut it touches: one transition, however long the base took over it.
  std::vector<Interval> kept;
  for (const Interval& x : excluded_) {
    if (x.to + guard < cut.from || x.from - guard > cut.to) {
      kept.push_back(x);
    } else {
      cut.from = std::min(cut.from, x.from);
      cut.to = std::max(cut.to, x.to);
    }
  }
  kept.push_back(cut);
  std::sort(kept.begin(), kept.end(), [](const Interval& a, const Interval& b) { return a.from < b.from; });
  excluded_ = kept;
  BaseStepRecord record;
  record.time = step.time;
  record.chi_square = step.chi_square;
  for (Eigen::Index c = 0; c < std::min<Eigen::Index>(step.size.size(), 3); ++c) record.rotation(c) = step.size(c);
  // The steps in time order, each one's carried rotation composed on the earlier ones' (static: the
  // channels are the body axes, the step's sizes the rotation vector in the first rest's frame).
  const auto at = std::upper_bound(steps_.begin(), steps_.end(), record.time,
                                   [](double t, const BaseStepRecord& b) { return t < b.time; });
  steps_.insert(at, record);
  carried_.clear();
  Eigen::Matrix3d r = Eigen::Matrix3d::Identity();
  for (const BaseStepRecord& b : steps_) {
    if (s_.mode == AlignmentMode::kStatic) r = rotationVectorToQuaternion(b.rotation).toRotationMatrix() * r;
    carried_.push_back(r);
  }
  double excluded = 0.0;
  for (const Interval& x : excluded_) excluded += x.to - x.from;
  return excluded <= s_.motion.max_excluded * s_.duration;
}

bool GyrocompassSolver::stepScanApplies(const AngleFitResult& f) {
  // The scan weighs the residuals as white angle noise. The random walks add to a mid-window step's
  // variance about N^2 T / 24 (angle) and K^2 T^3 / 420 (rate) against the white noise's 16 s^2 / n
  // (n points over T s); where they are not small (taken four times over) the scan would find steps
  // in the walks, so it is not run.
  const double white = *std::min_element(f.white_noise.begin(), f.white_noise.end());
  const double n = static_cast<double>(samples_), t = used_seconds_;
  const double arw = s_.noise.angle_random_walk, rrw = s_.noise.rate_random_walk;
  const double walks = arw * arw * t / 24.0 + rrw * rrw * t * t * t / 420.0;
  const double share = n * walks / (4.0 * white * white);
  if (share <= 0.1) return true;
  result_.notes.push_back(formatNumbers(
      "the base's steps were not looked for: the noise model's random walks are %.2g times the white noise's "
      "share of a step's statistic",
      share));
  return false;
}

bool GyrocompassSolver::fitStillBase() {
  for (;;) {
    resetSeries();
    if (!buildSeries()) return false;
    for (AngleSeries& series : series_) {
      series.white_noise = s_.noise.angle_white_noise;
      series.angle_quantum = s_.noise.angle_quantum;
      series.angle_random_walk = s_.noise.angle_random_walk;
      series.rate_random_walk = s_.noise.rate_random_walk;
    }
    if (samples_ < 10) return refuse("input", "too few gyro samples in the window");
    fit_ = std::make_unique<IntegratedAngleFit>(parameters_, std::move(series_));
    const AngleFitResult& f = fit_->solve(s_.max_condition);
    if (!f.ok) return refuse("design", f.problem);
    // The sweep's axes do not share their points; its base must be still.
    if (s_.mode == AlignmentMode::kSweep || !stepScanApplies(f)) return true;
    const BaseStep step = strongestStep(*fit_, std::max(2.0 * s_.motion.step_guard, 1.0));
    if (!step.found || step.chi_square < s_.motion.step_threshold) return true;
    // Three steps cut and the block means still ten times their limit: the base sways, and steps will
    // not carry it (cutting on would only cost the time of max_steps fits).
    const bool hopeless = steps_.size() >= 3 && [&] {
      const BlockScatter b = lowFrequencyScatter(*fit_, s_.motion.block, s_.motion.block_false_alarm);
      return b.ratio > 10.0 * b.limit;
    }();
    if (static_cast<int>(steps_.size()) >= s_.motion.max_steps || hopeless) {
      steps_exhausted_ = true;
      return true;
    }
    if (!carryStep(step)) return true;  // too much left out: stillBaseProblem says so
  }
}

std::pair<std::string, std::string> GyrocompassSolver::stillBaseProblem() const {
  const AlignmentResult& r = result_;
  BaseMotionEvidence motion;
  for (const Interval& x : excluded_) motion.excluded_seconds += x.to - x.from;
  motion.steps_carried = steps_.size();
  motion.steps_exhausted = steps_exhausted_;
  motion.worst_block_spread = worst_motion_;
  const std::string moved = baseMotionProblem(motion, s_.motion, s_.duration);
  if (!moved.empty()) return {kMotionGate, moved};
  if (r.scatter > s_.motion.max_scatter) {
    return {"stillness", formatNumbers("the residuals scatter %.2f times what the noise model predicts "
                                       "(motion/max_scatter %.2f): a base that sways or vibrates, a bias "
                                       "that jumps, or angle noise beyond the settings'",
                                       r.scatter, s_.motion.max_scatter)};
  }
  if (r.low_frequency_scatter > r.low_frequency_limit) {
    return {"stillness", formatNumbers("the residuals' %.3g s means scatter %.2f times what the noise model "
                                       "predicts (a still base exceeds %.2f once in %.3g windows): a base "
                                       "that sways slowly, or a random walk beyond the settings'",
                                       s_.motion.block, r.low_frequency_scatter, r.low_frequency_limit,
                                       1.0 / s_.motion.block_false_alarm)};
  }
  return {"", ""};
}

bool GyrocompassSolver::solveStill(HeadingSolution* h) {
  if (!fitStillBase()) return false;
  AlignmentResult& r = result_;
  r.samples = samples_;
  r.seconds = used_seconds_;
  r.worst_motion = worst_motion_;
  r.base_steps = steps_;
  for (const Interval& x : excluded_) r.excluded_seconds += x.to - x.from;
  if (!level(&still_level_)) return false;
  const AngleFitResult& f = fit_->result();
  r.white_noise = f.white_noise;
  r.scatter = *std::max_element(f.scatter.begin(), f.scatter.end());
  // The sweep's residuals carry what its harmonic regressors leave: its base is judged per point only.
  if (s_.mode != AlignmentMode::kSweep) {
    const BlockScatter blocks = lowFrequencyScatter(*fit_, s_.motion.block, s_.motion.block_false_alarm);
    r.low_frequency_scatter = blocks.ratio;
    r.low_frequency_limit = blocks.limit;
  }
  summariseSegments(f);
  measure(*fit_, still_level_, &still_rate_);
  *h = solveHeading(still_rate_, still_level_, s_.latitude);
  if (!steps_.empty()) {
    r.notes.push_back(formatNumbers("the base took %.0f step(s), carried: %.1f s left out around them",
                                    static_cast<double>(steps_.size()), r.excluded_seconds));
  }
  return true;
}

bool GyrocompassSolver::answerFromStill(const HeadingSolution& h, const std::string& why) {
  AlignmentResult& r = result_;
  r.estimator = "still_base";
  r.estimator_reason = why;
  // The fit's frame is the first rest's; the body at the window's end carries the steps since.
  const Eigen::Matrix3d end = h.orientation.toRotationMatrix() * carriedRotation(INFINITY);
  r.orientation = Eigen::Quaterniond(end).normalized();
  r.attitude = eulerFromOrientation(r.orientation);
  r.covariance_enu = h.covariance_enu;
  r.covariance_rpy = steps_.empty() ? h.covariance_rpy : eulerCovarianceFromEnu(r.attitude, h.covariance_enu);
  r.heading = trueHeadingDegrees(r.attitude.yaw);
  r.heading_sigma = h.budget.total * kDegrees;
  r.levelled_rate = h.levelled_rate;
  r.horizontal_rate = h.horizontal_rate;
  r.horizontal_rate_std = h.horizontal_rate_std;
  r.budget = h.budget;
  r.budget.max_latitude = s_.max_latitude;
  describeHoldStart(h);
  return applyStillGates(h);
}

}  // namespace core
}  // namespace hrg_gyro

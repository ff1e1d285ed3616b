// The solution of a gyrocompass window: the records Gyrocompass holds (gyrocompass_records.h) turned into
// integrated-angle series by mode (static: the triad's three body axes; indexed: the channels' directions turned by the
// indexer, its rests or its continuous angle; sweep: each axis against its commanded angle and that
// angle's harmonics), the level from the gravity reference, one IntegratedAngleFit, the Earth's rate
// with every term of its covariance, the heading (earth_rate_heading) and the gates. Gyrocompass::finish
// builds one over its records and returns solve(); nothing else uses it.
//
// Two estimators (alignment_settings.h, EstimatorChoice):
//   still base  the fit above on the rests of the base: a step the base takes (base_motion_scan.h) cuts
//               the window there, `motion/step_guard` s each side left out, and (static) the rotation the
//               gyros measured across it carried: later samples and accelerometer records are turned
//               back into the first rest's frame, the attitude given is the body's at the window's end.
//   tracking    with the triad and an accelerometer (static, indexed): the body tracked by the gyros,
//               gravity followed in the inertial frame (inertial_frame_alignment.h), over the unbroken
//               stretch of triad samples that ends the window.
// The still base answers where the base is still (its residuals white at every time scale, its steps
// within max_steps and max_excluded); otherwise the tracking does, or, without an accelerometer, the
// window is refused. Both running, a heading difference beyond max_estimator_sigmas of their noise
// (a slow lean the gyros alone cannot tell from the Earth's rate) hands the answer to the tracking.
// The answer is then checked against the Earth (earth_checks.h). No ROS.
#pragma once

#include <Eigen/Core>
#include <array>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "hrg_gyro/core/alignment/alignment_result.h"
#include "hrg_gyro/core/alignment/alignment_settings.h"
#include "hrg_gyro/core/alignment/base_motion_scan.h"
#include "hrg_gyro/core/alignment/earth_rate_heading.h"
#include "hrg_gyro/core/alignment/gyrocompass_records.h"
#include "hrg_gyro/core/alignment/inertial_frame_alignment.h"
#include "hrg_gyro/core/alignment/integrated_angle_fit.h"

namespace hrg_gyro {
namespace core {

class GyrocompassSolver {
 public:
  /// `settings` as the gyrocompass resolved them (its noise model complete); `records` its window's.
  GyrocompassSolver(const AlignmentSettings& settings, const GyrocompassRecords& records) : w_(records), s_(settings) {}
  AlignmentResult solve();

 private:
  struct Segment {
    int channel = -1;
    int group = 0;  // the indexer position (its angle error is shared by its segments)
    double start = 0.0, end = 0.0, angle = NAN, rate = NAN;
  };
  bool refuse(const std::string& gate, const std::string& reason) {
    result_.accepted = false;
    result_.gate = gate;
    result_.reason = reason;
    return false;
  }
  double seconds(Nanoseconds stamp) const { return w_.seconds(stamp); }
  // The still-base fit: the series by mode, fitted, cut at the base's steps until none is left.
  void resetSeries();
  bool buildSeries();
  bool fitStillBase();
  bool stepScanApplies(const AngleFitResult& f);
  bool carryStep(const BaseStep& step);
  bool excludedSample(double t_a, double t_b) const;
  Eigen::Matrix3d carriedRotation(double t) const;  // body at t -> the first rest's frame (static)
  // The gate and reason that keep the still-base fit from answering; empty when the base was still.
  std::pair<std::string, std::string> stillBaseProblem() const;
  // The tracking estimator and the choice between the two.
  bool canTrack() const;
  InertialFrameResult track();
  Eigen::Matrix3d trackedFrameFromBody() const;  // indexed: body -> the indexer's zero frame at the end
  bool chooseAndAnswer(const HeadingSolution& still, const InertialFrameResult& tracked);
  bool answerFromStill(const HeadingSolution& h, const std::string& why);
  bool answerFromTracking(const InertialFrameResult& t, const std::string& why);
  bool checkEarth(const EarthRateMeasurement& m, const LevelMeasurement& level);
  bool checkEarthTracked(const InertialFrameResult& t);
  bool solveStill(HeadingSolution* h);
  bool buildStatic();
  bool buildIndexed();
  bool buildSweep();
  bool buildSweepAxis(std::size_t axis, std::size_t per_axis);  // one axis's series, against its commanded angle
  std::vector<Eigen::Vector3d> indexedDirections(std::size_t channels) const;  // the channels' in the platform
  bool prepareIndexer();
  bool indexerAt(double t, double* angle) const;
  // The indexer's angle at both ends of a sample (its rest's, or interpolated); false: not usable.
  bool indexerSpan(double t_a, double t_b, int* rest, double* psi_a, double* psi_b) const;
  // Refuses a design that senses one horizontal component (or none) of the Earth's rate.
  bool indexedDesignResolvesHeading(const std::vector<Eigen::Vector2d>& s1, const std::vector<Eigen::Matrix2d>& s2,
                                    double weight);
  void commandTrack(const std::vector<PrecessionStateRecord>& records, std::vector<double>* times,
                    std::vector<double>* psi, std::vector<double>* change_time, std::vector<double>* change_rate) const;
  bool sweptBothWays(std::size_t axis, double turned_up, double turned_down);
  void describeHoldStart(const HeadingSolution& h);
  /// An Allan file's tau0 against the window's sample spacing (gate noise).
  bool allanRateMatches();
  bool applyStillGates(const HeadingSolution& h);
  bool gateAttitude();
  bool level(LevelMeasurement* out);
  bool measure(const IntegratedAngleFit& fit, const LevelMeasurement& level, EarthRateMeasurement* m);
  void summariseSegments(const AngleFitResult& fit);

  const GyrocompassRecords& w_;  // the window's records
  const AlignmentSettings& s_;
  AlignmentResult result_;
  std::unique_ptr<IntegratedAngleFit> fit_;
  struct Interval {
    double from = 0.0, to = 0.0;
  };
  std::vector<Interval> excluded_;  // s from the window's start, sorted, disjoint
  std::vector<BaseStepRecord> steps_;
  std::vector<Eigen::Matrix3d> carried_;  // after each step: the later body -> the first rest's frame
  bool steps_exhausted_ = false;          // max_steps reached with a step still found
  EarthRateMeasurement still_rate_;       // the still-base fit's, for the checks against the Earth
  LevelMeasurement still_level_;
  Eigen::Vector3d mean_rate_ = Eigen::Vector3d::Zero();  // the tracked stretch's mean gyro rate, b0
  std::vector<AngleSeries> series_;
  std::size_t parameters_ = 0;
  std::vector<Segment> segments_;  // by segment id
  double worst_motion_ = 0.0;
  std::uint64_t samples_ = 0;
  double used_seconds_ = 0.0;
  // Indexer track, seconds from the window's start.
  std::vector<double> indexer_time_, indexer_angle_, indexer_rate_;
  struct Rest {
    double from = 0.0, to = 0.0, angle = 0.0;
  };
  std::vector<Rest> rests_;
  // Sweep: each axis's probes (the integrals of cos k psi and sin k psi, orders 2 and 4) for the
  // residual drift harmonics' budget.
  std::array<std::array<std::vector<double>, 4>, 3> sweep_probes_;
  Eigen::Matrix3d triad_matrix_ = Eigen::Matrix3d::Identity();
};

}  // namespace core
}  // namespace hrg_gyro

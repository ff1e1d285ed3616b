// The solution of a gyrocompass window: the records Gyrocompass holds turned into integrated-angle
// series by mode (static: the triad's three body axes; indexed: the channels' directions turned by the
// indexer, its rests or its continuous angle; sweep: each axis against its commanded angle and that
// angle's harmonics), the level from the gravity reference, one IntegratedAngleFit, the Earth's rate
// with every term of its covariance, the heading (earth_rate_heading) and the gates. Gyrocompass::finish
// builds one over its records and returns solve(); nothing else uses it. No ROS.
#pragma once

#include <Eigen/Core>
#include <array>
#include <string>
#include <vector>

#include "hrg_gyro/core/alignment/earth_rate_heading.h"
#include "hrg_gyro/core/alignment/gyrocompass.h"
#include "hrg_gyro/core/alignment/integrated_angle_fit.h"

namespace hrg_gyro {
namespace core {

/// printf-style message with up to four numbers (the refusals' wording).
std::string formatAlignmentMessage(const char* pattern, double a = 0.0, double b = 0.0, double c = 0.0, double d = 0.0);

class GyrocompassSolver {
 public:
  explicit GyrocompassSolver(const Gyrocompass& g) : g_(g), s_(g.settings_) {}
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
  double seconds(Nanoseconds stamp) const { return toSeconds(stamp - g_.start_); }
  bool buildStatic();
  bool buildIndexed();
  bool buildSweep();
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
  AlignmentResult applyGates(const HeadingSolution& h);
  bool level(LevelMeasurement* out);
  bool measure(const IntegratedAngleFit& fit, const LevelMeasurement& level, EarthRateMeasurement* m);
  void summariseSegments(const AngleFitResult& fit);

  const Gyrocompass& g_;
  const AlignmentSettings& s_;
  AlignmentResult result_;
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

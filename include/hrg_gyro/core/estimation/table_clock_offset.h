// The offset between the table's stamps and the gyro's, measured where both see the same event:
// every change of the table's rate. A record stamped s describes the table at gyro time s - offset,
// so the table angle taken at gyro time t is phi(t - offset) ~ phi(t) - offset x rate(t). On a
// plateau that is a constant, which the calibration's increments never see; across a change of rate
// from W_a to W_b it is a jump of -offset (W_b - W_a) in the table angle, and the wave angle, which
// turned with the true table, disagrees by K offset (W_b - W_a) with the angle that the model
// predicts from the logged table:
//
//   offset = [mean(theta - I) after - mean(theta - I) before] / (K (W_b - W_a)),
//
// I the model's integral along the path, int K(theta) (dphi + Omega_E dt) + D(theta) dt, with the
// measured theta and the logged phi; the means are over the last `window` s of settled plateau
// before the change and the first after it, K the model's over the change. The K(theta) and D(theta) are those the
// calibration found, so the transitions are kept (thinned to at most `max_rate` samples per s) and measured at the end.
// Each transition gives one offset; a straight line through them in time gives the offset and its drift (the table's
// clock running at another rate than the gyro's, which scales K), their scatter about it the uncertainty, and a scatter
// far beyond what the wave-angle noise explains says the offset stepped during the session. No ROS.
#pragma once

#include <cstdint>
#include <deque>
#include <string>
#include <vector>

#include "hrg_gyro/core/common/units.h"
#include "hrg_gyro/core/model/harmonic_model.h"

namespace hrg_gyro {
namespace core {

class ModelPairEvaluator;

struct TableClockOffsetSettings {
  double window = 1.0;  ///< s of settled plateau on each side of a change
  /// s left out before the table's stamps show it leaving its plateau: with its stamps late by up to
  /// this, the gyro turned with the change while the table's records still showed the plateau
  double guard = 0.5;
  double max_rate = 200.0;         ///< samples kept per s of a transition
  double min_rate_change = 0.005;  ///< rad/s: smaller changes of rate are not measured
  double max_transition = 30.0;    ///< s from leaving one settled plateau to settling on the next
  std::size_t max_transitions = 64;
  double max_sample_gap = 0.1;  ///< s between two samples beyond which a change of rate is left out
};

/// One change of rate seen by both streams.
struct TableClockTransition {
  Nanoseconds stamp = 0;      ///< gyro stamp where the table left its plateau
  double rate_before = 0.0;   ///< rad/s
  double rate_after = 0.0;    ///< rad/s
  double offset = 0.0;        ///< s, table stamps minus gyro stamps
  double offset_noise = 0.0;  ///< s, predicted from the wave angle's scatter in the two windows
};

struct TableClockOffsetResult {
  bool estimated = false;
  std::string note;         ///< why not, or what the scatter says
  double offset = 0.0;      ///< s, mean of the transitions
  double offset_std = 0.0;  ///< s, its standard error
  double spread = 0.0;      ///< s, largest minus smallest transition offset
  /// The offset's steady drift over the session: the table's clock runs 1 + rate_error times as fast
  /// as the gyro's. It scales the table angle against the gyro's time, so K by 1 + rate_error.
  bool rate_estimated = false;  ///< at least 3 changes over at least a minute
  double rate_error = 0.0;      ///< s per s
  double rate_error_std = 0.0;
  bool changed = false;  ///< the offsets disagree beyond their noise and a steady drift: the offset stepped
  std::vector<TableClockTransition> transitions;
};

class TableClockOffsetEstimator {
 public:
  explicit TableClockOffsetEstimator(const TableClockOffsetSettings& settings = {});

  /// Every wave sample that had table records around it, in stamp order: theta the measured wave
  /// angle, table_angle and table_rate interpolated at its stamp, and the plateau it lies on (its id,
  /// its rate, whether settled).
  void add(Nanoseconds stamp, double theta, double table_angle, double table_rate, std::uint64_t plateau,
           double plateau_rate, bool settled);

  /// The offset from the transitions kept, with the calibrated models (K and D at the frequency
  /// `frequency`, NaN when independent of it) and the vertical Earth rate.
  TableClockOffsetResult estimate(const HarmonicModel& k, const HarmonicModel& d, double earth_rate,
                                  double frequency = NAN) const;

  std::size_t transitions() const { return done_.size(); }

 private:
  struct Sample {
    double t;  // s from the transition's (or the tail's) first sample
    double theta, phi;
    int side;  // -1 settled before, 0 between, +1 settled after
  };
  struct Transition {
    Nanoseconds origin = 0, left = 0;
    double rate_before = 0.0, rate_after = 0.0;
    std::vector<Sample> samples;
  };
  void keep(std::deque<Sample>* into, Nanoseconds origin, Nanoseconds stamp, double theta, double phi, int side);
  /// The steps of add(): a sample while a change of rate is open; the change complete, settled on
  /// its new plateau; a settled sample on a plateau; the table leaving its plateau.
  void addInTransition(Nanoseconds stamp, double theta, double table_angle, std::uint64_t plateau, double plateau_rate,
                       bool settled);
  void completeTransition(Nanoseconds stamp, double t, std::uint64_t plateau, double plateau_rate);
  void addOnPlateau(Nanoseconds stamp, double theta, double table_angle, std::uint64_t plateau, double plateau_rate);
  void beginTransition(Nanoseconds stamp, double theta, double table_angle);
  /// One change of rate's offset from the model's integral along its path (K0 `k0` where the change
  /// has no sample of its own); false when a side has fewer than 3 samples.
  static bool measure(const Transition& tr, ModelPairEvaluator* models, double earth_rate, double frequency, double k0,
                      TableClockTransition* out);

  TableClockOffsetSettings settings_;
  Nanoseconds last_kept_ = 0, last_added_ = 0;
  std::size_t broken_ = 0;  // changes of rate left out for a gap in the samples
  // The settled plateau the table is on and its last `window` s: the "before" side of a change.
  bool on_plateau_ = false;
  std::uint64_t plateau_ = 0;
  double plateau_rate_ = 0.0;
  std::deque<Sample> tail_;
  Nanoseconds tail_origin_ = 0;
  // The change under way.
  bool in_transition_ = false, has_after_ = false;
  std::uint64_t before_plateau_ = 0, after_plateau_ = 0;
  double before_rate_ = 0.0, after_start_ = 0.0;
  Nanoseconds open_origin_ = 0, left_ = 0;
  std::deque<Sample> open_samples_;
  std::vector<Transition> done_;
};

}  // namespace core
}  // namespace hrg_gyro

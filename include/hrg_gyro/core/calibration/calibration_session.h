// One calibration run fed by the two live streams (or a bag): turntable states and wave angles.
//
// The streams arrive independently, so a wave sample is held until the turntable stream has passed
// its stamp; it is then classified by the turntable states on either side of it: both must belong
// to the same settled plateau (a sample at a plateau boundary is skipped), and it is handed to the
// method with that plateau, the interpolated table angle and the reported rate. Memory is bounded:
// the wave queue and the turntable history are trimmed by age, the methods keep bins.
#pragma once

#include <cmath>
#include <cstdint>
#include <memory>

#include "hrg_gyro/core/calibration/calibration_method_interface.h"
#include "hrg_gyro/core/common/ring_buffer.h"
#include "hrg_gyro/core/model/gyro_parameters.h"

namespace hrg_gyro {
namespace core {

struct SessionCounters {
  std::uint64_t turntable = 0;       ///< turntable states received
  std::uint64_t wave = 0;            ///< wave samples received
  std::uint64_t used = 0;            ///< handed to the method
  std::uint64_t unsettled = 0;       ///< not on a settled plateau (ramps, settling, boundaries)
  std::uint64_t unsynchronized = 0;  ///< no turntable state around the stamp (or too far away)
  std::uint64_t out_of_order = 0;    ///< stamps going backwards within a stream
};

class CalibrationSession {
 public:
  CalibrationSession(const CalibrationSettings& settings, const GyroParameters& prior);

  void addTurntable(Nanoseconds stamp, double angle, double rate);
  /// quadrature_ratio: B/A of the wave (NaN if unknown), averaged for the defect diagnosis.
  void addWave(Nanoseconds stamp, double theta, double frequency, double quadrature_ratio = NAN);
  void addGeneratorPair(Nanoseconds stamp, const ChannelVector& raw, const ChannelVector& reference);
  /// The generator stream has moved past its sweep (told by that same stream, so it cannot be
  /// confused by another stream's lag): the correction-matrix run may finish.
  void generatorSweepEnded();

  const CalibrationSettings& settings() const { return settings_; }
  const GyroParameters& prior() const { return prior_; }
  const SessionCounters& counters() const { return counters_; }
  CalibrationProgress progress() const { return method_->progress(); }
  bool complete() const { return method_->complete(); }
  /// Auto-finish rule: the data are complete and the table has rested for auto_finish_idle s (for
  /// the correction matrix: the generator sweep has ended).
  bool shouldFinish() const;
  /// Fits, applies the gates and builds the new parameters (does not write anything).
  CalibrationOutcome finish() const;

 private:
  struct TurntableRecord {
    Nanoseconds stamp;
    double angle, rate;
    PlateauState plateau;
  };
  struct WaveRecord {
    Nanoseconds stamp;
    double theta, frequency;
  };
  void drain();
  void classify(const WaveRecord& w);

  CalibrationSettings settings_;
  GyroParameters prior_;
  std::unique_ptr<CalibrationMethod> method_;
  PlateauDetector detector_;
  RingBuffer<TurntableRecord> turntable_;
  RingBuffer<WaveRecord> pending_;
  SessionCounters counters_;
  Nanoseconds last_wave_stamp_ = 0;
  Nanoseconds last_generator_stamp_ = 0;
  bool generator_ended_ = false;
  double quadrature_sum_ = 0.0;  // of |B/A|, for the diagnosis's F factor
  std::uint64_t quadrature_count_ = 0;
};

}  // namespace core
}  // namespace hrg_gyro

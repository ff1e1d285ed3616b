// Turn-on bias capture: while the gyro stands still, the processor's outputs over a set time give
// the drift D0 that makes the compensated rate equal the Earth rate, and the model in force is
// refreshed with it (the harmonics of D and the shape of K are kept).
//
// At rest the wave obeys dtheta/dt = K(theta) Omega_v + D(theta), Omega_v the vertical Earth rate
// of the model's latitude. Over the capture, with the sums taken over the accepted outputs,
//   D0_new = (sum dtheta - Omega_v sum K dt - sum (D - D0) dt) / sum dt,
// where K and D are the values the compensation used at each step (so the D harmonics at the
// angles the wave visited are accounted for, and any frequency dependence of K and D too). For a
// frequency-dependent model every node's mean moves by the same amount.
//
// Stillness is judged on the compensated rate, in blocks of `block` seconds (block_mean_stillness.h): the capture is
// refused when a block's mean rate leaves the capture's mean by more than `max_motion`, when the
// mean itself is further than `max_bias` from the Earth rate (a turntable at constant rate), when
// the input has a gap or a reset, when the precession loop turns the wave (an output flagged
// PRECESSING), or when the model changes during the capture.
#pragma once

#include <cstdint>
#include <string>

#include "hrg_gyro/core/model/gyro_parameters.h"
#include "hrg_gyro/core/processing/block_mean_stillness.h"
#include "hrg_gyro/core/processing/compensator.h"

namespace hrg_gyro {
namespace core {

struct BiasCaptureSettings {
  double duration = 10.0;    ///< s of sample time averaged
  double block = 0.5;        ///< s, length of the blocks whose mean rates judge stillness
  double max_motion = 2e-3;  ///< rad/s, largest departure of a block's mean rate from the capture's mean
  double max_bias = 5e-3;    ///< rad/s, largest |mean compensated rate - Earth rate| taken as a bias
  /// Throws ConfigError naming the setting when a value is out of range.
  void validate() const;
};

struct BiasCaptureResult {
  bool accepted = false;
  std::string reason;    ///< why it was refused, or a one-line summary when accepted
  double seconds = 0.0;  ///< sample time averaged
  std::uint64_t samples = 0;
  double mean_rate = 0.0;     ///< rad/s, compensated body rate through the model in force
  double earth_rate = 0.0;    ///< rad/s, vertical Earth rate of the model
  double worst_motion = 0.0;  ///< rad/s, largest block departure seen
  double previous_d0 = 0.0;   ///< rad/s, D0 of the model in force (at the capture's mean frequency)
  double new_d0 = 0.0;        ///< rad/s
  GyroParameters parameters;  ///< the refreshed model (when accepted)
};

class BiasCapture {
 public:
  /// `in_force` is the model the processor is using; `settings` must be valid.
  BiasCapture(const BiasCaptureSettings& settings, const GyroParameters& in_force);

  /// One output of the processor (its increment and flags). Returns true once the capture has
  /// ended (complete, or refused early).
  bool add(const AngleIncrement& increment, std::uint8_t flags);
  /// Ends the capture early with a reason (no input, model reloaded, shutdown).
  void abort(const std::string& reason);
  bool finished() const { return finished_; }
  /// The outcome; valid once finished().
  BiasCaptureResult result() const;

 private:
  BiasCaptureSettings settings_;
  GyroParameters in_force_;
  double earth_rate_;
  bool finished_ = false;
  std::string refusal_;
  // Sums over the capture.
  double sum_dt_ = 0.0, sum_dtheta_ = 0.0, sum_k_dt_ = 0.0, sum_harmonic_d_dt_ = 0.0, sum_dalpha_ = 0.0;
  double sum_frequency_dt_ = 0.0, frequency_dt_ = 0.0;
  std::uint64_t samples_ = 0;
  BlockMeanStillness stillness_;  // block means of the compensated rate
};

/// The parameter file's `calibration.notes` after a bias capture at `when` (UTC text): the capture's
/// note first, then the earlier notes without the note of an earlier capture. Only the latest
/// capture is worth a note (its D0 replaced the earlier one), so repeated captures do not grow it.
std::string notesAfterBiasCapture(const std::string& notes, const std::string& when);

}  // namespace core
}  // namespace hrg_gyro

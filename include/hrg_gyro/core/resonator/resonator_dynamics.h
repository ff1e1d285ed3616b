// The resonator with its loops closed, advanced in time: the averaged equations
// (averaged_resonator.h) driven by the control loops (control_loops.h) through the imperfect drive
// chain (drive_chain.h). This is what a simulator steps to get (A, B, theta, tau) per output sample
// instead of integrating a given K(theta) and D(theta); the drift then follows from the shell's
// defects and the drive's errors (first_order_model.h, steady_state_response.h).
//
// A step of dt is split into n = ceil(dt control_rate) equal control periods. At the start of each
// the loops sample the wave (the true state: the pickoffs' errors belong to the signal level) and
// their wave-frame command is held over the period (a zero-order hold, as a digital controller's
// loop filters do), while the modulator places it on the forcers with the wave's current angle and
// phase (it runs at the carrier, with the demodulator); the averaged equations are integrated over
// the period by one classical Runge-Kutta step. The body rate is linear in time across the step, which RK4
// integrates exactly, so an ideal shell turns by exactly K0 times the body angle. Fixed-size state
// only: a step allocates nothing.
#pragma once

#include <cstdint>

#include "hrg_gyro/core/model/wave_parameters.h"
#include "hrg_gyro/core/resonator/averaged_resonator.h"
#include "hrg_gyro/core/resonator/control_loops.h"
#include "hrg_gyro/core/resonator/drive_chain.h"
#include "hrg_gyro/core/resonator/shell_parameters.h"

namespace hrg_gyro {
namespace core {

/// The inputs of one step.
struct ResonatorInputs {
  double body_rate_start = 0.0;  ///< Omega at the step's start, rad/s (inertial, about the sensitive axis)
  double body_rate_end = 0.0;    ///< Omega at its end; linear in between
  double virtual_rate = 0.0;     ///< commanded electrical precession rate, rad/s, held over the step
  /// Added to dtheta/dt as it is (rad/s): effects this model leaves out, e.g. a simulated turn-on bias.
  double angle_rate = 0.0;
};

class ResonatorDynamics {
 public:
  /// Throws std::invalid_argument if any settings fail to validate or the initial wave does not
  /// stand (A^2 > B^2, all finite).
  ResonatorDynamics(const ShellParameters& parameters, const LoopSettings& loops, const DriveChainErrors& drive,
                    const WaveParameters& initial);

  /// Advances by dt > 0 s. Returns false, leaving the wave where the failing control period began,
  /// if the wave stopped standing (A^2 <= B^2 or a value not finite): the slow variables are
  /// singular there.
  bool step(double dt, const ResonatorInputs& inputs);

  /// The wave now: theta is continuous (never wrapped), tau as the loops hold it.
  const WaveParameters& wave() const { return wave_; }
  /// Seconds advanced since construction.
  double time() const { return time_; }
  /// The reference carrier's offset dw_r (rad/s) and frequency f0 + dw_r / 2 pi (Hz).
  double referenceOffset() const { return command_.reference_offset; }
  double referenceFrequency() const;
  /// The loops' last command, and what the drive chain made of it on the wave at the end of the step.
  const LoopCommand& command() const { return command_; }
  WaveFrameForce realisedForce() const;
  const ControlLoops& loops() const { return loops_; }
  const AveragedResonator& resonator() const { return resonator_; }
  std::uint64_t controlPeriods() const { return control_periods_; }

 private:
  /// The averaged equations at w under the held command, as the modulator places it on w.
  WaveRates rates(const WaveParameters& w, double body_rate, double angle_rate) const;

  AveragedResonator resonator_;
  ControlLoops loops_;
  DriveChain drive_;
  WaveParameters wave_;
  LoopCommand command_;
  double time_ = 0.0;
  std::uint64_t control_periods_ = 0;
};

}  // namespace core
}  // namespace hrg_gyro

// The simulated gyro on its turntable: the resonator dynamics, the signal-level pickoff and
// demodulation, and the ground truth, one output sample at a time.
//
// Dynamics (docs/math.md, 'Dynamics and compensation'):
//   d theta/dt = K(theta) (Omega_table(t) + Omega_E) + D(theta) with the
// resonator's intrinsic K and D, integrated by RK4 over each resonator period. The table rate is
// piecewise linear, so the RK4 stages see it exactly. Each period is then sampled N times through
// the eight pickoffs and demodulated (SignalSynthesizer); `periods_per_output` periods are averaged
// into one output sample stamped at the centre of its window. With the generator enabled the
// session starts with a known sweep of (theta, B, tau) at rest (for the correction-matrix fit), and
// the turntable profile, if any, follows it.
//
// A wandering bias (ResonatorConfig::bias_drift) adds rate t + W B(t) to d theta/dt, t from the
// scenario start. The trend is inside the RK4 stages (linear in t, so integrated exactly); the random
// walk is held over each output window (its value at the window's start, stepped by W sqrt(T) N(0, 1)
// from a stream of its own between windows), a constant the RK4 stages integrate exactly too.
//
// The turntable records are those the table controller logs (TurntableLogger): by default one per
// output sample with its stamp and the exact table state, otherwise at the log rate with encoder
// noise, quantisation, a differenced rate, losses and glitches. Channel samples may be lost too
// (SimulationConfig::channels); a lost one is still simulated (its index counts, as a publisher's
// sequence number does) but flagged not delivered. The truth is always the exact motion.
//
// With a thermal section (temperature_dependence.h, temperature_profile.h) the temperature is evaluated at the centre
// of each output window and held over it: the pickoff defects, the amplitude and the intrinsic K and D are those of
// that temperature, and the sample reports T and f(T). Without one every sample reports the nominal frequency and an
// unknown (NaN) temperature, exactly as before thermal support existed.
//
// With the averaged resonator (SimulationConfig::dynamics, dynamics_config.h) the wave is not
// integrated from given K and D: ResonatorDynamics is stepped once per carrier period with the sensed
// rate at the period's ends (linear in between, as the RK4 stages above see it), the commanded
// virtual rate and, as an angle rate from outside the shell, the resonator section's drift at the
// period's start angle plus the bias drift (its trend at the period's middle: exact for a linear
// trend). The rate noise enters as a body-rate noise held over the period (the same angle random
// walk). The synthesizer gets the resonator's (A, B, theta, tau) at the period's start, the truth
// reports them and the reference carrier's frequency (the phase loop's), and so does the sample.
// The loops run at rest for dynamics.settle_time s before the first sample. The precession loop
// follows the scenario's schedule (dynamics.commands) and commandVirtualRate(), each applied from
// the start of the next carrier period; every sample carries the rate in force, the commanded
// virtual angle (its integral) and the commands applied within its window.
//
// One axis of a triad (TriadSimulator) senses the inertial rate about its own sensitive axis instead
// of the table's vertical rotation: it is built with an AxisRateInput, whose rate replaces
// Omega_table + Omega_E in the dynamics above; the truth's inertial angle is then that rate's
// integral (Simpson's rule on the RK4 grid, exact to the order of the RK4 stages), and the axis logs no
// table records (the triad logs its one table). With the averaged resonator the input's rate at the
// ends of each carrier period is the body rate the resonator is stepped with, and the truth's angle
// is Simpson's rule over each period (the rate at its middle added). Without an input the single-axis
// path is unchanged, bit for bit (GyroSimulatorTest.ScenarioWithoutNewSectionsKeepsItsFingerprint).
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "hrg_gyro/core/common/units.h"
#include "hrg_gyro/core/model/model_pair_evaluator.h"
#include "hrg_gyro/core/resonator/resonator_dynamics.h"
#include "hrg_gyro/core/simulation/gaussian_noise.h"
#include "hrg_gyro/core/simulation/signal_synthesizer.h"
#include "hrg_gyro/core/simulation/simulation_config.h"
#include "hrg_gyro/core/simulation/stream_delivery.h"
#include "hrg_gyro/core/simulation/turntable_log.h"

namespace hrg_gyro {
namespace core {

struct TruthState {
  double table_angle = 0.0;     ///< rad, Earth-fixed
  double table_rate = 0.0;      ///< rad/s
  double inertial_angle = 0.0;  ///< rad, table angle + vertical Earth rate x time
  double inertial_rate = 0.0;   ///< rad/s
  double theta = 0.0;           ///< true electrical angle, rad (continuous)
  double amplitude = 0.0;
  double quadrature = 0.0;
  double phase = 0.0;
  double frequency = 0.0;    ///< Hz
  double temperature = NAN;  ///< degC
  /// The injected turn-on bias D0(t) at the sample, rad/s: the mean of the intrinsic D (at the
  /// sample's temperature) plus the bias drift's trend and random walk (as held over the window).
  double bias = 0.0;
  bool generator = false;
  const std::string* segment = nullptr;  ///< profile label (owned by the simulator)
};

/// A command the precession loop took up: from `time` (s from the scenario start) it turns the
/// wave at `rate` (electrical rad/s, as commanded).
struct AppliedPrecession {
  double time = 0.0;
  double rate = 0.0;
  bool scheduled = false;  ///< from the scenario's schedule; false: commandVirtualRate()
};

/// The precession loop's state at a sample (averaged resonator only).
struct PrecessionState {
  double rate = 0.0;   ///< commanded electrical rate in force at the sample's end, rad/s
  double angle = 0.0;  ///< commanded virtual angle at the sample's centre: the integral of the commanded rate, rad
  std::uint64_t commands = 0;  ///< commands applied so far
};

struct SimulationSample {
  std::uint64_t index = 0;
  Nanoseconds stamp = 0;  ///< centre of the demodulation window
  ChannelVector z = ChannelVector::Zero();
  double frequency = 0.0;    ///< Hz
  double temperature = NAN;  ///< degC
  std::uint32_t periods = 0;
  TruthState truth;
  /// False: this channel sample was lost on its way (consumers must not see it).
  bool channels_delivered = true;
  /// Added to the stamp of this channel sample's message only (a scheduled stamp glitch; the truth
  /// keeps `stamp`).
  Nanoseconds channels_stamp_offset = 0;
  /// Turntable records logged since the previous sample, up to this one's stamp, in log order.
  std::vector<TurntableLogRecord> turntable;
  /// Averaged resonator only: the precession loop's state, and the commands it took up within this
  /// sample's window (in order).
  PrecessionState precession;
  std::vector<AppliedPrecession> precession_commands;
};

/// What one axis of a triad senses: the inertial rate about its sensitive axis, a smooth function of
/// time. Called several times per resonator period, with times that increase but for a repeat.
class AxisRateInput {
 public:
  virtual ~AxisRateInput() = default;
  /// Inertial rate about the axis at t s from the scenario start, rad/s.
  virtual double rateAt(double t) const = 0;
};

class GyroSimulator {
 public:
  /// `input` (not owned, must outlive the simulator): the rate this gyro senses, for one axis of a
  /// triad; nullptr (the default): the table's rate plus the vertical Earth rate, as a single gyro.
  explicit GyroSimulator(const SimulationConfig& config, const AxisRateInput* input = nullptr);
  // The dynamics evaluator points into config_: the simulator stays where it was built.
  GyroSimulator(const GyroSimulator&) = delete;
  GyroSimulator& operator=(const GyroSimulator&) = delete;

  const SimulationConfig& config() const { return config_; }
  /// Simulated duration of the whole scenario, s.
  double duration() const;
  /// Simulated time reached, s from the start.
  double elapsed() const { return t_; }
  bool done() const;

  /// The next output sample; false once the scenario is complete.
  bool next(SimulationSample* out);

  /// Whether the wave comes from the averaged resonator with its loops (which take precession commands).
  bool hasPrecessionLoop() const { return dynamics_.has_value(); }
  /// Commands the precession loop to turn the wave at `rate` (electrical rad/s) from the start of the
  /// next carrier period, until the next command (a scheduled one included). Throws std::logic_error
  /// without a precession loop, std::invalid_argument for a rate that is not finite.
  void commandVirtualRate(double rate);

  /// What the table controller has logged so far (records made, lost, glitched).
  const TurntableLogCounters& turntableLogCounters() const { return logger_.counters(); }

 private:
  /// d theta/dt at time t for the wave angle theta and the sensed inertial rate `sensed` (rad/s).
  double thetaRate(double t, double theta, double sensed);
  /// The inertial rate the gyro senses at t: the input's, or the table's plus the vertical Earth rate.
  double sensedRate(double t) const;
  /// Adds the input's angle over one period of h s (Simpson's rule on its rates at the period's start,
  /// middle and end) to input_angle_.
  void integrateInputAngle(double h, double rate_start, double rate_middle, double rate_end);
  /// A triad axis's truth at t_center: the input's rate there and its angle, Simpson's rule from the
  /// period boundary t_lo where it was angle_lo.
  void setInputTruth(double t_lo, double angle_lo, double t_center, TruthState* truth) const;
  void nextDynamic(SimulationSample* out);
  /// nextDynamic for the averaged resonator.
  void nextResonator(SimulationSample* out);
  /// Takes up the scheduled and commanded precession due at the current time.
  void applyPrecessionCommands(SimulationSample* out);
  void nextGenerator(SimulationSample* out);
  double generatorDuration() const;
  std::uint64_t generatorOutputsPerState() const;
  void stamp(double t_center, SimulationSample* out) const;
  /// Advances t_ by one carrier period h.
  void advanceTime(double h);
  /// A window of `m` periods from t_start to t_: its mean channels (sum / m), frequency, temperature
  /// and stamp; returns its centre, s.
  double closeWindow(const ChannelVector& sum, int m, double t_start, SimulationSample* out) const;
  /// The truth's wave (A, B, tau), frequency, temperature and injected bias at t_center.
  void setTruthWave(double amplitude, double quadrature, double phase, double t_center, bool generator,
                    TruthState* truth) const;
  /// The injected D0 at t s from the start, within the current window (TruthState::bias).
  double injectedBias(double t) const;
  /// Thermal scenarios: moves the gyro to the temperature at time t (s from the start).
  void updateTemperature(double t);
  /// Fills out->turntable with the records logged up to the sample's centre time t_center.
  void logTurntable(double t_center, SimulationSample* out);

  SimulationConfig config_;
  SignalSynthesizer synth_;
  GaussianNoise rate_noise_;       // separate stream: switching it on leaves the pickoff noise unchanged
  GaussianNoise bias_walk_draws_;  // the bias random walk's own stream, for the same reason
  double bias_walk_ = 0.0;         // W B(t) at the current window's start, held over the window, rad/s
  // Intrinsic K and D: the resonator's own models, or (thermal) those of the current temperature.
  HarmonicModel thermal_k_{0.0}, thermal_d_{0.0};
  ModelPairEvaluator intrinsic_;
  double temperature_ = NAN;  // degC; NaN without a thermal section
  double frequency_;          // reported resonance frequency, Hz
  double amplitude_;          // wave amplitude A at the current temperature
  double earth_rate_;
  const AxisRateInput* input_;  // nullptr: the single-axis table
  double input_angle_ = 0.0;    // integral of the input's rate up to t_, rad (Kahan-compensated)
  double input_angle_compensation_ = 0.0;
  double t_ = 0.0;  // s since start, Kahan-compensated
  double t_compensation_ = 0.0;
  double theta_;  // true electrical angle at t_
  std::uint64_t index_ = 0;
  TurntableLogger logger_;
  StreamDelivery channel_delivery_;
  std::uint64_t next_log_ = 0;  // index of the next record at the turntable log rate
  std::uint64_t generator_state_ = 0;
  std::uint64_t generator_outputs_in_state_ = 0;
  std::string generator_label_ = "generator";
  // The averaged resonator (dynamics.model: averaged), its precession commands and their integral.
  std::optional<ResonatorDynamics> dynamics_;
  std::size_t next_scheduled_ = 0;
  std::optional<double> commanded_;  // commandVirtualRate(), not yet taken up
  double virtual_rate_ = 0.0;
  double virtual_angle_ = 0.0;  // at t_, rad
  std::uint64_t precession_commands_ = 0;
  double shell_bias_ = 0.0;  // the mean of the averaged shell's settled drift, rad/s (TruthState::bias)
};

}  // namespace core
}  // namespace hrg_gyro

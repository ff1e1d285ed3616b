#include "hrg_gyro/core/simulation/gyro_simulator.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <vector>

#include "hrg_gyro/core/model/earth_rate.h"
#include "hrg_gyro/core/simulation/intrinsic_model.h"

namespace hrg_gyro {
namespace core {

GyroSimulator::GyroSimulator(const SimulationConfig& config, const AxisRateInput* input)
    : config_(config),
      synth_(config_.pickoff, config_.resonator.samples_per_period, config_.seed),
      rate_noise_(config_.seed ^ 0x5deece66dULL),
      bias_walk_draws_(config_.seed ^ 0x1f83d9abfb41bd6bULL),
      intrinsic_(config_.resonator.scale_factor, config_.resonator.drift),
      frequency_(config_.resonator.frequency),
      amplitude_(config_.resonator.amplitude),
      earth_rate_(verticalEarthRate(config_.latitude)),
      input_(input),
      theta_(config_.resonator.initial_theta),
      logger_(config_.turntable_log, config_.seed),
      channel_delivery_(config_.channels, config_.seed ^ 0x9b05688c2b3e6c1fULL) {
  if (config_.ripple.amplitude > 0.0) {
    config_.profile.setRipple(config_.ripple.amplitude, config_.ripple.frequency, config_.ripple.phase);
  }
  if (config_.thermal.enabled) updateTemperature(0.0);
  const DynamicsConfig& d = config_.dynamics;
  if (d.averaged()) {
    const ResonatorConfig& rc = config_.resonator;
    const IntrinsicModel intrinsic(config_);
    shell_bias_ = intrinsic.meanDrift() - rc.drift.meanAt(rc.frequency);
    dynamics_.emplace(d.shell, d.loops, d.drive, WaveParameters{rc.amplitude, 0.0, theta_, rc.phase});
    // The loops lock at rest (the sensed rate of the first instant, no virtual rate) before the
    // first sample, as in a gyro that has been running.
    if (d.settle_time > 0.0) {
      ResonatorInputs rest;
      rest.body_rate_start = rest.body_rate_end = sensedRate(0.0);
      const double period = 1.0 / rc.frequency;
      const long periods = std::lround(d.settle_time / period);
      for (long i = 0; i < periods; ++i) {
        if (!dynamics_->step(period, rest))
          throw std::runtime_error("resonator: the wave stopped standing while the loops settled");
      }
    }
    theta_ = dynamics_->wave().theta;
  }
}

void GyroSimulator::commandVirtualRate(double rate) {
  if (!dynamics_) throw std::logic_error("no precession loop: the scenario's dynamics are not the averaged resonator");
  if (!std::isfinite(rate)) throw std::invalid_argument("virtual rate must be finite");
  commanded_ = rate;
}

void GyroSimulator::applyPrecessionCommands(SimulationSample* out) {
  const std::vector<ScheduledPrecession>& schedule = config_.dynamics.commands;
  // Due when its time falls before the middle of this period (stamps are on the period grid).
  const double due = t_ + 0.5 / config_.resonator.frequency;
  while (next_scheduled_ < schedule.size() && schedule[next_scheduled_].time < due) {
    virtual_rate_ = schedule[next_scheduled_++].rate;
    ++precession_commands_;
    out->precession_commands.push_back({t_, virtual_rate_, true});
  }
  if (commanded_) {
    virtual_rate_ = *commanded_;
    commanded_.reset();
    ++precession_commands_;
    out->precession_commands.push_back({t_, virtual_rate_, false});
  }
}

void GyroSimulator::logTurntable(double t_center, SimulationSample* out) {
  out->turntable.clear();
  out->channels_delivered = channel_delivery_.delivered(t_center);
  out->channels_stamp_offset = channel_delivery_.stampOffset(t_center);
  if (input_) return;  // one axis of a triad: the triad logs the table
  const double log_rate = config_.turntable_log.rate;
  if (log_rate == 0.0) {
    // One record with the sample, stamped like it, from the sample's own truth.
    logger_.log(t_center, out->stamp, out->truth.table_angle, out->truth.table_rate, &out->turntable);
    return;
  }
  for (;; ++next_log_) {
    const double t = static_cast<double>(next_log_) / log_rate;
    if (t > t_center) break;
    double angle, rate;
    config_.profile.evaluate(t - generatorDuration(), &angle, &rate);
    logger_.log(t, toNanoseconds(config_.start_time + t), angle, rate, &out->turntable);
  }
}

void GyroSimulator::updateTemperature(double t) {
  const double temperature = config_.thermal.profile.evaluate(t);
  if (temperature == temperature_) return;  // a hold: nothing to rebuild
  const ResonatorConfig& rc = config_.resonator;
  GyroAtTemperature g = gyroAtTemperature(config_.thermal, temperature, rc.frequency, rc.amplitude, config_.pickoff,
                                          rc.scale_factor, rc.drift);
  temperature_ = temperature;
  frequency_ = g.frequency;
  amplitude_ = g.amplitude;
  synth_.setDefects(g.pickoff);
  thermal_k_ = std::move(g.scale_factor);
  thermal_d_ = std::move(g.drift);
  intrinsic_ = ModelPairEvaluator(thermal_k_, thermal_d_);
}

std::uint64_t GyroSimulator::generatorOutputsPerState() const {
  return static_cast<std::uint64_t>(std::max(1.0, std::round(config_.generator.dwell / config_.outputPeriod())));
}

double GyroSimulator::generatorDuration() const {
  if (!config_.generator.enabled) return 0.0;
  const GeneratorConfig& g = config_.generator;
  const double states = static_cast<double>(g.angles) * g.quadratures.size() * g.phases.size();
  return states * generatorOutputsPerState() * config_.outputPeriod();
}

double GyroSimulator::duration() const { return generatorDuration() + config_.profile.duration(); }

bool GyroSimulator::done() const { return t_ >= duration() - 1e-9; }

double GyroSimulator::sensedRate(double t) const {
  if (input_) return input_->rateAt(t);
  double angle, rate;
  config_.profile.evaluate(t - generatorDuration(), &angle, &rate);
  return rate + earth_rate_;
}

double GyroSimulator::thetaRate(double t, double theta, double sensed) {
  double k, d;
  intrinsic_.evaluate(theta, config_.resonator.frequency, &k, &d);
  const BiasDriftConfig& drift = config_.resonator.bias_drift;
  // Only with a drift: adding a zero could still flip the sign of a zero rate.
  if (drift.enabled()) return k * sensed + d + (drift.trendAt(t) + bias_walk_);
  return k * sensed + d;
}

double GyroSimulator::injectedBias(double t) const {
  const HarmonicModel& d = config_.thermal.enabled ? thermal_d_ : config_.resonator.drift;
  const double d0 = d.meanAt(config_.resonator.frequency);
  return (dynamics_ ? d0 + shell_bias_ : d0) + config_.resonator.bias_drift.trendAt(t) + bias_walk_;
}

void GyroSimulator::stamp(double t_center, SimulationSample* out) const {
  out->stamp = toNanoseconds(config_.start_time + t_center);
}

void GyroSimulator::advanceTime(double h) {
  // Kahan summation keeps 24 h of 200 us steps exact to the nanosecond.
  const double y = h - t_compensation_;
  const double sum_t = t_ + y;
  t_compensation_ = (sum_t - t_) - y;
  t_ = sum_t;
}

double GyroSimulator::closeWindow(const ChannelVector& sum, int m, double t_start, SimulationSample* out) const {
  out->z = sum / m;
  out->frequency = frequency_;
  out->temperature = temperature_;
  out->periods = static_cast<std::uint32_t>(m);
  const double t_center = 0.5 * (t_start + t_);
  stamp(t_center, out);
  return t_center;
}

void GyroSimulator::setTruthWave(double amplitude, double quadrature, double phase, double t_center, bool generator,
                                 TruthState* truth) const {
  truth->amplitude = amplitude;
  truth->quadrature = quadrature;
  truth->phase = phase;
  truth->frequency = frequency_;
  truth->temperature = temperature_;
  truth->bias = injectedBias(t_center);
  truth->generator = generator;
}

bool GyroSimulator::next(SimulationSample* out) {
  if (done()) return false;
  const double t_start = t_;
  if (config_.generator.enabled && t_ < generatorDuration() - 1e-9) {
    nextGenerator(out);
  } else {
    nextDynamic(out);
  }
  out->index = index_++;
  const double walk = config_.resonator.bias_drift.random_walk;
  // The Wiener increment over the window just simulated, held over the next one.
  if (walk > 0.0) bias_walk_ += walk * std::sqrt(t_ - t_start) * bias_walk_draws_.next();
  return true;
}

void GyroSimulator::integrateInputAngle(double h, double rate_start, double rate_middle, double rate_end) {
  // Kahan-compensated like the time: hours of small increments stay exact to the last bits.
  const double y = h / 6 * (rate_start + 4 * rate_middle + rate_end) - input_angle_compensation_;
  const double sum = input_angle_ + y;
  input_angle_compensation_ = (sum - input_angle_) - y;
  input_angle_ = sum;
}

void GyroSimulator::setInputTruth(double t_lo, double angle_lo, double t_center, TruthState* truth) const {
  // The input's rate at the centre and its angle: Simpson from the period boundary before it.
  truth->inertial_rate = input_->rateAt(t_center);
  truth->inertial_angle = angle_lo;
  if (t_center > t_lo) {
    truth->inertial_angle +=
        (t_center - t_lo) / 6 *
        (input_->rateAt(t_lo) + 4 * input_->rateAt(0.5 * (t_lo + t_center)) + truth->inertial_rate);
  }
}

void GyroSimulator::nextDynamic(SimulationSample* out) {
  if (dynamics_) {
    nextResonator(out);
    return;
  }
  const ResonatorConfig& rc = config_.resonator;
  const int m = rc.periods_per_output;
  const double period = 1.0 / rc.frequency;
  std::vector<double> boundary_theta(m + 1), boundary_input_angle(m + 1);
  boundary_theta[0] = theta_;
  boundary_input_angle[0] = input_angle_;
  const double t_start = t_;
  if (config_.thermal.enabled) updateTemperature(t_start + 0.5 * m * period);
  ChannelVector sum = ChannelVector::Zero();
  WaveParameters wave{amplitude_, rc.quadrature, theta_, rc.phase};
  for (int p = 0; p < m; ++p) {
    // RK4 over one period: the rate changes by < 1e-5 relative within it.
    const double h = period, t = t_;
    // The sensed rate depends on time only: one evaluation per stage time.
    const double sensed0 = sensedRate(t), sensed_mid = sensedRate(t + h / 2), sensed1 = sensedRate(t + h);
    const double k1 = thetaRate(t, theta_, sensed0);
    const double k2 = thetaRate(t + h / 2, theta_ + h / 2 * k1, sensed_mid);
    const double k3 = thetaRate(t + h / 2, theta_ + h / 2 * k2, sensed_mid);
    const double k4 = thetaRate(t + h, theta_ + h * k3, sensed1);
    double theta_end = theta_ + h / 6 * (k1 + 2 * k2 + 2 * k3 + k4);
    // The input's angle by Simpson's rule on the same stages (RK4 of a function of time alone).
    if (input_) integrateInputAngle(h, sensed0, sensed_mid, sensed1);
    if (rc.rate_noise > 0.0) {
      // A white body-rate noise, seen through the scale factor like any rotation.
      double k, d;
      intrinsic_.evaluate(theta_, rc.frequency, &k, &d);
      theta_end += k * rc.rate_noise * std::sqrt(h) * rate_noise_.next();
    }
    wave.theta = theta_;
    sum += synth_.period(wave, theta_end);
    theta_ = theta_end;
    boundary_theta[p + 1] = theta_;
    boundary_input_angle[p + 1] = input_angle_;
    advanceTime(h);
  }
  const double t_center = closeWindow(sum, m, t_start, out);
  // Truth at the window centre, theta interpolated between the period boundaries around it.
  const double pos = 0.5 * m;
  const int lo = std::min(static_cast<int>(pos), m - 1);
  const double frac = pos - lo;
  TruthState& truth = out->truth;
  truth.theta = boundary_theta[lo] + frac * (boundary_theta[lo + 1] - boundary_theta[lo]);
  config_.profile.evaluate(t_center - generatorDuration(), &truth.table_angle, &truth.table_rate, &truth.segment);
  if (input_) {
    setInputTruth(t_start + lo * period, boundary_input_angle[lo], t_center, &truth);
  } else {
    truth.inertial_rate = truth.table_rate + earth_rate_;
    truth.inertial_angle = truth.table_angle + earth_rate_ * t_center;
  }
  setTruthWave(amplitude_, rc.quadrature, rc.phase, t_center, false, &truth);
  logTurntable(t_center, out);
}

void GyroSimulator::nextResonator(SimulationSample* out) {
  const ResonatorConfig& rc = config_.resonator;
  const int m = rc.periods_per_output;
  const double period = 1.0 / rc.frequency;
  double boundary_theta[2] = {0.0, 0.0}, boundary_psi[2] = {0.0, 0.0}, input_angle_lo = 0.0;
  const int lo = std::min(m / 2, m - 1);  // the period holding the window's centre
  const double frac = 0.5 * m - lo;
  const double t_start = t_;
  out->precession_commands.clear();
  ChannelVector sum = ChannelVector::Zero();
  ResonatorInputs in;
  for (int p = 0; p < m; ++p) {
    applyPrecessionCommands(out);
    const double h = period, t = t_, input_angle_before = input_angle_;
    in.body_rate_start = sensedRate(t);
    in.body_rate_end = sensedRate(t + h);
    if (input_) integrateInputAngle(h, in.body_rate_start, input_->rateAt(t + 0.5 * h), in.body_rate_end);
    if (rc.rate_noise > 0.0) {
      // A white body-rate noise held over the period: the angle random walk of the harmonic path.
      const double noise = rc.rate_noise / std::sqrt(h) * rate_noise_.next();
      in.body_rate_start += noise;
      in.body_rate_end += noise;
    }
    in.virtual_rate = virtual_rate_;
    const BiasDriftConfig& drift = rc.bias_drift;
    const double added = rc.drift.orders().empty() ? rc.drift.meanAt(rc.frequency) : rc.drift(theta_, rc.frequency);
    in.angle_rate = added + (drift.enabled() ? drift.trendAt(t + 0.5 * h) + bias_walk_ : 0.0);
    const WaveParameters start = dynamics_->wave();
    if (!dynamics_->step(h, in)) throw std::runtime_error("resonator: the wave stopped standing (A^2 <= B^2)");
    const double theta_end = dynamics_->wave().theta;
    sum += synth_.period(start, theta_end);
    if (p == lo) {
      input_angle_lo = input_angle_before;
      boundary_theta[0] = theta_, boundary_psi[0] = virtual_angle_;
      boundary_theta[1] = theta_end, boundary_psi[1] = virtual_angle_ + virtual_rate_ * h;
    }
    theta_ = theta_end;
    virtual_angle_ += virtual_rate_ * h;
    advanceTime(h);
  }
  const WaveParameters& wave = dynamics_->wave();
  frequency_ = dynamics_->referenceFrequency();
  const double t_center = closeWindow(sum, m, t_start, out);
  TruthState& truth = out->truth;
  truth.theta = boundary_theta[0] + frac * (boundary_theta[1] - boundary_theta[0]);
  config_.profile.evaluate(t_center - generatorDuration(), &truth.table_angle, &truth.table_rate, &truth.segment);
  if (input_) {
    setInputTruth(t_start + lo * period, input_angle_lo, t_center, &truth);
  } else {
    truth.inertial_rate = truth.table_rate + earth_rate_;
    truth.inertial_angle = truth.table_angle + earth_rate_ * t_center;
  }
  setTruthWave(wave.amplitude, wave.quadrature, wave.phase, t_center, false, &truth);
  out->precession.rate = virtual_rate_;
  out->precession.angle = boundary_psi[0] + frac * (boundary_psi[1] - boundary_psi[0]);
  out->precession.commands = precession_commands_;
  logTurntable(t_center, out);
}

void GyroSimulator::nextGenerator(SimulationSample* out) {
  const GeneratorConfig& g = config_.generator;
  const ResonatorConfig& rc = config_.resonator;
  const std::uint64_t per_state = generatorOutputsPerState();
  // State order: phase fastest, then quadrature, then angle.
  const std::uint64_t np = g.phases.size(), nq = g.quadratures.size();
  const std::uint64_t s = generator_state_;
  if (config_.thermal.enabled) updateTemperature((index_ + 0.5) * config_.outputPeriod());
  WaveParameters wave;
  wave.amplitude = amplitude_;
  wave.phase = g.phases[s % np];
  wave.quadrature = g.quadratures[(s / np) % nq];
  wave.theta = kPi * static_cast<double>(s / (np * nq)) / g.angles;
  const int m = rc.periods_per_output;
  ChannelVector sum = ChannelVector::Zero();
  for (int p = 0; p < m; ++p) sum += synth_.period(wave, wave.theta);
  const double t_start = t_;
  t_ = (index_ + 1) * config_.outputPeriod();
  const double t_center = closeWindow(sum, m, t_start, out);
  TruthState& truth = out->truth;
  truth = TruthState();
  truth.theta = wave.theta;
  setTruthWave(wave.amplitude, wave.quadrature, wave.phase, t_center, true, &truth);
  truth.inertial_rate = earth_rate_;
  truth.inertial_angle = earth_rate_ * t_center;
  truth.segment = &generator_label_;
  logTurntable(t_center, out);
  if (++generator_outputs_in_state_ >= per_state) {
    generator_outputs_in_state_ = 0;
    ++generator_state_;
  }
}

}  // namespace core
}  // namespace hrg_gyro

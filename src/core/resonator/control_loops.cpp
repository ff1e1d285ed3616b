#include "hrg_gyro/core/resonator/control_loops.h"

#include <cmath>
#include <stdexcept>
#include <string>

#include "hrg_gyro/core/common/units.h"

namespace hrg_gyro {
namespace core {

void LoopSettings::validate() const {
  const auto require = [](bool ok, const char* field, const std::string& what) {
    if (!ok) throw std::invalid_argument(std::string("loops ") + field + ": " + what);
  };
  require(std::isfinite(control_rate) && control_rate > 0.0, "control_rate", "must be a positive number of Hz");
  require(std::isfinite(energy) && energy > 0.0, "energy", "must be positive");
  require(std::isfinite(phase), "phase", "must be finite");
  require(std::isfinite(damping_ratio) && damping_ratio > 0.0, "damping_ratio", "must be positive");
  const double fastest = 0.1 * control_rate;
  for (const auto& [name, value] : {std::pair<const char*, double>{"energy_bandwidth", energy_bandwidth},
                                    {"quadrature_bandwidth", quadrature_bandwidth},
                                    {"phase_bandwidth", phase_bandwidth}}) {
    require(std::isfinite(value) && value >= 0.0 && value <= fastest, name,
            "must lie in [0, control_rate / 10] Hz (0 opens the loop)");
  }
}

double LoopSettings::proportionalGain(double bandwidth) const { return 2.0 * damping_ratio * kTwoPi * bandwidth; }

double LoopSettings::integralGain(double bandwidth) const {
  const double wn = kTwoPi * bandwidth;
  return wn * wn;
}

ControlLoops::ControlLoops(const LoopSettings& settings) : settings_(settings) {
  settings_.validate();
  kp_energy_ = settings_.proportionalGain(settings_.energy_bandwidth);
  ki_energy_ = settings_.integralGain(settings_.energy_bandwidth);
  kp_quadrature_ = settings_.proportionalGain(settings_.quadrature_bandwidth);
  ki_quadrature_ = settings_.integralGain(settings_.quadrature_bandwidth);
  kp_phase_ = settings_.proportionalGain(settings_.phase_bandwidth);
  ki_phase_ = settings_.integralGain(settings_.phase_bandwidth);
}

LoopCommand ControlLoops::update(const WaveParameters& measured, double virtual_rate, double period) {
  const double a = measured.amplitude, b = measured.quadrature;
  LoopCommand command;
  // Energy: dE/dt = 2 A dA/dt + 2 B dB/dt, so a_v = c / (2A) makes the loop act on E directly.
  const double energy_error = a * a + b * b - settings_.energy;
  energy_integral_ += energy_error * period;
  command.force.antinode_velocity = -(kp_energy_ * energy_error + ki_energy_ * energy_integral_) / (2.0 * a);
  quadrature_integral_ += b * period;
  command.force.node_displacement = -(kp_quadrature_ * b + ki_quadrature_ * quadrature_integral_);
  // A linear phase detector over a whole turn: the error wrapped to [-pi, pi].
  const double phase_offset = measured.phase - settings_.phase;
  const double phase_error = phase_offset - kTwoPi * nearestWhole(phase_offset / kTwoPi);
  phase_integral_ += phase_error * period;
  command.reference_offset = kp_phase_ * phase_error + ki_phase_ * phase_integral_;
  command.force.node_velocity = virtual_rate * (a * a - b * b) / a;
  return command;
}

}  // namespace core
}  // namespace hrg_gyro

#include "hrg_gyro/core/evaluation/triad_pipeline.h"

namespace hrg_gyro {
namespace core {

OfflineTriadCalibration calibrateOnTriadSimulation(const TriadSimulationConfig& scenario,
                                                   const std::array<GyroParameters, 3>& priors,
                                                   const CalibrationSettings& axis_settings,
                                                   const TriadCalibrationSettings& triad_settings,
                                                   const TriadParameters& prior_triad,
                                                   const ProcessorConfig& processor) {
  TriadSimulator sim(scenario);
  std::array<std::unique_ptr<GyroProcessor>, 3> processors;
  for (int i = 0; i < 3; ++i)
    processors[i] = std::make_unique<GyroProcessor>(processor, std::make_shared<const GyroParameters>(priors[i]));
  TriadCalibration calibration(axis_settings, triad_settings, priors, prior_triad);
  TriadSample s;
  while (sim.next(&s)) {
    // In the order `hrg_bag simulate` writes them at the sample's stamp: the axes, the table, the fixture.
    for (int i = 0; i < 3; ++i) {
      const SimulationSample& a = s.axes[i];
      if (!a.channels_delivered) continue;
      const ProcessorResult r = processors[i]->process({a.stamp, a.z, a.frequency, a.temperature});
      if (r.has_wave) calibration.addWave(i, a.stamp, r.wave.theta, a.frequency);
    }
    for (const TurntableLogRecord& record : s.turntable)
      calibration.addTurntable(record.stamp, record.angle, record.rate, record.index);
    if (s.fixture_logged) {
      FixtureRecord record;
      record.stamp = s.stamp;
      record.index = s.fixture.index;
      record.name = s.fixture.name ? *s.fixture.name : std::string();
      record.body_to_table = s.fixture.body_to_table;
      record.locked = s.fixture.locked;
      calibration.addFixture(record);
    }
  }
  OfflineTriadCalibration out;
  out.outcome = calibration.finish();
  for (int i = 0; i < 3; ++i) out.processors[i] = processors[i]->counters();
  out.simulated_seconds = sim.duration();
  return out;
}

}  // namespace core
}  // namespace hrg_gyro

#include "hrg_gyro/core/evaluation/offline_pipeline.h"

#include "hrg_gyro/core/calibration/calibration_feed.h"

namespace hrg_gyro {
namespace core {

OfflineCalibration calibrateOnSimulation(const SimulationConfig& scenario,
                                         std::shared_ptr<const GyroParameters> parameters,
                                         const CalibrationSettings& calibration, const ProcessorConfig& processor) {
  GyroSimulator sim(scenario);
  GyroProcessor proc(processor, parameters);
  CalibrationSession session(calibration, *parameters);
  CalibrationFeed feed(&session, &proc);
  SimulationSample s;
  while (sim.next(&s)) {
    if (s.truth.generator) {
      if (s.channels_delivered)
        feed.addSweepSample(s.stamp, s.z, {s.truth.amplitude, s.truth.quadrature, s.truth.theta, s.truth.phase});
      continue;
    }
    // What the table controller logged, not the truth; or what the precession loop executed (the
    // feed takes the one the method synchronises with, as the live calibrator does).
    if (sim.hasPrecessionLoop()) feed.addPrecessionState(s.stamp, s.precession.angle, s.precession.rate, s.index);
    for (const TurntableLogRecord& record : s.turntable)
      feed.addTableState(record.stamp, record.angle, record.rate, record.index);
    if (s.channels_delivered)
      feed.addWaveChannels({s.stamp + s.channels_stamp_offset, s.z, s.frequency, s.temperature}, s.stamp);
  }
  OfflineCalibration out;
  out.outcome = session.finish();
  out.processor = proc.counters();
  out.session = session.counters();
  out.simulated_seconds = sim.elapsed();
  return out;
}

std::vector<EvaluationResult> verifyOnSimulation(const SimulationConfig& scenario,
                                                 const std::vector<std::shared_ptr<const GyroParameters>>& parameters,
                                                 const EvaluationSettings& evaluation,
                                                 const ProcessorConfig& processor) {
  GyroSimulator sim(scenario);
  std::vector<GyroProcessor> processors;
  std::vector<OutputEvaluator> evaluators;
  for (const auto& p : parameters) {
    processors.emplace_back(processor, p);
    evaluators.emplace_back(evaluation);
  }
  SimulationSample s;
  while (sim.next(&s)) {
    if (!s.channels_delivered) continue;
    for (std::size_t i = 0; i < processors.size(); ++i) {
      const ProcessorResult r =
          processors[i].process({s.stamp + s.channels_stamp_offset, s.z, s.frequency, s.temperature});
      if (!r.has_output) continue;
      evaluators[i].add(s.stamp, r.increment.theta_mid, r.alpha, s.truth.table_rate, s.truth.inertial_angle,
                        s.truth.inertial_rate);
    }
  }
  std::vector<EvaluationResult> results;
  for (const OutputEvaluator& e : evaluators) results.push_back(e.result());
  return results;
}

}  // namespace core
}  // namespace hrg_gyro

#include "hrg_gyro/core/evaluation/offline_pipeline.h"

#include "hrg_gyro/core/calibration/generator_pairing.h"

namespace hrg_gyro {
namespace core {

OfflineCalibration calibrateOnSimulation(const SimulationConfig& scenario,
                                         std::shared_ptr<const GyroParameters> parameters,
                                         const CalibrationSettings& calibration, const ProcessorConfig& processor) {
  GyroSimulator sim(scenario);
  GyroProcessor proc(processor, parameters);
  CalibrationSession session(calibration, *parameters);
  GeneratorPairing pairing([&session](Nanoseconds t, const ChannelVector& raw, const ChannelVector& reference) {
    session.addGeneratorPair(t, raw, reference);
  });
  // The field method synchronises with the precession loop's state, as the live calibrator does.
  const bool virtual_rotation = traitsOf(calibration.method).virtual_rotation;
  SimulationSample s;
  while (sim.next(&s)) {
    if (s.truth.generator) {
      if (!s.channels_delivered) continue;
      pairing.addRaw(s.stamp, s.z);
      pairing.addReference(s.stamp, {s.truth.amplitude, s.truth.quadrature, s.truth.theta, s.truth.phase});
      continue;
    }
    // What the table controller logged, not the truth; or what the precession loop executed.
    if (virtual_rotation) {
      if (sim.hasPrecessionLoop()) session.addRotationRecord(s.stamp, s.precession.angle, s.precession.rate, s.index);
    } else {
      for (const TurntableLogRecord& record : s.turntable)
        session.addRotationRecord(record.stamp, record.angle, record.rate, record.index);
    }
    if (!s.channels_delivered) continue;
    const ProcessorResult r = proc.process({s.stamp + s.channels_stamp_offset, s.z, s.frequency, s.temperature});
    if (r.has_wave)
      session.addWave(s.stamp, r.wave.theta, s.frequency, quadratureRatio(r.wave.quadrature, r.wave.amplitude));
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

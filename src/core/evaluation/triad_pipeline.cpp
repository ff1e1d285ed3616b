#include "hrg_gyro/core/evaluation/triad_pipeline.h"

#include <algorithm>
#include <cmath>
#include <memory>

#include "hrg_gyro/core/simulation/triad_motion.h"

namespace hrg_gyro {
namespace core {
namespace {

/// A simulated axis's channels as its driver sends them (a glitched stamp included).
ChannelSample channelSample(const SimulationSample& a) {
  return {a.stamp + a.channels_stamp_offset, a.z, a.frequency, a.temperature};
}

}  // namespace

OfflineTriadCalibration calibrateOnTriadSimulation(const TriadSimulationConfig& scenario,
                                                   const std::array<GyroParameters, 3>& priors,
                                                   const CalibrationSettings& axis_settings,
                                                   const TriadCalibrationSettings& triad_settings,
                                                   const TriadParameters& prior_triad,
                                                   const ProcessorConfig& processor) {
  TriadSimulator sim(scenario);
  TriadProcessor processors(processor, priors);
  TriadCalibration calibration(axis_settings, triad_settings, priors, prior_triad);
  TriadSample s;
  ProcessorResult r;
  while (sim.next(&s)) {
    // In the order `hrg_bag simulate` writes them at the sample's stamp: the axes, the table, the fixture.
    for (std::size_t i = 0; i < 3; ++i) {
      const SimulationSample& a = s.axes[i];
      if (!a.channels_delivered) continue;
      processors.process(i, channelSample(a), &r);
      if (r.has_wave) calibration.addWave(static_cast<int>(i), a.stamp, r.wave.theta, a.frequency);
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
  for (std::size_t i = 0; i < 3; ++i) out.processors[i] = processors.processor(i).counters();
  out.simulated_seconds = sim.duration();
  return out;
}

namespace {

/// One set of files on the simulated triad: its processing chain, its sums per segment.
struct VerifiedChain {
  std::unique_ptr<TriadProcessor> triad;
  std::vector<Eigen::Vector3d> published, exact;  // rad, summed increments per segment
  std::vector<double> seconds;
  std::vector<TriadBodySample> completed;
};

struct Window {
  double begin, end;  // s from the scenario start
};

/// The segments a verification judges: the table's constant-rate pieces (moves between positions
/// aside) longer than twice the margin, each with its window, the margin cut from both ends.
void verificationSegments(const TriadSimulationConfig& scenario, const TriadMotion& motion, double margin,
                          std::vector<TriadVerificationSegment>* segments, std::vector<Window>* windows) {
  for (const TurntableProfile::Piece& piece : scenario.table_profile.pieces()) {
    const bool move = piece.label.size() >= 5 && piece.label.compare(piece.label.size() - 5, 5, "/move") == 0;
    if (move || piece.accel != 0.0 || piece.duration <= 2.0 * margin) continue;
    TriadVerificationSegment segment;
    segment.label = piece.label;
    segment.table_rate = piece.rate0;
    segment.position = motion.stateAt(piece.start + 0.5 * piece.duration).position;
    segments->push_back(segment);
    windows->push_back({piece.start + margin, piece.start + piece.duration - margin});
  }
}

/// One chain's sums per segment as its verification: each segment's mean rate and error, the worst and
/// rms relative error where the table turned, the worst rest error where it did not.
TriadVerification summarise(const VerifiedChain& chain, const std::vector<TriadVerificationSegment>& segments) {
  TriadVerification v;
  v.combiner = chain.triad->combiner().counters();
  double sum_square = 0.0;
  int turning = 0;
  for (std::size_t k = 0; k < segments.size(); ++k) {
    if (!(chain.seconds[k] > 0.0)) continue;
    TriadVerificationSegment segment = segments[k];
    segment.seconds = chain.seconds[k];
    segment.mean_rate = chain.exact[k] / chain.seconds[k];
    segment.mean_error = (chain.published[k] - chain.exact[k]) / chain.seconds[k];
    if (segment.turning()) {
      const double ppm = segment.relativeErrorPpm();
      v.worst_turning_ppm = std::max(v.worst_turning_ppm, ppm);
      sum_square += ppm * ppm;
      ++turning;
    } else {
      v.worst_rest_error = std::max(v.worst_rest_error, segment.mean_error.norm());
    }
    v.segments.push_back(segment);
  }
  if (turning > 0) v.rms_turning_ppm = std::sqrt(sum_square / turning);
  return v;
}

}  // namespace

std::vector<TriadVerification> verifyTriadOnSimulation(const TriadSimulationConfig& scenario,
                                                       const std::vector<TriadCalibrationFiles>& files,
                                                       const ProcessorConfig& processor, double margin) {
  const TriadMotion motion(scenario);
  std::vector<TriadVerificationSegment> segments;
  std::vector<Window> windows;
  verificationSegments(scenario, motion, margin, &segments, &windows);

  std::vector<VerifiedChain> chains(files.size());
  for (std::size_t c = 0; c < files.size(); ++c) {
    TriadProcessorSettings settings;
    settings.processor = processor;
    chains[c].triad = std::make_unique<TriadProcessor>(settings, files[c].axes,
                                                       std::make_shared<const TriadParameters>(files[c].triad));
    chains[c].published.assign(segments.size(), Eigen::Vector3d::Zero());
    chains[c].exact.assign(segments.size(), Eigen::Vector3d::Zero());
    chains[c].seconds.assign(segments.size(), 0.0);
  }

  // A combined sample belongs to the segment whose window holds its whole interval.
  std::size_t cursor = 0;
  auto accumulate = [&](VerifiedChain* chain) {
    for (const TriadBodySample& b : chain->completed) {
      if (!b.integrated()) continue;
      const double t_end = 1e-9 * static_cast<double>(b.stamp) - scenario.start_time;
      const double t_begin = t_end - b.dt;
      std::size_t k = cursor;
      while (k < windows.size() && windows[k].end < t_end) ++k;
      if (k == windows.size() || t_begin < windows[k].begin) continue;
      chain->published[k] += b.delta_angle;
      chain->exact[k] += motion.angularVelocityAt(t_end - 0.5 * b.dt) * b.dt;
      chain->seconds[k] += b.dt;
    }
    chain->completed.clear();
  };

  TriadSimulator sim(scenario);
  TriadSample s;
  ProcessorResult r;
  while (sim.next(&s)) {
    const double t = 1e-9 * static_cast<double>(s.stamp) - scenario.start_time;
    while (cursor < windows.size() && windows[cursor].end < t - 1.0) ++cursor;  // samples arrive within 1 s
    for (VerifiedChain& chain : chains) {
      for (std::size_t i = 0; i < 3; ++i) {
        const SimulationSample& a = s.axes[i];
        if (!a.channels_delivered) continue;
        chain.triad->process(i, channelSample(a), &r);
        chain.triad->release(nullptr, &chain.completed);
      }
      accumulate(&chain);
    }
  }

  std::vector<TriadVerification> results(files.size());
  for (std::size_t c = 0; c < files.size(); ++c) {
    VerifiedChain& chain = chains[c];
    cursor = 0;
    chain.triad->finish(nullptr, &chain.completed);
    accumulate(&chain);
    results[c] = summarise(chain, segments);
    results[c].name = files[c].name;
  }
  return results;
}

}  // namespace core
}  // namespace hrg_gyro

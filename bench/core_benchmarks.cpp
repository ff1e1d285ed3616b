// Google Benchmark suites of the ROS-free core: the per-sample pipeline and its parts, the fits,
// and the simulator's real-time factor. `make bench` runs them (Release build) and writes JSON.
#include <benchmark/benchmark.h>
#include <unistd.h>

#include <array>
#include <cmath>
#include <memory>
#include <string>
#include <vector>

#include "hrg_gyro/core/common/units.h"
#include "hrg_gyro/core/estimation/harmonic_fit.h"
#include "hrg_gyro/core/model/correction_matrix.h"
#include "hrg_gyro/core/model/wave_parameters.h"
#include "hrg_gyro/core/processing/compensator.h"
#include "hrg_gyro/core/processing/gyro_processor.h"
#include "hrg_gyro/core/processing/triad_combiner.h"
#include "hrg_gyro/core/processing/triad_variance_pairing.h"
#include "hrg_gyro/core/resonator/resonator_dynamics.h"
#include "hrg_gyro/core/signal/synchronous_demodulator.h"
#include "hrg_gyro/core/signal/wave_estimator.h"
#include "hrg_gyro/core/simulation/gaussian_noise.h"
#include "hrg_gyro/core/simulation/gyro_simulator.h"
#include "hrg_gyro/core/simulation/simulation_config.h"

namespace hrg_gyro {
namespace core {
namespace {

// A model of `orders` K harmonics (2, 4, ...) and two D harmonics; frequency dependent over three
// nodes when asked (the paper's K(theta, f)).
std::shared_ptr<const GyroParameters> parametersWith(int harmonics, bool frequency_dependent) {
  auto p = std::make_shared<GyroParameters>();
  std::vector<int> orders;
  std::vector<double> cos, sin;
  for (int k = 1; k <= harmonics; ++k) {
    orders.push_back(2 * k);
    cos.push_back(1e-4 / k);
    sin.push_back(-0.5e-4 / k);
  }
  if (frequency_dependent) {
    Eigen::MatrixXd nodes(1 + 2 * orders.size(), 3);
    for (int j = 0; j < 3; ++j) {
      nodes(0, j) = -0.56 * (1.0 + 1e-4 * j);
      for (std::size_t i = 0; i < orders.size(); ++i) {
        nodes(1 + i, j) = cos[i] * (1.0 + 0.1 * j);
        nodes(1 + orders.size() + i, j) = sin[i] * (1.0 - 0.1 * j);
      }
    }
    p->scale_factor = HarmonicModel(orders, FrequencyInterpolator({4990.0, 5000.0, 5010.0}), nodes);
  } else {
    p->scale_factor = HarmonicModel(orders, -0.56, cos, sin);
  }
  p->drift = HarmonicModel({2, 4}, 1e-5, {2e-5, 1e-6}, {-1e-5, 0.0});
  return p;
}

// Channel amplitudes of a wave turning at 0.5 rad/s electrical, 1 kHz, 4096 samples (cycled).
std::vector<ChannelSample> channelStream(std::size_t n = 4096) {
  std::vector<ChannelSample> s(n);
  for (std::size_t i = 0; i < n; ++i) {
    s[i].stamp = static_cast<Nanoseconds>(i + 1) * 1000000;
    s[i].z = idealChannels({1.0, 0.02, 0.5e-3 * static_cast<double>(i), 0.3});
    s[i].frequency = 5000.0;
  }
  return s;
}

void BM_Demodulation(benchmark::State& state) {
  const int n = static_cast<int>(state.range(0));
  SynchronousDemodulator d(n);
  std::vector<double> c(n), s(n);
  GaussianNoise g(1);
  for (int j = 0; j < n; ++j) {
    c[j] = g.next();
    s[j] = g.next();
  }
  for (auto _ : state) benchmark::DoNotOptimize(d.demodulate(c.data(), s.data()));
  state.SetItemsProcessed(state.iterations());
  state.SetLabel("per period of " + std::to_string(n) + " samples");
}
BENCHMARK(BM_Demodulation)->Arg(8)->Arg(32)->Arg(128);

void BM_WaveState(benchmark::State& state) {
  const std::vector<ChannelSample> in = channelStream();
  WaveLimits limits;
  WaveState w;
  std::size_t i = 0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(estimateWave(in[i].z, limits, &w));
    benchmark::DoNotOptimize(w);  // estimateWave is inline: keep every field it computes
    i = (i + 1) & 4095;
  }
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_WaveState);

// The per-sample form: cos/sin of both angles come with the wave state, no trigonometry here.
void BM_CompensationStep(benchmark::State& state) {
  Compensator c(parametersWith(static_cast<int>(state.range(0)), state.range(1) != 0));
  std::vector<double> cs(8192);
  for (std::size_t i = 0; i < 4096; ++i) {
    cs[2 * i] = std::cos(0.1 + 5e-4 * i);
    cs[2 * i + 1] = std::sin(0.1 + 5e-4 * i);
  }
  double sum = 0.0;
  std::size_t i = 0;
  for (auto _ : state) {
    const double theta = 0.1 + 5e-4 * i;
    const AngleIncrement inc =
        c.step(theta, theta + 5e-4, 1e-3, 5000.0 + theta, cs[2 * i], cs[2 * i + 1], cs[2 * i + 2], cs[2 * i + 3]);
    if (++i == 4095) i = 0;
    sum += inc.dalpha;
  }
  benchmark::DoNotOptimize(sum);
  state.SetItemsProcessed(state.iterations());
  state.SetLabel(std::to_string(state.range(0)) + " K harmonics" + (state.range(1) ? ", K(theta, f)" : ""));
}
BENCHMARK(BM_CompensationStep)->Args({0, 0})->Args({4, 0})->Args({8, 0})->Args({4, 1})->Args({8, 1});

// The angle-only form (one sincos of theta_mid per call): tools and tests use it.
void BM_CompensationStepFromAngle(benchmark::State& state) {
  Compensator c(parametersWith(static_cast<int>(state.range(0)), false));
  double theta = 0.1, sum = 0.0;
  for (auto _ : state) {
    sum += c.step(theta, theta + 5e-4, 1e-3, 5000.0).dalpha;
    theta += 5e-4;
  }
  benchmark::DoNotOptimize(sum);
  state.SetItemsProcessed(state.iterations());
  state.SetLabel(std::to_string(state.range(0)) + " K harmonics");
}
BENCHMARK(BM_CompensationStepFromAngle)->Arg(4);

// The target figure: Z -> (E - P)Z -> theta -> K, D -> dalpha, everything the processor does per sample.
void BM_ProcessSample(benchmark::State& state) {
  GyroProcessor p(ProcessorConfig(), parametersWith(static_cast<int>(state.range(0)), state.range(1) != 0));
  std::vector<ChannelSample> in = channelStream();
  const Nanoseconds period = static_cast<Nanoseconds>(in.size()) * 1000000;
  std::size_t i = 0;
  Nanoseconds offset = 0;
  double sum = 0.0;
  for (auto _ : state) {
    ChannelSample s = in[i];
    s.stamp += offset;
    sum += p.process(s).increment.dalpha;
    if (++i == in.size()) {
      i = 0;
      offset += period;  // keep time moving forward; the wave angle jumps back to the start once
    }
  }
  benchmark::DoNotOptimize(sum);
  state.SetItemsProcessed(state.iterations());
  state.SetLabel(std::to_string(state.range(0)) + " K harmonics" + (state.range(1) ? ", K(theta, f)" : ""));
}
BENCHMARK(BM_ProcessSample)->Args({0, 0})->Args({4, 0})->Args({8, 0})->Args({4, 1});

// The batch entry point over queued runs of 256 samples (what `hrg_bag process` and a draining node
// do), the same stream and model as BM_ProcessSample; time per sample.
void BM_ProcessBatch(benchmark::State& state) {
  GyroProcessor p(ProcessorConfig(), parametersWith(static_cast<int>(state.range(0)), state.range(1) != 0));
  std::vector<ChannelSample> in = channelStream();
  std::vector<ProcessorResult> out(256);
  const Nanoseconds period = static_cast<Nanoseconds>(in.size()) * 1000000;
  std::size_t i = 0;
  double sum = 0.0;
  for (auto _ : state) {
    p.processBatch(in.data() + i, out.size(), out.data());
    sum += out.back().increment.dalpha;
    i += out.size();
    if (i == in.size()) {
      i = 0;
      for (ChannelSample& s : in) s.stamp += period;  // time moves forward (outside the hot loop, 1 in 16)
    }
  }
  benchmark::DoNotOptimize(sum);
  state.SetItemsProcessed(state.iterations() * static_cast<std::int64_t>(out.size()));
  state.SetLabel(std::to_string(state.range(0)) + " K harmonics" + (state.range(1) ? ", K(theta, f)" : "") +
                 ", batches of 256");
}
BENCHMARK(BM_ProcessBatch)->Args({4, 0})->Args({4, 1});

// The triad's step beyond the three axes' processing: three axis outputs of one stamp in (each with
// its variance), one body-frame sample out (M dalpha - bias dt, the rate, M diag(sigma^2) M^T), 10 kHz
// stamps. A misaligned M, so no product is trivial; time per triad sample.
std::shared_ptr<const TriadParameters> benchTriad() {
  auto triad = std::make_shared<TriadParameters>();
  triad->axis_to_body << 1.0004, -3e-3, 1.2e-3, 4e-3, 0.9993, -2e-3, -1e-3, 2.5e-3, 1.0002;
  triad->bias << 2e-4, -1e-4, 5e-5;
  return triad;
}

std::vector<std::array<AxisOutput, 3>> triadStream() {
  std::vector<std::array<AxisOutput, 3>> stream(4096);
  for (std::size_t i = 0; i < stream.size(); ++i) {
    for (std::size_t a = 0; a < 3; ++a) {
      AxisOutput& o = stream[i][a];
      o.stamp = static_cast<Nanoseconds>(i + 1) * 100000;
      o.dt = 1e-4;
      o.dalpha = 1e-5 * (1.0 + 0.1 * static_cast<double>(a)) + 1e-9 * static_cast<double>(i % 7);
      o.rate_variance = 6e-6 * (1.0 + 1e-3 * static_cast<double>(i % 11));
    }
  }
  return stream;
}

void BM_TriadStep(benchmark::State& state) {
  TriadCombiner combiner(TriadCombinerSettings(), benchTriad());
  std::vector<std::array<AxisOutput, 3>> stream = triadStream();
  const Nanoseconds period = static_cast<Nanoseconds>(stream.size()) * 100000;
  std::vector<TriadBodySample> out;
  out.reserve(8);
  const std::array<AxisOutput, 3>* next = stream.data();
  const std::array<AxisOutput, 3>* const end = next + stream.size();
  double sum = 0.0;
  for (auto _ : state) {
    out.clear();
    combiner.add(0, (*next)[0], &out);
    combiner.add(1, (*next)[1], &out);
    combiner.add(2, (*next)[2], &out);
    sum += out[0].angular_velocity.x();
    if (++next == end) {
      next = stream.data();
      for (auto& stamp : stream) {
        for (AxisOutput& o : stamp) o.stamp += period;  // time moves forward (1 in 4096)
      }
    }
  }
  benchmark::DoNotOptimize(sum);
  state.SetItemsProcessed(state.iterations());
  state.SetLabel("per triad sample: 3 axis outputs in, 1 body-frame sample out");
}
BENCHMARK(BM_TriadStep);

// The triad node's path: each output first paired with its variance from the axis's Imu topic.
void BM_TriadStepPaired(benchmark::State& state) {
  TriadCombiner combiner(TriadCombinerSettings(), benchTriad());
  std::array<TriadVariancePairing, 3> pairings;
  std::vector<std::array<AxisOutput, 3>> stream = triadStream();
  const Nanoseconds period = static_cast<Nanoseconds>(stream.size()) * 100000;
  std::vector<TriadBodySample> out;
  out.reserve(8);
  std::vector<AxisOutput> ready;
  ready.reserve(8);
  std::size_t i = 0;
  double sum = 0.0;
  for (auto _ : state) {
    out.clear();
    for (std::size_t a = 0; a < 3; ++a) {
      const AxisOutput& o = stream[i][a];
      ready.clear();
      pairings[a].addOutput(o, &ready);
      pairings[a].addVariance(o.stamp, o.rate_variance, &ready);
      for (const AxisOutput& r : ready) combiner.add(a, r, &out);
    }
    sum += out[0].angular_velocity.x();
    if (++i == stream.size()) {
      i = 0;
      for (auto& stamp : stream) {
        for (AxisOutput& o : stamp) o.stamp += period;
      }
    }
  }
  benchmark::DoNotOptimize(sum);
  state.SetItemsProcessed(state.iterations());
  state.SetLabel("per triad sample, each output paired with its variance first (the node's path)");
}
BENCHMARK(BM_TriadStepPaired);

void BM_HarmonicFit(benchmark::State& state) {
  const int bins = static_cast<int>(state.range(0));
  std::vector<FitPoint> points(bins);
  GaussianNoise g(2);
  for (int b = 0; b < bins; ++b) {
    points[b].theta = M_PI * (b + 0.5) / bins;
    points[b].value = -0.56 + 1e-4 * std::cos(2 * points[b].theta) + 1e-6 * g.next();
    points[b].span = M_PI / bins;
  }
  for (auto _ : state) benchmark::DoNotOptimize(fitHarmonics(points, {2, 4, 6, 8}));
  state.SetLabel(std::to_string(bins) + " bins, orders 2,4,6,8");
}
BENCHMARK(BM_HarmonicFit)->Arg(128)->Arg(1024);

void BM_CorrectionMatrixFit(benchmark::State& state) {
  const int pairs = static_cast<int>(state.range(0));
  std::vector<ChannelVector> measured, reference;
  for (int i = 0; i < pairs; ++i) {
    const ChannelVector z = idealChannels({1.0, 0.02 * (i % 3), 0.1 * i, 0.3});
    reference.push_back(z);
    measured.push_back(z + 1e-3 * ChannelVector(z[1], -z[0], z[3], z[2]));
  }
  for (auto _ : state) {
    CorrectionMatrixEstimator e;
    for (int i = 0; i < pairs; ++i) e.add(measured[i], reference[i]);
    benchmark::DoNotOptimize(e.solve());
  }
  state.SetLabel(std::to_string(pairs) + " generator pairs");
}
BENCHMARK(BM_CorrectionMatrixFit)->Arg(24)->Arg(1000);

// The shipped scenario: beside an installed benchmark (lib/hrg_gyro -> share/hrg_gyro/config), else
// in the source tree it was built from.
std::string scenarioPath(const std::string& name) {
  char self[4096];
  const ssize_t n = ::readlink("/proc/self/exe", self, sizeof self - 1);
  if (n > 0) {
    std::string dir(self, static_cast<std::size_t>(n));
    dir.erase(dir.find_last_of('/'));
    const std::string installed = dir + "/../../share/hrg_gyro/config/scenarios/" + name;
    if (::access(installed.c_str(), R_OK) == 0) return installed;
  }
  return std::string(HRG_GYRO_SOURCE_DIR) + "/config/scenarios/" + name;
}

// Real-time factor of the signal-level simulator: simulated seconds per wall second (counter rtf).
void BM_SimulatorRealTimeFactor(benchmark::State& state) {
  SimulationConfig config = SimulationConfig::load(scenarioPath("dual_rate.yaml"), nodeOnlyScenarioKeys());
  config.resonator.frequency = 5000.0;
  config.resonator.samples_per_period = 32;
  config.resonator.periods_per_output = static_cast<int>(state.range(0));  // 5: 1 kHz output
  GyroSimulator sim(config);
  SimulationSample s;
  double simulated = 0.0;
  for (auto _ : state) {
    const double before = sim.elapsed();
    for (int k = 0; k < 200; ++k) {
      if (!sim.next(&s)) state.SkipWithError("scenario ended");
    }
    simulated += sim.elapsed() - before;
  }
  state.counters["rtf"] = benchmark::Counter(simulated, benchmark::Counter::kIsRate);
  state.SetItemsProcessed(200 * state.iterations());
  state.SetLabel("5 kHz, 32 samples/period, 8 defective sensors, " + std::to_string(5000 / state.range(0)) +
                 " Hz output");
}
BENCHMARK(BM_SimulatorRealTimeFactor)->Arg(5)->Arg(25)->Unit(benchmark::kMillisecond);

// The resonator from its equations of motion (core/resonator) with every loop closed: energy,
// quadrature, phase, and precession at a commanded 0.5 rad/s, the loops updated once per carrier
// period (5 kHz), on a shell and drive with every defect (Q 9.4e6, damping anisotropy 4e-5 1/s,
// 5 mHz split, forcers 2e-3 and -1e-3 off, 1 mrad lag, precession scale 3e-3) turning at 0.05 rad/s.
// One step is one output sample of `periods` carrier periods: 5 is the simulator's 1 kHz output, 25
// its 200 Hz. Counter rtf: simulated seconds per wall second.
void BM_ResonatorStep(benchmark::State& state) {
  ShellParameters shell;
  shell.frequency = 5000.0;
  shell.damping_time = 600.0;
  shell.damping_anisotropy = 4e-5;
  shell.damping_axis = 0.4;
  shell.frequency_split = 2.0 * kPi * 5e-3;
  shell.frequency_axis = -0.7;
  DriveChainErrors drive;
  drive.gain_error_c = 2e-3;
  drive.gain_error_s = -1e-3;
  drive.phase_error = 1e-3;
  drive.virtual_rate_gain_error = 3e-3;
  ResonatorDynamics dynamics(shell, LoopSettings(), drive, {1.0, 0.0, 0.3, 0.3});
  const double dt = static_cast<double>(state.range(0)) / shell.frequency;
  ResonatorInputs in;
  in.body_rate_start = in.body_rate_end = 0.05;
  in.virtual_rate = 0.5;
  constexpr int kSteps = 1000;
  double simulated = 0.0;
  for (auto _ : state) {
    for (int k = 0; k < kSteps; ++k) {
      if (!dynamics.step(dt, in)) state.SkipWithError("the wave stopped standing");
    }
    benchmark::DoNotOptimize(dynamics.wave());
    simulated += kSteps * dt;
  }
  state.counters["rtf"] = benchmark::Counter(simulated, benchmark::Counter::kIsRate);
  state.SetItemsProcessed(kSteps * state.iterations());
  state.SetLabel("all loops closed, every defect, " + std::to_string(5000 / state.range(0)) +
                 " Hz output, loops at 5 kHz");
}
BENCHMARK(BM_ResonatorStep)->Arg(5)->Arg(25)->Arg(1);

// The whole signal-level simulator on the averaged resonator with its loops (the shipped
// resonator_dual_rate.yaml: every shell and drive defect, 8 defective sensors, 32 samples per period),
// the wave precessed at a commanded 0.5 rad/s on a still table as in a field calibration. Counter rtf:
// simulated seconds per wall second (the target is 100x).
void BM_SimulatorWithLoopsRealTimeFactor(benchmark::State& state) {
  SimulationConfig config = SimulationConfig::load(scenarioPath("resonator_dual_rate.yaml"), nodeOnlyScenarioKeys());
  config.resonator.periods_per_output = static_cast<int>(state.range(0));  // 5: 1 kHz output
  config.profile = TurntableProfile();
  config.profile.append(1e6, 0.0, 0.0, "still");
  config.dynamics.commands = {{0.0, 0.5}};
  GyroSimulator sim(config);
  SimulationSample s;
  double simulated = 0.0;
  for (auto _ : state) {
    const double before = sim.elapsed();
    for (int k = 0; k < 200; ++k) {
      if (!sim.next(&s)) state.SkipWithError("scenario ended");
    }
    simulated += sim.elapsed() - before;
  }
  state.counters["rtf"] = benchmark::Counter(simulated, benchmark::Counter::kIsRate);
  state.SetItemsProcessed(200 * state.iterations());
  state.SetLabel("averaged resonator, loops at 5 kHz, 32 samples/period, 8 defective sensors, " +
                 std::to_string(5000 / state.range(0)) + " Hz output");
}
BENCHMARK(BM_SimulatorWithLoopsRealTimeFactor)->Arg(5)->Arg(25)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace core
}  // namespace hrg_gyro

BENCHMARK_MAIN();

// Fuzz target: the per-sample processing path (GyroProcessor, shared by the processor node, its
// nodelet and `hrg_bag process`) on arbitrary sequences of channel amplitudes, stamps and
// frequencies, with model swaps and resets in between. Invariants: no crash, no sanitizer report,
// every published number finite, the integrated angle equal to the sum of the increments since the
// last reset, and every sample accounted for by exactly one verdict.
//
// Input layout: byte 0 picks the starting model; then records, each a control byte and a payload.
// Raw records feed the bytes as doubles and stamps unchanged (NaN, Inf, denormals, garbage);
// "plausible" records build a valid wave and stamp step from a few bytes so that the fuzzer also
// reaches the integration, unwrapping, glitch and gap logic that garbage never gets past.
#include <cstring>
#include <memory>
#include <vector>

#include "fuzz_check.h"
#include "hrg_gyro/core/model/parameter_file.h"
#include "hrg_gyro/core/model/wave_parameters.h"
#include "hrg_gyro/core/processing/gyro_processor.h"

namespace hrg_gyro {
namespace fuzz {
namespace {

// Three models: nominal, with harmonics and P, and frequency dependent (spline over 3 nodes).
const char* const kModels[] = {
    "schema_version: 1\n"
    "scale_factor: {orders: [], mean: -0.56, cos: [], sin: []}\n"
    "drift: {orders: [], mean: 0.0, cos: [], sin: []}\n"
    "correction_matrix: {p: [0.0, 0.0, 0.0, 0.0]}\n"
    "earth_rate: {enabled: false, latitude: 0.0}\n",
    "schema_version: 1\n"
    "scale_factor: {orders: [2, 4, 6, 8], mean: -0.56, cos: [1.0e-3, -2.0e-4, 5.0e-5, 1.0e-6],"
    " sin: [-4.0e-4, 1.0e-4, 0.0, -2.0e-6]}\n"
    "drift: {orders: [2, 4], mean: 2.0e-5, cos: [1.0e-5, 0.0], sin: [0.0, -3.0e-6]}\n"
    "correction_matrix: {p: [1.0e-3, -2.0e-3, 5.0e-4, -3.0e-4]}\n"
    "earth_rate: {enabled: true, latitude: 0.9}\n",
    "schema_version: 1\n"
    "scale_factor: {orders: [2, 4], frequency_nodes: [4990.0, 5000.0, 5010.0],"
    " mean: [-0.5601, -0.56, -0.5599], cos: [[1.0e-3, 1.1e-3, 1.2e-3], [0.0, 1.0e-5, 2.0e-5]],"
    " sin: [[0.0, 0.0, 0.0], [-1.0e-4, -1.0e-4, -1.0e-4]]}\n"
    "drift: {orders: [2], frequency_nodes: [4990.0, 5010.0], interpolation: piecewise_linear,"
    " mean: [1.0e-5, 2.0e-5], cos: [[1.0e-5, 0.0]], sin: [[0.0, 1.0e-5]]}\n"
    "correction_matrix: {p: [0.0, 0.0, 0.0, 0.0]}\n"
    "earth_rate: {enabled: true, latitude: -0.3}\n",
};
constexpr std::size_t kModelCount = sizeof(kModels) / sizeof(kModels[0]);

std::shared_ptr<const core::GyroParameters> model(std::size_t index) {
  static const std::vector<std::shared_ptr<const core::GyroParameters>> models = [] {
    std::vector<std::shared_ptr<const core::GyroParameters>> m;
    for (const char* text : kModels)
      m.push_back(std::make_shared<core::GyroParameters>(core::parseParameterText(text)));
    return m;
  }();
  return models[index % kModelCount];
}

// Stamp arithmetic of the harness wraps like the unsigned it is made of (the processor must cope
// with any int64 stamp, but the harness itself must not overflow a signed integer).
std::int64_t shifted(std::int64_t stamp, std::int64_t delta) {
  return static_cast<std::int64_t>(static_cast<std::uint64_t>(stamp) + static_cast<std::uint64_t>(delta));
}

class Reader {
 public:
  Reader(const std::uint8_t* data, std::size_t size) : data_(data), size_(size) {}
  bool empty() const { return pos_ >= size_; }
  template <typename T>
  T take() {  // zero-filled past the end
    T value{};
    unsigned char bytes[sizeof(T)] = {};
    const std::size_t n = size_ - pos_ < sizeof(T) ? size_ - pos_ : sizeof(T);
    std::memcpy(bytes, data_ + pos_, n);
    pos_ += n;
    std::memcpy(&value, bytes, sizeof(T));
    return value;
  }

 private:
  const std::uint8_t* data_;
  std::size_t size_;
  std::size_t pos_ = 0;
};

void checkResult(const core::ProcessorResult& r) {
  if (r.has_wave) {
    const core::WaveState& w = r.wave;
    for (double v : {w.theta, w.amplitude, w.quadrature, w.phase, w.energy, w.quadrature_product, w.cos_component,
                     w.sin_component, w.phase_error, w.cos_theta, w.sin_theta}) {
      HRG_FUZZ_CHECK_FINITE(v);
    }
  }
  HRG_FUZZ_CHECK_FINITE(r.alpha);
  if (r.has_output) {
    const core::AngleIncrement& i = r.increment;
    for (double v : {i.dt, i.dtheta, i.theta_mid, i.scale_factor, i.drift, i.dalpha, i.dalpha_earth_fixed}) {
      HRG_FUZZ_CHECK_FINITE(v);
    }
    HRG_FUZZ_CHECK(i.dt > 0.0);
    HRG_FUZZ_CHECK(i.scale_factor < 0.0);
  }
}

}  // namespace

int sampleProcessingTarget(const std::uint8_t* data, std::size_t size) {
  Reader in(data, size);
  core::ProcessorConfig config;
  core::GyroProcessor processor(config, model(in.take<std::uint8_t>()));
  core::ChannelSample sample;
  sample.stamp = 1'000'000'000;
  sample.frequency = 5000.0;
  double theta = 0.3, alpha_sum = 0.0;
  std::uint64_t verdicts = 0;
  for (int records = 0; !in.empty() && records < 4096; ++records) {
    const std::uint8_t control = in.take<std::uint8_t>();
    switch (control % 5) {
      case 0:  // raw
        sample.stamp = in.take<std::int64_t>();
        for (int c = 0; c < 4; ++c) sample.z[c] = in.take<double>();
        sample.frequency = in.take<double>();
        break;
      case 1: {  // plausible wave, forward step of up to 65 ms, frequency near the nodes
        core::WaveParameters wave;
        theta += (in.take<std::int16_t>()) * 1e-4;
        wave.theta = theta;
        wave.amplitude = 0.05 + in.take<std::uint8_t>() / 64.0;
        wave.quadrature = wave.amplitude * (in.take<std::int8_t>() / 128.0);
        wave.phase = in.take<std::int8_t>() * 0.025;
        sample.z = core::idealChannels(wave);
        sample.stamp = shifted(sample.stamp, static_cast<std::int64_t>(in.take<std::uint16_t>()) * 1000);
        sample.frequency = 4980.0 + in.take<std::uint8_t>() * 0.2;
        break;
      }
      case 2: {  // perturb the last sample: sign flip, zero, scale, or a stamp change
        const std::uint8_t what = in.take<std::uint8_t>();
        const int channel = what & 3;
        switch ((what >> 2) % 6) {
          case 0:
            sample.z[channel] = -sample.z[channel];
            break;
          case 1:
            sample.z[channel] = 0.0;
            break;
          case 2:
            sample.z *= in.take<double>();
            break;
          case 3:
            sample.stamp = shifted(sample.stamp, -static_cast<std::int64_t>(in.take<std::uint32_t>()));
            break;
          case 4:
            sample.stamp = shifted(sample.stamp, static_cast<std::int64_t>(in.take<std::uint32_t>()) * 1000);
            break;
          default:
            sample.frequency = in.take<double>();
            break;
        }
        break;
      }
      case 3:  // a parameter reload between samples
        processor.setParameters(model(in.take<std::uint8_t>()));
        continue;
      default:  // reset (what a bag loop triggers in the node)
        processor.reset();
        alpha_sum = 0.0;
        continue;
    }
    const core::ProcessorResult r = processor.process(sample);
    ++verdicts;
    checkResult(r);
    if (r.verdict == core::SampleVerdict::kFirst) {  // after construction, reset() or a bag loop
      HRG_FUZZ_CHECK(r.alpha == 0.0);
      alpha_sum = 0.0;
    }
    if (r.has_output) {
      alpha_sum += r.increment.dalpha;  // the same additions in the same order: exactly equal
      HRG_FUZZ_CHECK(r.alpha == alpha_sum);
    }
  }
  const core::ProcessorCounters& c = processor.counters();
  HRG_FUZZ_CHECK(c.received == verdicts);
  HRG_FUZZ_CHECK(c.accepted + c.rejected() == c.received);
  return 0;
}

}  // namespace fuzz
}  // namespace hrg_gyro

#ifdef HRG_LIBFUZZER
extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  return hrg_gyro::fuzz::sampleProcessingTarget(data, size);
}
#endif

#include "hrg_gyro/core/processing/triad_processor.h"

#include <stdexcept>

namespace hrg_gyro {
namespace core {
namespace {

PrecessionWatchSettings watchSettings(const TriadProcessorSettings& settings) {
  PrecessionWatchSettings w;
  w.hold = settings.precession_hold;
  w.backward_reset = settings.processor.backward_reset;  // the stamps' rule, as for the channels
  return w;
}

}  // namespace

TriadProcessor::Axis::Axis(const TriadProcessorSettings& settings)
    : watch(watchSettings(settings)),
      noise(settings.noise),
      // release() follows every output: the watch decides before more than max_held wait.
      waiting(2 * watch.settings().max_held + 1) {}

TriadProcessor::TriadProcessor(const TriadProcessorSettings& settings, const std::array<GyroParameters, 3>& axes,
                               std::shared_ptr<const TriadParameters> triad)
    : settings_((settings.noise.validate(), settings)),
      axes_{{Axis(settings_), Axis(settings_), Axis(settings_)}},
      combiner_(std::make_unique<TriadCombiner>(settings_.combiner, std::move(triad))) {
  for (std::size_t a = 0; a < 3; ++a) {
    axes_[a].processor =
        std::make_unique<GyroProcessor>(settings_.processor, std::make_shared<const GyroParameters>(axes[a]));
  }
}

TriadProcessor::TriadProcessor(const ProcessorConfig& processor, const std::array<GyroParameters, 3>& axes)
    : settings_{processor}, axes_{{Axis(settings_), Axis(settings_), Axis(settings_)}} {
  for (std::size_t a = 0; a < 3; ++a) {
    axes_[a].processor = std::make_unique<GyroProcessor>(processor, std::make_shared<const GyroParameters>(axes[a]));
  }
}

TriadProcessor::~TriadProcessor() = default;

void TriadProcessor::process(std::size_t axis, const ChannelSample& sample, ProcessorResult* r) {
  if (axis >= 3) throw std::out_of_range("triad processor: axis index must be 0, 1 or 2");
  Axis& a = axes_[axis];
  a.processor->process(sample, r);
  if (!combiner_ || !r->has_wave) return;
  const Nanoseconds from = a.previous_accepted;
  a.previous_accepted = sample.stamp;
  if (!r->has_output) return;
  ++a.outputs;
  a.watch.addOutput(from, sample.stamp);
  a.waiting.push_back({sample.stamp, r->increment.dt, r->increment.dalpha, r->alpha, r->flags});
}

bool TriadProcessor::addPrecessionState(std::size_t axis, const PrecessionStateRecord& record) {
  if (axis >= 3) throw std::out_of_range("triad processor: axis index must be 0, 1 or 2");
  return axes_[axis].watch.addState(record);
}

void TriadProcessor::releaseAxis(std::size_t axis, std::vector<TriadAxisOutput>* outputs,
                                 std::vector<TriadBodySample>* completed) {
  Axis& a = axes_[axis];
  PrecessionDecision d;
  while (!a.waiting.empty() && a.watch.next(&d)) {
    const Waiting w = a.waiting.front();
    a.waiting.pop_front();
    AxisOutput out;
    out.stamp = w.stamp;
    out.dt = w.dt;
    out.dalpha = w.dalpha;
    out.flags = w.flags;
    if (d.flagged()) {
      out.flags |= kFlagPrecessing;
      ++a.precessed;
    }
    // As the processor node: its Imu's variance, and none with a gap or reset (no Imu then).
    a.noise.add(w.alpha, w.dt, out.flags);
    if (!(out.flags & (kFlagGap | kFlagReset))) {
      out.rate_variance = (out.flags & kFlagPrecessing) ? kUnmeasuredRateVariance : a.noise.variance();
    }
    if (outputs) outputs->push_back({axis, out});
    combiner_->add(axis, out, completed);
  }
}

void TriadProcessor::release(std::vector<TriadAxisOutput>* outputs, std::vector<TriadBodySample>* completed) {
  if (!combiner_) return;
  for (std::size_t axis = 0; axis < 3; ++axis) releaseAxis(axis, outputs, completed);
}

void TriadProcessor::finish(std::vector<TriadAxisOutput>* outputs, std::vector<TriadBodySample>* completed) {
  if (!combiner_) return;
  for (Axis& a : axes_) a.watch.finish();
  release(outputs, completed);
  combiner_->flush(completed);
}

}  // namespace core
}  // namespace hrg_gyro

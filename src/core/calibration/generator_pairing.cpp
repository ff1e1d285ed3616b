#include "hrg_gyro/core/calibration/generator_pairing.h"

#include <utility>

namespace hrg_gyro {
namespace core {

GeneratorPairing::GeneratorPairing(Sink sink, std::size_t max_waiting)
    : sink_(std::move(sink)), max_waiting_(max_waiting) {}

void GeneratorPairing::addRaw(Nanoseconds stamp, const ChannelVector& raw) {
  raw_[stamp] = raw;
  match();
}

void GeneratorPairing::addReference(Nanoseconds stamp, const WaveParameters& wave) {
  reference_[stamp] = idealChannels(wave);
  match();
}

void GeneratorPairing::clear() {
  raw_.clear();
  reference_.clear();
}

void GeneratorPairing::match() {
  // Each stream is in stamp order: the older of the two oldest entries can no longer find its
  // partner once the other stream has passed its stamp.
  while (!raw_.empty() && !reference_.empty()) {
    const auto raw = raw_.begin();
    const auto reference = reference_.begin();
    if (raw->first == reference->first) {
      sink_(raw->first, raw->second, reference->second);
      raw_.erase(raw);
      reference_.erase(reference);
    } else if (raw->first < reference->first) {
      raw_.erase(raw);
    } else {
      reference_.erase(reference);
    }
  }
  // Raw channels flow outside the sweep too (no reference ever comes for them): keep the newest.
  while (raw_.size() > max_waiting_) raw_.erase(raw_.begin());
  while (reference_.size() > max_waiting_) reference_.erase(reference_.begin());
}

}  // namespace core
}  // namespace hrg_gyro

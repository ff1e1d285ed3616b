// Pairs the raw channel amplitudes of the generator sweep with the generator's reference wave, for
// the correction-matrix fit. The two arrive as separate streams (live topics, bag messages, or one
// simulated sample carrying both) stamped by the same driver clock, so a pair is two entries with
// the same stamp. Either stream may run ahead of the other: entries wait, in stamp order, until
// their partner arrives or a later stamp on the other stream proves it never will. Both waiting
// lists are bounded, so a stream that stops cannot grow memory.
#pragma once

#include <cstddef>
#include <functional>
#include <map>

#include "hrg_gyro/core/common/units.h"
#include "hrg_gyro/core/model/wave_parameters.h"

namespace hrg_gyro {
namespace core {

class GeneratorPairing {
 public:
  /// Receives every pair, in stamp order: raw channels and the reference wave's ideal channels.
  using Sink = std::function<void(Nanoseconds stamp, const ChannelVector& raw, const ChannelVector& reference)>;

  explicit GeneratorPairing(Sink sink, std::size_t max_waiting = 10000);

  void addRaw(Nanoseconds stamp, const ChannelVector& raw);
  /// The generator's wave at `stamp` (its ideal channels are the reference).
  void addReference(Nanoseconds stamp, const WaveParameters& wave);
  /// Forgets everything waiting (a new run).
  void clear();

  std::size_t waitingRaw() const { return raw_.size(); }
  std::size_t waitingReferences() const { return reference_.size(); }

 private:
  void match();

  Sink sink_;
  std::size_t max_waiting_;
  std::map<Nanoseconds, ChannelVector> raw_, reference_;
};

}  // namespace core
}  // namespace hrg_gyro

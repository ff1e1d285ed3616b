// Which messages of a simulated stream reach the consumer, and with which stamp: a real session loses
// some (a full queue, a busy logger) and has outages. Each message is dropped with a fixed
// probability, drawn from its own seeded stream so that the result is the same run after run, and
// every message whose true time falls in a scheduled gap [start, start + duration) is lost. A
// scheduled stamp glitch [at, offset] gives the first message at or after `at` a stamp `offset` s off
// (a clock glitch, a stray or buffered message: one message, the stream goes on as it was). Times are
// s from the scenario start. Off by default: nothing is dropped or moved and no random number is drawn.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "hrg_gyro/core/common/units.h"
#include "hrg_gyro/core/common/yaml_field.h"
#include "hrg_gyro/core/simulation/gaussian_noise.h"

namespace hrg_gyro {
namespace core {

struct StreamGap {
  double start = 0.0;     ///< s from the scenario start
  double duration = 0.0;  ///< s
};

struct StampGlitch {
  double at = 0.0;      ///< s from the scenario start
  double offset = 0.0;  ///< s added to that one message's stamp
};

struct DeliveryConfig {
  double drop_probability = 0.0;  ///< chance that any one message is lost, [0, 1)
  std::vector<StreamGap> gaps;
  std::vector<StampGlitch> stamp_glitches;  ///< in the order of `at`

  bool enabled() const { return drop_probability > 0.0 || !gaps.empty() || !stamp_glitches.empty(); }
  /// Reads `drop_probability`, `gaps` ([[start, duration], ...]) and `stamp_glitches` ([[at, offset],
  /// ...]) from `section`, leaving the other keys to the caller. Throws ConfigError naming the key.
  static DeliveryConfig parse(const YamlField& section);
};

class StreamDelivery {
 public:
  StreamDelivery(const DeliveryConfig& config, std::uint64_t seed) : config_(config), random_(seed) {}

  /// Whether the message of true time t (s from the scenario start) arrives.
  bool delivered(double t);
  /// What the message of true time t has added to its stamp: a glitch's offset for the first message
  /// at or after its time, 0 otherwise. Called once per message, in time order.
  Nanoseconds stampOffset(double t);

 private:
  DeliveryConfig config_;
  GaussianNoise random_;
  std::size_t next_glitch_ = 0;
};

}  // namespace core
}  // namespace hrg_gyro

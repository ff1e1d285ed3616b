// Which messages of a simulated stream reach the consumer: a real session loses some (a full queue,
// a busy logger) and has outages. Each message is dropped with a fixed probability, drawn from its
// own seeded stream so that the result is the same run after run, and every message whose true time
// falls in a scheduled gap [start, start + duration) is lost. Times are s from the scenario start.
// Off by default: nothing is dropped and no random number is drawn.
#pragma once

#include <cstdint>
#include <vector>

#include "hrg_gyro/core/common/yaml_field.h"
#include "hrg_gyro/core/simulation/gaussian_noise.h"

namespace hrg_gyro {
namespace core {

struct StreamGap {
  double start = 0.0;     ///< s from the scenario start
  double duration = 0.0;  ///< s
};

struct DeliveryConfig {
  double drop_probability = 0.0;  ///< chance that any one message is lost, [0, 1)
  std::vector<StreamGap> gaps;

  bool enabled() const { return drop_probability > 0.0 || !gaps.empty(); }
  /// Reads `drop_probability` and `gaps` ([[start, duration], ...]) from `section`, leaving the
  /// other keys to the caller. Throws ConfigError naming the key.
  static DeliveryConfig parse(const YamlField& section);
};

class StreamDelivery {
 public:
  StreamDelivery(const DeliveryConfig& config, std::uint64_t seed) : config_(config), random_(seed) {}

  /// Whether the message of true time t (s from the scenario start) arrives.
  bool delivered(double t);

 private:
  DeliveryConfig config_;
  GaussianNoise random_;
};

}  // namespace core
}  // namespace hrg_gyro

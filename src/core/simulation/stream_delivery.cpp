#include "hrg_gyro/core/simulation/stream_delivery.h"

#include <cmath>

namespace hrg_gyro {
namespace core {

DeliveryConfig DeliveryConfig::parse(const YamlField& section) {
  DeliveryConfig c;
  c.drop_probability = section.getDouble("drop_probability", 0.0);
  if (!(c.drop_probability >= 0.0 && c.drop_probability < 1.0)) {
    section["drop_probability"].fail("must be in [0, 1)");
  }
  if (section.has("gaps")) {
    const YamlField gaps = section["gaps"];
    gaps.requireSequence();
    for (std::size_t i = 0; i < gaps.size(); ++i) {
      const std::vector<double> g = gaps.at(i).asDoubles(2);
      if (!(std::isfinite(g[0]) && g[0] >= 0.0)) gaps.at(i).fail("the start must be >= 0 s");
      if (!(std::isfinite(g[1]) && g[1] > 0.0)) gaps.at(i).fail("the duration must be positive (s)");
      c.gaps.push_back({g[0], g[1]});
    }
  }
  return c;
}

bool StreamDelivery::delivered(double t) {
  // The draw comes first, so that a gap does not shift which later messages are dropped.
  const bool dropped = config_.drop_probability > 0.0 && random_.uniform() < config_.drop_probability;
  if (dropped) return false;
  for (const StreamGap& g : config_.gaps) {
    if (t >= g.start && t < g.start + g.duration) return false;
  }
  return true;
}

}  // namespace core
}  // namespace hrg_gyro

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
  if (section.has("stamp_glitches")) {
    const YamlField glitches = section["stamp_glitches"];
    glitches.requireSequence();
    for (std::size_t i = 0; i < glitches.size(); ++i) {
      const std::vector<double> g = glitches.at(i).asDoubles(2);
      if (!(std::isfinite(g[0]) && g[0] >= 0.0)) glitches.at(i).fail("the time must be >= 0 s");
      if (!(std::isfinite(g[1]) && g[1] != 0.0 && std::abs(g[1]) <= 1e6)) {
        glitches.at(i).fail("the offset must be non-zero and at most 1e6 s either way");
      }
      if (!c.stamp_glitches.empty() && g[0] <= c.stamp_glitches.back().at) {
        glitches.at(i).fail("the times must increase");
      }
      c.stamp_glitches.push_back({g[0], g[1]});
    }
  }
  return c;
}

Nanoseconds StreamDelivery::stampOffset(double t) {
  if (next_glitch_ >= config_.stamp_glitches.size() || t < config_.stamp_glitches[next_glitch_].at) return 0;
  return toNanoseconds(config_.stamp_glitches[next_glitch_++].offset);
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

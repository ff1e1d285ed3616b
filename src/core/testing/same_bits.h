// Test support: bit-for-bit comparison of doubles (NaN and signed zeros included) and of whole wave
// states, for the tests that pin two ways of computing to the same numbers (a batch against one
// sample at a time, say). A mismatch names the field.
#pragma once

#include <gtest/gtest.h>

#include <cstring>
#include <utility>

#include "hrg_gyro/core/signal/wave_estimator.h"

namespace hrg_gyro {
namespace core {

inline bool sameBits(double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; }

inline ::testing::AssertionResult sameWaveBits(const WaveState& a, const WaveState& b) {
  static const std::pair<const char*, double WaveState::*> kFields[] = {
      {"theta", &WaveState::theta},
      {"amplitude", &WaveState::amplitude},
      {"quadrature", &WaveState::quadrature},
      {"phase", &WaveState::phase},
      {"energy", &WaveState::energy},
      {"quadrature_product", &WaveState::quadrature_product},
      {"cos_component", &WaveState::cos_component},
      {"sin_component", &WaveState::sin_component},
      {"phase_error", &WaveState::phase_error},
      {"cos_theta", &WaveState::cos_theta},
      {"sin_theta", &WaveState::sin_theta}};
  for (const auto& [name, field] : kFields) {
    if (!sameBits(a.*field, b.*field)) {
      return ::testing::AssertionFailure() << "wave " << name << ": " << a.*field << " vs " << b.*field;
    }
  }
  return ::testing::AssertionSuccess();
}

}  // namespace core
}  // namespace hrg_gyro

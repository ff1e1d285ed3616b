// Test support: bit-for-bit comparison of doubles (NaN and signed zeros included) and of whole wave
// states and angle increments, for the tests that pin two ways of computing to the same numbers (a
// batch against one sample at a time, say). A mismatch names the field.
#pragma once

#include <gtest/gtest.h>

#include <cstddef>
#include <cstring>
#include <utility>

#include "hrg_gyro/core/processing/compensator.h"
#include "hrg_gyro/core/signal/wave_estimator.h"

namespace hrg_gyro {
namespace core {

inline bool sameBits(double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; }

/// Every listed double field of a and b, bit for bit; a failure names the first field that differs.
template <class T, std::size_t N>
::testing::AssertionResult sameFieldBits(const char* what, const T& a, const T& b,
                                         const std::pair<const char*, double T::*> (&fields)[N]) {
  for (const auto& [name, field] : fields) {
    if (!sameBits(a.*field, b.*field)) {
      return ::testing::AssertionFailure() << what << " " << name << ": " << a.*field << " vs " << b.*field;
    }
  }
  return ::testing::AssertionSuccess();
}

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
  return sameFieldBits("wave", a, b, kFields);
}

inline ::testing::AssertionResult sameIncrementBits(const AngleIncrement& a, const AngleIncrement& b) {
  static const std::pair<const char*, double AngleIncrement::*> kFields[] = {
      {"dt", &AngleIncrement::dt},
      {"dtheta", &AngleIncrement::dtheta},
      {"theta_mid", &AngleIncrement::theta_mid},
      {"frequency", &AngleIncrement::frequency},
      {"scale_factor", &AngleIncrement::scale_factor},
      {"drift", &AngleIncrement::drift},
      {"dalpha", &AngleIncrement::dalpha},
      {"dalpha_earth_fixed", &AngleIncrement::dalpha_earth_fixed}};
  return sameFieldBits("increment", a, b, kFields);
}

}  // namespace core
}  // namespace hrg_gyro

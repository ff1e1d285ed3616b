// Physical constants, angle helpers and the integer-nanosecond time base of the core.
//
// Stamps are int64 nanoseconds so that a dt of 100 us taken between two wall-clock stamps near
// 1.7e9 s keeps full precision (a double holds such a stamp only to ~0.2 us, a 2e-4 relative error
// in dt and therefore in the output rate).
#pragma once

#include <cmath>
#include <cstdint>

namespace hrg_gyro {
namespace core {

constexpr double kPi = 3.14159265358979323846;
constexpr double kTwoPi = 2.0 * kPi;

using Nanoseconds = std::int64_t;

constexpr double toSeconds(Nanoseconds ns) { return static_cast<double>(ns) * 1e-9; }
inline Nanoseconds toNanoseconds(double seconds) { return static_cast<Nanoseconds>(std::llround(seconds * 1e9)); }

/// std::round (halves away from zero, sign of zero kept) without the library call: the per-sample
/// path rounds angle ratios several times. Exact: x - trunc(x) has no rounding error; beyond 2^52
/// (every such double is already an integer) and for NaN it defers to std::round.
inline double roundHalfAway(double x) {
  if (!(std::abs(x) < 0x1p52)) return std::round(x);
  double t = static_cast<double>(static_cast<std::int64_t>(x));
  const double fraction = x - t;
  if (fraction >= 0.5) {
    t += 1.0;
  } else if (fraction <= -0.5) {
    t -= 1.0;
  }
  return std::copysign(t, x);
}

/// 1.5 * 2^52: for |x| < 2^51, the sum x + kRoundingShift is a double whose last bit is worth 1, so
/// it holds x rounded to the nearest whole number (ties to even), also in its low bits.
constexpr double kRoundingShift = 0x1.8p52;
/// The whole number nearest to x, |x| < 2^51, ties to even: two additions, about half the chain of
/// roundHalfAway, for a hot path where a tie may go either way.
inline double nearestWhole(double x) { return (x + kRoundingShift) - kRoundingShift; }

/// x mod period, in [0, period).
inline double positiveModulo(double x, double period) {
  double r = std::fmod(x, period);
  if (r < 0.0) r += period;
  return r >= period ? 0.0 : r;
}

/// Angle wrapped to (-pi, pi].
inline double wrapToPi(double angle) {
  double r = positiveModulo(angle + kPi, kTwoPi) - kPi;
  return r == -kPi ? kPi : r;
}

/// sin(x)/x with the removable singularity handled.
inline double sinc(double x) { return std::abs(x) < 1e-8 ? 1.0 - x * x / 6.0 : std::sin(x) / x; }

}  // namespace core
}  // namespace hrg_gyro

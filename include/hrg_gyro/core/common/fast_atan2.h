// atan2 for the per-sample path, inline and without the library call (which is most of the cost of a
// wave-state estimate).
//
// The ratio t = min(|x|, |y|) / max(|x|, |y|) in [0, 1] is moved next to the nearest c = k/8 by
// atan(t) = atan(c) + atan(u), u = (t - c) / (1 + t c), so |u| <= 1/16, and atan(u) is its Taylor
// series up to u^13 (the first term left out is below 2^-60 / 15 ~ 6e-20). The octant and quadrant
// are then restored with pi/2 - a and pi - a. The error is a few roundings of numbers below pi:
// below 1e-15 rad in absolute terms (fast_atan2_test.cpp checks it against std::atan2 on a dense
// grid and on random pairs). Zeros, infinities, NaN and operands beyond 2^-1000 .. 1.7e308 go to
// std::atan2, so their conventions (signed zeros, atan2(0, -0) = pi, ...) are the library's.
#pragma once

#include <cmath>

namespace hrg_gyro {
namespace core {

inline double fastAtan2(double y, double x) {
  const double ax = std::abs(x), ay = std::abs(y);
  // One test for zeros, infinities, NaN and the extremes of the range (where the reduction would
  // overflow or lose digits to subnormal numbers): the library takes those.
  if (!(ax + ay >= 0x1p-1000 && ax + ay <= 1.7e308)) return std::atan2(y, x);
  // atan(k / 8), k = 0 .. 8.
  static constexpr double kAtanOfEighths[9] = {0.0,
                                               0.12435499454676144,
                                               0.24497866312686414,
                                               0.35877067027057225,
                                               0.4636476090008061,
                                               0.5585993153435624,
                                               0.6435011087932844,
                                               0.7188299996216245,
                                               0.7853981633974483};
  const bool swapped = ay > ax;
  const double num = swapped ? ax : ay, den = swapped ? ay : ax;
  const int k = static_cast<int>(8.0 * (num / den) + 0.5);
  const double c = 0.125 * k;
  const double u = (num - c * den) / (den + c * num);
  const double u2 = u * u;
  const double series =
      u + u * u2 *
              (-1.0 / 3.0 +
               u2 * (1.0 / 5.0 + u2 * (-1.0 / 7.0 + u2 * (1.0 / 9.0 + u2 * (-1.0 / 11.0 + u2 * (1.0 / 13.0))))));
  double a = kAtanOfEighths[k] + series;
  if (swapped) a = 1.5707963267948966 - a;
  if (x < 0.0) a = 3.141592653589793 - a;
  return std::signbit(y) ? -a : a;
}

}  // namespace core
}  // namespace hrg_gyro

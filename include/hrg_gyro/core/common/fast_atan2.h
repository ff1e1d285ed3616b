// atan2 for the per-sample path, inline and without the library call (which was most of the cost of
// a wave-state estimate), for one double or for lanes of them (double_lanes.h), with the same bits in
// every lane as for one double.
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
#include <cstdint>

#include "hrg_gyro/core/common/double_lanes.h"

namespace hrg_gyro {
namespace core {

/// Whether fastAtan2Reduced applies to (y, x): both finite, not both zero, not extreme (a bool for a
/// double, a mask for lanes).
template <class V>
inline auto fastAtan2Applies(V y, V x) {
  const V sum = laneAbs(x) + laneAbs(y);
  return (sum >= 0x1p-1000) & (sum <= 1.7e308);
}

/// c = k / 8 for the k nearest to 8 t (t in [0, 1]) and table[k] (9 entries), lane by lane. A t
/// outside [0, 1] (NaN from a rejected sample's 0 / 0, whose result nobody uses) reads entry 0.
inline void eighthNearest(double t, const double* table, double* c, double* value) {
  double scaled = 8.0 * t + 0.5;
  scaled = scaled >= 0.0 && scaled < 9.0 ? scaled : 0.0;
  const int k = static_cast<int>(scaled);
  *c = 0.125 * k;
  *value = table[k];
}
template <class V>
inline void eighthNearest(V t, const double* table, V* c, V* value) {
  typedef typename LaneTraits<V>::Index Index;
  V scaled = 8.0 * t + 0.5;
  scaled = select((scaled >= 0.0) & (scaled < 9.0), scaled, splat<V>(0.0));
  const Index k = __builtin_convertvector(scaled, Index);  // truncates, as static_cast<int>
  *c = 0.125 * __builtin_convertvector(k, V);
  for (unsigned i = 0; i < sizeof(V) / sizeof(double); ++i) (*value)[i] = table[k[i]];
}

/// The reduction and series alone, for operands where fastAtan2Applies (lane by lane).
template <class V>
inline V fastAtan2Reduced(V y, V x) {
  const V ax = laneAbs(x), ay = laneAbs(y);
  const auto swapped = ay > ax;
  const V num = select(swapped, ax, ay), den = select(swapped, ay, ax);
  // c = the eighth nearest to num / den and atan(c) from the table.
  static constexpr double kAtanOfEighths[9] = {0.0,
                                               0.12435499454676144,
                                               0.24497866312686414,
                                               0.35877067027057225,
                                               0.4636476090008061,
                                               0.5585993153435624,
                                               0.6435011087932844,
                                               0.7188299996216245,
                                               0.7853981633974483};
  V c, base;
  eighthNearest(num / den, kAtanOfEighths, &c, &base);
  const V u = (num - c * den) / (den + c * num);
  // u - u^3/3 + ... + u^13/13 with the polynomial in u^2 by Estrin's scheme: three short chains of
  // products instead of one long one.
  const V z = u * u, z2 = z * z, z4 = z2 * z2;
  const V p =
      (-1.0 / 3.0 + z * (1.0 / 5.0)) + z2 * (-1.0 / 7.0 + z * (1.0 / 9.0)) + z4 * (-1.0 / 11.0 + z * (1.0 / 13.0));
  V a = base + (u + (u * z) * p);
  a = select(swapped, 1.5707963267948966 - a, a);
  a = select(x < 0.0, 3.141592653589793 - a, a);
  return laneCopysign(a, y);
}

inline double fastAtan2(double y, double x) {
  return fastAtan2Applies(y, x) ? fastAtan2Reduced(y, x) : std::atan2(y, x);
}

}  // namespace core
}  // namespace hrg_gyro

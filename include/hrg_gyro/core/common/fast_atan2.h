// atan2 for the per-sample path, inline and without the library call (which was most of the cost of
// a wave-state estimate), for one double or for lanes of them (double_lanes.h), with the same bits in
// every lane as for one double.
//
// The ratio t = min(|x|, |y|) / max(|x|, |y|) in [0, 1] is moved next to the nearest c = k/32 by
// atan(t) = atan(c) + atan(u), u = (t - c) / (1 + t c), so |u| <= 1/64, and atan(u) is its Taylor
// series up to u^7 (the first term left out is below 2^-54 / 9 ~ 6e-18). The octant and quadrant
// are restored as offset +- a (0, pi/2 or pi). The error is a few roundings of numbers below pi:
// below 1e-15 rad in absolute terms (fast_atan2_test.cpp checks it against std::atan2 on a dense
// grid and on random pairs). Zeros, infinities, NaN and operands beyond 2^-1000 .. 1.7e308 go to
// std::atan2, so their conventions (signed zeros, atan2(0, -0) = pi, ...) are the library's.
#pragma once

#include <cmath>
#include <cstdint>

#include "hrg_gyro/core/common/double_lanes.h"
#include "hrg_gyro/core/common/units.h"

namespace hrg_gyro {
namespace core {

/// Whether fastAtan2Reduced applies to (y, x): both finite, not both zero, not extreme (a bool for a
/// double, a mask for lanes).
template <class V>
inline auto fastAtan2Applies(V y, V x) {
  const V sum = laneAbs(x) + laneAbs(y);
  return (sum >= 0x1p-1000) & (sum <= 1.7e308);
}

/// Where the reduction moves t (in [0, 1]), given t32 = 32 t: k, the whole number nearest to 32 t
/// (ties to even: either neighbour leaves |u| <= 1/64), as a double, and atan(k / 32) from the table.
/// Adding kRoundingShift (units.h) rounds 32 t to a whole number held in the low bits of the sum:
/// the way to u has no conversion to int and back and no range check. The table index is those low
/// six bits, and the table has 64 entries, so a NaN lane (a rejected sample's 0 / 0, whose result
/// nobody uses) reads one of them too.
constexpr double kAtanSteps = 32.0;
inline void nearestStep(double t32, const double* table, double* k, double* value) {
  const double shifted = t32 + kRoundingShift;
  *k = shifted - kRoundingShift;
  *value = table[__builtin_bit_cast(std::uint64_t, shifted) & 63];
}
template <class V>
inline void nearestStep(V t32, const double* table, V* k, V* value) {
  typedef typename LaneTraits<V>::Bits Bits;
  const V shifted = t32 + kRoundingShift;
  *k = shifted - kRoundingShift;
  const Bits index = (Bits)shifted & 63;
  for (unsigned i = 0; i < sizeof(V) / sizeof(double); ++i) (*value)[i] = table[index[i]];
}

/// v with its sign bit flipped where `flip` has its sign bit set (an exact negation, one XOR).
inline double laneFlipSign(double v, double flip) {
  return __builtin_bit_cast(
      double, __builtin_bit_cast(std::uint64_t, v) ^ (__builtin_bit_cast(std::uint64_t, flip) & 0x8000000000000000u));
}
template <class V>
inline V laneFlipSign(V v, V flip) {
  typedef typename LaneTraits<V>::Bits Bits;
  return (V)((Bits)v ^ ((Bits)flip & INT64_MIN));
}

/// The reduction and series alone, for operands where fastAtan2Applies (lane by lane).
template <class V>
inline V fastAtan2Reduced(V y, V x) {
  const V ax = laneAbs(x), ay = laneAbs(y);
  const auto swapped = ay > ax;
  const auto negative_x = x < 0.0;
  const V num = select(swapped, ax, ay), den = select(swapped, ay, ax);
  // atan2(|y|, x) = offset +- atan(num / den): 0 + a (|x| >= |y|, x >= 0), pi - a (x < 0),
  // pi/2 - a (|y| > |x|, x >= 0), pi/2 + a (x < 0). Offset and sign are known before the series, so
  // the result waits for one sign flip and one addition after it instead of two subtractions and two
  // selections.
  const V offset =
      select(swapped, splat<V>(1.5707963267948966), select(negative_x, splat<V>(3.141592653589793), splat<V>(0.0)));
  const V minus = select(swapped ^ negative_x, splat<V>(-0.0), splat<V>(0.0));
  // The 32nds k / 32 nearest to t = num / den, and atan(k / 32) from the table (entries 33 to 63 are
  // never read for a t in [0, 1]).
  // clang-format off
  static constexpr double kAtanOfSteps[64] = {
      0.0, 0.031239833430268277, 0.06241880999595735, 0.09347678115858947,
      0.12435499454676144, 0.15499674192394097, 0.18534794999569476, 0.21535769969773805,
      0.24497866312686414, 0.2741674511196588, 0.3028848683749714, 0.3310960767041321,
      0.35877067027057225, 0.38588266939807375, 0.4124104415973873, 0.43833655985795783,
      0.4636476090008061, 0.48833395105640554, 0.5123894603107377, 0.5358112379604637,
      0.5585993153435624, 0.5807563535676704, 0.6022873461349642, 0.6231993299340659,
      0.6435011087932844, 0.6632029927060933, 0.6823165548747481, 0.7008544078844502,
      0.7188299996216245, 0.7362574289814281, 0.7531512809621944, 0.7695264804056583,
      0.7853981633974483};
  // clang-format on
  // num / den32 = 32 t exactly as 32 (num / den) would round it: den / 32 is exact (den is a normal
  // number), and it saves a multiplication on the way to k.
  const V den32 = (1.0 / kAtanSteps) * den, num32 = (1.0 / kAtanSteps) * num;
  V k, base;
  nearestStep(num / den32, kAtanOfSteps, &k, &base);
  // atan(t) = atan(c) + atan(u) with c = k / 32, u = (t - c) / (1 + t c) = (num - c den) / (den + c num),
  // |u| <= 1/64, and atan(u) = u - u^3/3 + u^5/5 - u^7/7 (the first term left out, u^9/9, is below
  // 2^-54 / 9 ~ 6e-18). c den is k den32, the same number, and it waits for k alone (likewise c num
  // wherever k > 0).
  const V u = (num - k * den32) / (den + k * num32);
  const V z = u * u;
  const V p = (-1.0 / 3.0 + z * (1.0 / 5.0)) + (z * z) * (-1.0 / 7.0);
  // base + u waits for u alone, the series term is added last; the restoring addition is the only
  // rounding at the magnitude of pi. The sign of y goes into both of its terms beforehand (rounding
  // is symmetric, so this is copysign of the sum, bit for bit).
  const V a = (base + u) + (u * z) * p;
  return laneFlipSign(offset, y) + laneFlipSign(a, laneFlipSign(minus, y));
}

inline double fastAtan2(double y, double x) {
  return fastAtan2Applies(y, x) ? fastAtan2Reduced(y, x) : std::atan2(y, x);
}

}  // namespace core
}  // namespace hrg_gyro

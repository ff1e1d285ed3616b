// Several doubles handled as one value (the GCC/Clang vector extensions), and the handful of
// elementwise operations the per-sample arithmetic needs, written once for a plain double and for
// lanes. A function templated on the lane type then computes every lane with the same sequence of
// correctly rounded operations as the scalar instance (no fused multiply-add: the core is built with
// -ffp-contract=off), so the batch path and the one-sample path give the same bits.
#pragma once

#include <cmath>
#include <cstdint>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

namespace hrg_gyro {
namespace core {

/// On a function of the batch paths: compiled twice, for AVX2 and for the baseline, the better one
/// chosen at load time (the bits are the same: no fused multiply-add either way). Clang 14 emits the
/// chooser of such a function only in a file that also calls it, which leaves the library's own
/// clones undefined; a clang build (the fuzzers, built for the machine they run on with -mavx2)
/// compiles one version instead.
#if defined(__clang__)
#define HRG_GYRO_CLONES_FOR_AVX2
#else
#define HRG_GYRO_CLONES_FOR_AVX2 __attribute__((target_clones("avx2", "default")))
#endif

typedef double DoubleLanes2 __attribute__((vector_size(16)));
typedef double DoubleLanes4 __attribute__((vector_size(32)));

/// The integer lanes that go with a double lane type: its bits.
template <class V>
struct LaneTraits;
template <>
struct LaneTraits<DoubleLanes2> {
  typedef std::int64_t Bits __attribute__((vector_size(16)));
};
template <>
struct LaneTraits<DoubleLanes4> {
  typedef std::int64_t Bits __attribute__((vector_size(32)));
};

/// x in every lane (x itself for a double). x - (+0) is x for every x, -0.0 included (0 + -0.0 would
/// be +0.0).
template <class V>
inline V splat(double x) {
  return x - V{};
}
template <>
inline double splat<double>(double x) {
  return x;
}

/// mask ? a : b, lane by lane (a mask is what a lane comparison returns).
template <class M, class V>
inline V select(M mask, V a, V b) {
  return mask ? a : b;
}

inline double laneSqrt(double x) { return std::sqrt(x); }
#if defined(__SSE2__)
/// One instruction for both lanes (GCC leaves the loop below on a pair as two scalar roots); the
/// root is correctly rounded either way, so the bits are the same.
inline DoubleLanes2 laneSqrt(DoubleLanes2 x) { return _mm_sqrt_pd(x); }
#endif
template <class V>
inline V laneSqrt(V x) {
  V r;
  for (unsigned i = 0; i < sizeof(V) / sizeof(double); ++i) r[i] = std::sqrt(x[i]);
  return r;
}

inline double laneAbs(double x) { return std::abs(x); }
template <class V>
inline V laneAbs(V x) {
  typedef typename LaneTraits<V>::Bits Bits;
  return (V)((Bits)x & INT64_MAX);
}

/// |magnitude| with the sign bit of sign.
inline double laneCopysign(double magnitude, double sign) { return std::copysign(magnitude, sign); }
template <class V>
inline V laneCopysign(V magnitude, V sign) {
  typedef typename LaneTraits<V>::Bits Bits;
  return (V)(((Bits)magnitude & INT64_MAX) | ((Bits)sign & INT64_MIN));
}

}  // namespace core
}  // namespace hrg_gyro

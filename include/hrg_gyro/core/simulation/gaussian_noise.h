// Seeded white Gaussian noise for the simulator, fast enough for per-sample sensor noise.
//
// Uniforms come from xoshiro256++ (Blackman and Vigna; state seeded by splitmix64 from the scenario
// seed). Normals by one of two methods, chosen at construction; each is bit-for-bit reproducible by
// seed (no library-defined algorithm):
//  - kPolar (the default): Marsaglia's polar method, two normals per accepted pair and one logarithm
//    per pair. Its streams are the ones the statistical tests and test helpers were written against.
//  - kZiggurat (~4x cheaper; not yet the synthesizer's, see signal_synthesizer.h): a 256-layer ziggurat
//    (Marsaglia and Tsang): the density exp(-x^2/2) is covered
// by 256 strips of equal area; one 64-bit draw picks a strip (8 bits) and a signed abscissa (53 bits),
// and in ~99 % of draws the point lies inside the curve's strip with no further work. Otherwise the
// wedge is tested against exp(-x^2/2) directly, or, for the bottom strip, the tail beyond r is
// sampled exactly (Marsaglia's exponential method), so the output is exactly normal up to double
// rounding, with no logarithm per deviate (its tables come from exp, log and sqrt once).
// Either is ~5x or more faster than std::normal_distribution on libstdc++, whose generate_canonical
// works in long double.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>

namespace hrg_gyro {
namespace core {

class GaussianNoise {
 public:
  enum class Method { kPolar, kZiggurat };

  explicit GaussianNoise(std::uint64_t seed, Method method = Method::kPolar)
      : layers_(method == Method::kZiggurat ? &Layers::get() : nullptr) {
    std::uint64_t x = seed;
    for (std::uint64_t& word : s_) word = splitmix64(&x);
  }

  /// Standard normal deviate.
  double next() { return layers_ ? nextZiggurat() : nextPolar(); }

  /// n standard normal deviates: the same numbers, in the same order, as n calls of next(), and the
  /// generator left in the same state. For the polar method the accepted pairs are drawn first and
  /// their logarithms and square roots computed afterwards, independent of one another, so the CPU
  /// overlaps them instead of waiting on each in turn.
  void fill(double* out, int n) {
    if (layers_) {
      for (int i = 0; i < n; ++i) out[i] = nextZiggurat();
      return;
    }
    int i = 0;
    if (i < n && has_spare_) {
      has_spare_ = false;
      out[i++] = spare_;
    }
    constexpr int kPairs = 64;
    double u[kPairs], v[kPairs], r2[kPairs];
    while (i < n) {
      const int pairs = std::min(kPairs, (n - i + 1) / 2);
      // Candidates written in turn and kept by advancing k only for the accepted ones: the same
      // accepted pairs, in the same order, as polarPair's loop, without the branch on r2 that
      // went the wrong way for about one candidate in five.
      for (int k = 0; k < pairs;) k += static_cast<int>(polarCandidate(&u[k], &v[k], &r2[k]));
      for (int k = 0; k < pairs; ++k) {
        const double scale = polarScale(r2[k]);
        out[i++] = u[k] * scale;
        if (i < n) {
          out[i++] = v[k] * scale;
        } else {
          spare_ = v[k] * scale;  // an odd count: the pair's second deviate is the next one
          has_spare_ = true;
        }
      }
    }
  }

  /// Uniform in [0, 1) with 53 random bits.
  double uniform() { return static_cast<double>(nextBits() >> 11) * 0x1.0p-53; }

  std::uint64_t nextBits() {
    const std::uint64_t result = rotl(s_[0] + s_[3], 23) + s_[0];
    const std::uint64_t t = s_[1] << 17;
    s_[2] ^= s_[0];
    s_[3] ^= s_[1];
    s_[1] ^= s_[2];
    s_[0] ^= s_[3];
    s_[2] ^= t;
    s_[3] = rotl(s_[3], 45);
    return result;
  }

 private:
  /// A candidate point (u, v) uniform in the square [-1, 1)^2 and r2 = u^2 + v^2; true when the polar
  /// method accepts it (inside the unit disc, not its centre). Without a branch: fill() counts on it.
  bool polarCandidate(double* u, double* v, double* r2) {
    *u = 2.0 * uniform() - 1.0;
    *v = 2.0 * uniform() - 1.0;
    *r2 = *u * *u + *v * *v;
    return (*r2 < 1.0) & (*r2 != 0.0);
  }
  /// The polar method's accepted point: (u, v) uniform in the unit disc without its centre.
  void polarPair(double* u, double* v, double* r2) {
    while (!polarCandidate(u, v, r2)) {
    }
  }
  /// The factor that turns an accepted point into two independent standard normal deviates.
  static double polarScale(double r2) { return std::sqrt(-2.0 * std::log(r2) / r2); }

  double nextPolar() {
    if (has_spare_) {
      has_spare_ = false;
      return spare_;
    }
    double u, v, r2;
    polarPair(&u, &v, &r2);
    const double scale = polarScale(r2);
    spare_ = v * scale;
    has_spare_ = true;
    return u * scale;
  }

  double nextZiggurat() {
    for (;;) {
      const std::uint64_t bits = nextBits();
      const int i = static_cast<int>(bits & 255u);                         // the strip
      const double u = static_cast<double>(bits >> 11) * 0x1.0p-52 - 1.0;  // [-1, 1), 53 bits
      if (std::abs(u) < layers_->inner[i]) return u * layers_->x[i];       // inside the curve
      if (i == 0) return tail(u < 0.0);
      const double x = u * layers_->x[i];
      const double y = layers_->f[i] + uniform() * (layers_->f[i + 1] - layers_->f[i]);
      if (y < std::exp(-0.5 * x * x)) return x;  // in the wedge under the curve
    }
  }

  /// Strip i spans [0, x[i]] at heights f[i] .. f[i + 1] (f = exp(-x^2/2) at the edges); strip 0 is
  /// the rectangle under f(r) plus the tail beyond r, drawn as one rectangle of the same area.
  /// inner[i] = x[i + 1] / x[i]: below it a point lies under the curve whatever its height.
  struct Layers {
    static constexpr double kTailStart = 3.6541528853610088;  // r, the tail's start for 256 strips
    static constexpr double kArea = 4.92867323399e-3;         // the area of every strip
    std::array<double, 257> x{}, f{};
    std::array<double, 256> inner{};
    Layers() {
      const double r = kTailStart;
      x[0] = kArea / std::exp(-0.5 * r * r);
      x[1] = r;
      for (int i = 1; i < 255; ++i) x[i + 1] = std::sqrt(-2.0 * std::log(std::exp(-0.5 * x[i] * x[i]) + kArea / x[i]));
      x[256] = 0.0;
      for (int i = 0; i <= 256; ++i) f[i] = std::exp(-0.5 * x[i] * x[i]);
      for (int i = 0; i < 256; ++i) inner[i] = x[i + 1] / x[i];
    }
    static const Layers& get() {
      static const Layers layers;
      return layers;
    }
  };

  /// |x| > r from the normal tail: x = r + e1 / r with e1, e2 exponential, kept when 2 e2 > (e1/r)^2.
  double tail(bool negative) {
    const double r = Layers::kTailStart;
    double x, y;
    do {
      x = -std::log(1.0 - uniform()) / r;
      y = -std::log(1.0 - uniform());
    } while (2.0 * y < x * x);
    return negative ? -(r + x) : r + x;
  }

  static std::uint64_t rotl(std::uint64_t x, int k) { return (x << k) | (x >> (64 - k)); }
  static std::uint64_t splitmix64(std::uint64_t* x) {
    std::uint64_t z = (*x += 0x9e3779b97f4a7c15ULL);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
    return z ^ (z >> 31);
  }

  const Layers* layers_;  // null for the polar method
  std::uint64_t s_[4];
  double spare_ = 0.0;
  bool has_spare_ = false;
};

}  // namespace core
}  // namespace hrg_gyro

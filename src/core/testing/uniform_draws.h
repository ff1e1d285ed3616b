// Test support: seeded uniform draws in [-1, 1), for the tests that try many random inputs (the same
// sequence as std::uniform_real_distribution<double>(-1, 1) over std::mt19937_64(seed)).
#pragma once

#include <cstdint>
#include <random>

namespace hrg_gyro {
namespace core {
namespace testing {

class UniformDraws {
 public:
  explicit UniformDraws(std::uint64_t seed) : engine_(seed) {}
  double operator()() { return distribution_(engine_); }

 private:
  std::mt19937_64 engine_;
  std::uniform_real_distribution<double> distribution_{-1.0, 1.0};
};

}  // namespace testing
}  // namespace core
}  // namespace hrg_gyro

// Test support: a 64-bit FNV-1a hash over the bytes of values, for the tests that pin a simulator's
// output bit for bit to a hash recorded before a change (any changed bit changes the hash). Each test
// says which fields of its samples go in.
#pragma once

#include <Eigen/Geometry>
#include <cstdint>
#include <cstring>

namespace hrg_gyro {
namespace core {
namespace testing {

class BitFingerprint {
 public:
  template <typename T>
  void add(const T& value) {
    unsigned char bytes[sizeof(T)];
    std::memcpy(bytes, &value, sizeof(T));
    for (const unsigned char b : bytes) hash_ = (hash_ ^ b) * 0x100000001b3ULL;
  }
  void add(const Eigen::Vector3d& v) {
    for (int j = 0; j < 3; ++j) add(v[j]);
  }
  void add(const Eigen::Quaterniond& q) {
    for (int j = 0; j < 4; ++j) add(q.coeffs()[j]);
  }
  std::uint64_t value() const { return hash_; }

 private:
  std::uint64_t hash_ = 0xcbf29ce484222325ULL;
};

}  // namespace testing
}  // namespace core
}  // namespace hrg_gyro

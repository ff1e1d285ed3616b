// Invariant checks shared by the fuzz targets. A broken invariant aborts: libFuzzer then saves the
// input as a crash artifact, and the corpus-replay gtest in `make test` fails.
#pragma once

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>

#define HRG_FUZZ_CHECK(condition)                                                                   \
  do {                                                                                              \
    if (!(condition)) {                                                                             \
      std::fprintf(stderr, "%s:%d: fuzz invariant violated: %s\n", __FILE__, __LINE__, #condition); \
      std::abort();                                                                                 \
    }                                                                                               \
  } while (0)

#define HRG_FUZZ_CHECK_FINITE(value) HRG_FUZZ_CHECK(std::isfinite(value))

namespace hrg_gyro {
namespace fuzz {

/// The targets, callable from libFuzzer's entry point and from the corpus-replay test.
int parameterFileTarget(const std::uint8_t* data, std::size_t size);
int sampleProcessingTarget(const std::uint8_t* data, std::size_t size);

}  // namespace fuzz
}  // namespace hrg_gyro

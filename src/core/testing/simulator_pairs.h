// Test support: two simulated gyros stepped together, for the tests that hold one scenario to the
// bits of another (a section of zeros against none, an axis's hook against the plain simulator, a
// gyro at a constant temperature against the gyro frozen there).
#pragma once

#include <gtest/gtest.h>

#include <functional>

#include "hrg_gyro/core/simulation/gyro_simulator.h"

namespace hrg_gyro {
namespace core {
namespace testing {

/// Steps `a` and `b` together to their end: the same number of samples with the same stamps,
/// channels and true wave angle, bit for bit (a failure names the first sample that differs);
/// `check(sa, sb, n)`, when given, adds the test's own checks of each pair. Returns the pairs compared.
inline int stepTogether(
    GyroSimulator* a, GyroSimulator* b,
    const std::function<void(const SimulationSample&, const SimulationSample&, int)>& check = nullptr) {
  SimulationSample sa, sb;
  int n = 0;
  while (a->next(&sa)) {
    if (!b->next(&sb)) {
      ADD_FAILURE() << "the second simulator ended after " << n << " samples";
      return n;
    }
    if (sa.stamp != sb.stamp || sa.z != sb.z || !(sa.truth.theta == sb.truth.theta)) {
      ADD_FAILURE() << "sample " << n << " differs: stamps " << sa.stamp << " and " << sb.stamp << ", theta "
                    << sa.truth.theta << " and " << sb.truth.theta << ", channels " << sa.z.transpose() << " and "
                    << sb.z.transpose();
      return n;
    }
    if (check) check(sa, sb, n);
    ++n;
  }
  EXPECT_FALSE(b->next(&sb)) << "the second simulator goes on after " << n << " samples";
  return n;
}

}  // namespace testing
}  // namespace core
}  // namespace hrg_gyro

// Test support: what a constructor or parser refused. The tests of every settings check ask the same
// question -- refused, and naming which key? -- so it is asked once here.
#pragma once

#include <gtest/gtest.h>

#include <stdexcept>
#include <string>
#include <vector>

#include "hrg_gyro/core/common/yaml_field.h"

namespace hrg_gyro {
namespace core {

/// The key of the ConfigError `make()` throws, or "accepted" when it throws none.
template <class Make>
std::string refusedKey(const Make& make) {
  try {
    make();
  } catch (const ConfigError& e) {
    return e.key();
  }
  return "accepted";
}

/// An input and the key it must be refused by ("accepted": none).
struct RefusalCase {
  std::string input, key;
};

/// Each case's input through `parse`, the key it is refused by checked: one expectation per case,
/// naming its input, so a table of cases reads as the settings' rules.
template <class Parse>
void expectRefusedKeys(const Parse& parse, const std::vector<RefusalCase>& cases) {
  for (const RefusalCase& c : cases) EXPECT_EQ(refusedKey([&] { parse(c.input); }), c.key) << c.input;
}

/// The message of the std::invalid_argument `make()` throws, or "accepted" when it throws none.
template <class Make>
std::string refusal(const Make& make) {
  try {
    make();
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "accepted";
}

}  // namespace core
}  // namespace hrg_gyro

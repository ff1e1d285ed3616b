// Test support: what a constructor or parser refused. The tests of every settings check ask the same
// question -- refused, and naming which key? -- so it is asked once here.
#pragma once

#include <stdexcept>
#include <string>

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

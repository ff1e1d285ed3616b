#include "hrg_gyro/core/common/number_format.h"

#include <charconv>
#include <cmath>
#include <cstdio>
#include <sstream>

namespace hrg_gyro {
namespace core {

std::string formatDouble(double value) {
  char buf[64];
  const auto res = std::to_chars(buf, buf + sizeof(buf), value);
  std::string s(buf, res.ptr);
  // Keep it visibly a float for YAML readers that would otherwise type "1" as an integer.
  if (std::isfinite(value) && s.find_first_of(".eE") == std::string::npos) s += ".0";
  return s;
}

std::string formatShort(double value, int precision) {
  std::ostringstream s;
  s.precision(precision);
  s << value;
  return s.str();
}

std::string formatNumbers(const char* pattern, double a, double b, double c, double d) {
  char buffer[512];
  std::snprintf(buffer, sizeof buffer, pattern, a, b, c, d);
  return buffer;
}

}  // namespace core
}  // namespace hrg_gyro

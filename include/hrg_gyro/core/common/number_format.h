// Numbers as text, in the two forms the project writes them: the shortest decimal that reads back to
// the same double (files that must round-trip exactly: parameter files, results, the YAML the ROS
// layer hands the core), and a number to a few significant digits (the messages of gates and
// refusals). A module of its own, so a file that only prints a number depends on neither the YAML
// reader nor the calibration's outcome. No ROS.
#pragma once

#include <string>

namespace hrg_gyro {
namespace core {

/// Shortest decimal text that reads back to exactly the same double (round-trip exact files); a whole
/// number keeps ".0", so a YAML reader types it as a float.
std::string formatDouble(double value);
/// A number with `precision` significant digits, for gate messages.
std::string formatShort(double value, int precision = 4);
/// A printf-style message with up to four numbers (the alignment's refusals' wording), at most 511 characters.
std::string formatNumbers(const char* pattern, double a = 0.0, double b = 0.0, double c = 0.0, double d = 0.0);

}  // namespace core
}  // namespace hrg_gyro

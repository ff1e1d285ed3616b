// The per-axis options of hrg_bag's triad commands (process --triad, calibrate --method triad):
// --axis-params, --axis-channels, --axis-out, each NAME=VALUE with NAME an axis of the triad.
#pragma once

#include <array>
#include <map>
#include <string>
#include <vector>

namespace hrg_gyro {
namespace bag_tools {

/// The NAME=VALUE items of option `option` (without its dashes) by name, each name given once; a
/// UsageError names what is wrong.
std::map<std::string, std::string> perAxis(const std::vector<std::string>& items, const std::string& option);

/// Each name of `given` one of the triad's `axes`; a UsageError names the first that is not.
void checkAxisNames(const std::map<std::string, std::string>& given, const std::array<std::string, 3>& axes,
                    const std::string& option);

}  // namespace bag_tools
}  // namespace hrg_gyro

#include "triad_axis_options.h"

#include "bag_tools.h"

namespace hrg_gyro {
namespace bag_tools {

std::map<std::string, std::string> perAxis(const std::vector<std::string>& items, const std::string& option) {
  std::map<std::string, std::string> out;
  for (const std::string& item : items) {
    const std::size_t eq = item.find('=');
    const std::string name = eq == std::string::npos ? std::string() : item.substr(0, eq);
    const std::string value = eq == std::string::npos ? std::string() : item.substr(eq + 1);
    if (name.empty() || value.empty()) {
      throw UsageError("--" + option + " expects NAME=VALUE with NAME an axis of the triad, got '" + item + "'");
    }
    if (!out.emplace(name, value).second) throw UsageError("--" + option + " gives axis " + name + " twice");
  }
  return out;
}

void checkAxisNames(const std::map<std::string, std::string>& given, const std::array<std::string, 3>& axes,
                    const std::string& option) {
  for (const auto& kv : given) {
    const std::string& name = kv.first;
    if (name != axes[0] && name != axes[1] && name != axes[2]) {
      throw UsageError("--" + option + " " + name + "=" + kv.second + ": '" + name +
                       "' is not an axis of the triad (its axes: " + axes[0] + ", " + axes[1] + ", " + axes[2] + ")");
    }
  }
}

}  // namespace bag_tools
}  // namespace hrg_gyro

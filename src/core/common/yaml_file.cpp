#include "hrg_gyro/core/common/yaml_file.h"

#include <stdexcept>

#include "hrg_gyro/core/common/atomic_file.h"
#include "hrg_gyro/core/common/yaml_field.h"

namespace hrg_gyro {
namespace core {

YAML::Node loadYamlFile(const std::string& path, std::size_t max_bytes, const std::string& what) {
  std::string text;
  try {
    text = readBoundedRegularFile(path, max_bytes, what);
  } catch (const std::runtime_error& e) {
    throw ConfigError("", e.what());
  }
  try {
    return YAML::Load(text);
  } catch (const YAML::ParserException& e) {
    throw ConfigError("",
                      "YAML syntax error in '" + path + "' at line " + std::to_string(e.mark.line + 1) + ": " + e.msg);
  }
}

}  // namespace core
}  // namespace hrg_gyro

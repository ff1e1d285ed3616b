// The YAML document of a configuration file, read the one bounded way (common/atomic_file.h's
// readBoundedRegularFile: a regular file, never a FIFO or a device, of at most a given size), with
// the file and the line of a syntax error named. The triad file, the scenarios and the alignment's
// settings are read through it.
#pragma once

#include <yaml-cpp/yaml.h>

#include <cstddef>
#include <string>

namespace hrg_gyro {
namespace core {

/// The document of `path`, at most `max_bytes`; `what` names the file in messages ("triad file").
/// Throws ConfigError (without a key) for an unreadable file and for a YAML syntax error.
YAML::Node loadYamlFile(const std::string& path, std::size_t max_bytes, const std::string& what);

}  // namespace core
}  // namespace hrg_gyro

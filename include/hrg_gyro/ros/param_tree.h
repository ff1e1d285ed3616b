// A node's private parameters as a YAML tree, so that the core's validating parsers (scenarios,
// calibrator settings) read `rosparam load`-ed parameters exactly as they read YAML files: one set
// of keys, one set of checks, errors that name the key.
#pragma once

#include <ros/node_handle.h>
#include <yaml-cpp/yaml.h>

#include <string>

namespace hrg_gyro {

/// Converts an XmlRpc value (any type) to YAML.
YAML::Node toYaml(const XmlRpc::XmlRpcValue& value);

/// The whole private namespace of `nh` as a YAML map (empty map when it has no parameters).
YAML::Node privateParameters(const ros::NodeHandle& nh);

}  // namespace hrg_gyro

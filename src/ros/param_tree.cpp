#include "hrg_gyro/ros/param_tree.h"

#include <sstream>

#include "hrg_gyro/core/common/number_format.h"
#include "hrg_gyro/core/common/yaml_field.h"

namespace hrg_gyro {

YAML::Node toYaml(const XmlRpc::XmlRpcValue& value) {
  XmlRpc::XmlRpcValue v = value;  // the accessors are non-const
  switch (v.getType()) {
    case XmlRpc::XmlRpcValue::TypeBoolean:
      return YAML::Node(static_cast<bool>(v));
    case XmlRpc::XmlRpcValue::TypeInt:
      return YAML::Node(static_cast<int>(v));
    case XmlRpc::XmlRpcValue::TypeDouble:
      // Through the shortest round-trip text so YAML reads back exactly this double.
      return YAML::Node(core::formatDouble(static_cast<double>(v)));
    case XmlRpc::XmlRpcValue::TypeString:
      return YAML::Node(static_cast<std::string>(v));
    case XmlRpc::XmlRpcValue::TypeArray: {
      YAML::Node seq(YAML::NodeType::Sequence);
      for (int i = 0; i < v.size(); ++i) seq.push_back(toYaml(v[i]));
      return seq;
    }
    case XmlRpc::XmlRpcValue::TypeStruct: {
      YAML::Node map(YAML::NodeType::Map);
      for (auto it = v.begin(); it != v.end(); ++it) map[it->first] = toYaml(it->second);
      return map;
    }
    default:
      return YAML::Node();
  }
}

YAML::Node privateParameters(const ros::NodeHandle& nh) {
  XmlRpc::XmlRpcValue tree;
  if (!nh.getParam(nh.getNamespace(), tree) || tree.getType() != XmlRpc::XmlRpcValue::TypeStruct) {
    return YAML::Node(YAML::NodeType::Map);
  }
  return toYaml(tree);
}

}  // namespace hrg_gyro

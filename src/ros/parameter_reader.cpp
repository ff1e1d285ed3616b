#include "hrg_gyro/ros/parameter_reader.h"

#include <ros/console.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <stdexcept>

namespace hrg_gyro {
namespace {

/// Leaf keys of an XmlRpc struct, nested maps joined with '/'.
void flatten(XmlRpc::XmlRpcValue& value, const std::string& prefix, std::vector<std::string>* out) {
  if (value.getType() != XmlRpc::XmlRpcValue::TypeStruct || value.size() == 0) {
    if (!prefix.empty()) out->push_back(prefix);
    return;
  }
  for (auto it = value.begin(); it != value.end(); ++it) {
    flatten(it->second, prefix.empty() ? it->first : prefix + "/" + it->first, out);
  }
}

/// A value for a message: the shortest form that reads back ("nan", "inf", "0.5", "60"), in
/// exponent form only for very large or small magnitudes.
std::string numberText(double v) {
  const bool exponent_ok = std::abs(v) >= 1e6 || (v != 0.0 && std::abs(v) < 1e-4);
  char text[32];
  for (int precision = 1; precision <= 17; ++precision) {
    std::snprintf(text, sizeof text, "%.*g", precision, v);
    if (std::strtod(text, nullptr) == v && (exponent_ok || std::strchr(text, 'e') == nullptr)) return text;
  }
  std::snprintf(text, sizeof text, "%.17g", v);
  return text;
}

std::string unitText(const std::string& unit) { return unit.empty() ? std::string() : " " + unit; }

}  // namespace

ParameterReader::ParameterReader(const ros::NodeHandle& private_nh, std::string node)
    : pnh_(private_nh), node_(std::move(node)) {}

void ParameterReader::note(const std::string& key, bool set) {
  read_.insert(key);
  if (!set) defaulted_.insert(key);
}

void ParameterReader::failWrongType(const std::string& key) const {
  XmlRpc::XmlRpcValue raw;
  pnh_.getParam(key, raw);
  throw std::invalid_argument(node_ + ": ~" + key + " has a value of the wrong type (" + raw.toXml() +
                              "); numbers in exponent form need a sign in YAML: 1.0e+6");
}

void ParameterReader::claim(const std::vector<std::string>& keys, bool subtree) {
  for (const std::string& key : keys) {
    if (subtree) {
      subtrees_.insert(key);
    } else {
      note(key, pnh_.hasParam(key));
    }
  }
}

std::vector<std::string> ParameterReader::unknownKeys() const {
  XmlRpc::XmlRpcValue tree;
  std::vector<std::string> keys, unknown;
  if (pnh_.getParam(pnh_.getNamespace(), tree)) flatten(tree, "", &keys);
  for (const std::string& key : keys) {
    bool known = read_.count(key) > 0;
    // A key read as a whole (a list, or a map read by getParam) covers its leaves; so does a claimed subtree.
    for (std::size_t slash = key.find('/'); !known && slash != std::string::npos; slash = key.find('/', slash + 1)) {
      const std::string head = key.substr(0, slash);
      known = read_.count(head) > 0 || subtrees_.count(head) > 0;
    }
    if (!known && subtrees_.count(key) > 0) known = true;
    if (!known) unknown.push_back(key);
  }
  return unknown;
}

void ParameterReader::failRule(const std::string& key, const std::string& rule, const std::string& value) const {
  throw std::invalid_argument(node_ + ": ~" + key + " must be " + rule + ", not " + value);
}

double ParameterReader::getPositive(const std::string& key, double fallback, const std::string& unit) {
  double v = fallback;
  if (getOptional(key, &v) && !(v > 0.0 && std::isfinite(v))) {
    failRule(key, "a positive finite number" + (unit.empty() ? std::string() : " (" + unit + ")"), numberText(v));
  }
  return v;
}

double ParameterReader::getInRange(const std::string& key, double fallback, double low, double high,
                                   const std::string& unit) {
  double v = fallback;
  if (getOptional(key, &v) && !(v >= low && v <= high && std::isfinite(v))) {
    failRule(key, "in [" + numberText(low) + ", " + numberText(high) + "]" + unitText(unit), numberText(v));
  }
  return v;
}

double ParameterReader::getFinite(const std::string& key, double fallback, const std::string& unit) {
  double v = fallback;
  if (getOptional(key, &v) && !std::isfinite(v)) {
    failRule(key, "a finite number" + (unit.empty() ? std::string() : " (" + unit + ")"), numberText(v));
  }
  return v;
}

const ros::NodeHandle& ParameterReader::checkDiagnosticPeriod() {
  double period = 1.0;
  if (getOptional("diagnostic_period", &period) && !(period > 0.0 && period <= 3600.0)) {
    failRule("diagnostic_period", "in (0, 3600] s", numberText(period));
  }
  return pnh_;
}

int ParameterReader::getAtLeast(const std::string& key, int fallback, int low, const std::string& unit) {
  int v = fallback;
  if (getOptional(key, &v) && v < low) {
    failRule(key, "at least " + std::to_string(low) + (unit.empty() ? std::string() : " (" + unit + ")"),
             std::to_string(v));
  }
  return v;
}

std::size_t ParameterReader::warnAboutUnknownKeys() const {
  const std::vector<std::string> unknown = unknownKeys();
  for (const std::string& key : unknown) {
    ROS_WARN("%s: unknown parameter %s/%s is ignored (a typo? see the node's parameter template)", node_.c_str(),
             pnh_.getNamespace().c_str(), key.c_str());
  }
  return unknown.size();
}

}  // namespace hrg_gyro

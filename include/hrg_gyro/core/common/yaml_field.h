// A YAML node together with its dotted key path, so that every validation error names the key.
//
// All configuration the core reads (parameter files, simulator scenarios, calibrator settings)
// goes through this one accessor: "scale_factor.cos[2]: expected a finite number, got 'abc'".
#pragma once

#include <yaml-cpp/yaml.h>

#include <initializer_list>
#include <stdexcept>
#include <string>
#include <vector>

namespace hrg_gyro {
namespace core {

/// A configuration value that is missing, of the wrong type or out of range. key() is the dotted
/// path of the offending entry.
class ConfigError : public std::runtime_error {
 public:
  ConfigError(const std::string& key, const std::string& problem)
      : std::runtime_error(key.empty() ? problem : key + ": " + problem), key_(key), problem_(problem) {}
  const std::string& key() const { return key_; }
  const std::string& problem() const { return problem_; }

 private:
  std::string key_;
  std::string problem_;
};

class YamlField {
 public:
  YamlField(YAML::Node node, std::string path) : node_(std::move(node)), path_(std::move(path)) {}

  const std::string& path() const { return path_; }
  const YAML::Node& node() const { return node_; }
  bool isMap() const { return node_.IsMap(); }
  bool isSequence() const { return node_.IsSequence(); }
  bool has(const std::string& key) const { return node_.IsMap() && node_[key].IsDefined() && !node_[key].IsNull(); }

  /// Required child of a map.
  YamlField operator[](const std::string& key) const;
  /// Element of a sequence.
  YamlField at(std::size_t index) const;
  std::size_t size() const { return node_.size(); }
  /// Throws unless this node is a map (with its path in the message).
  const YamlField& requireMap() const;
  const YamlField& requireSequence() const;
  /// Throws for any key not in the allowed list (catches typos such as "scale_factr") and for a key
  /// given twice in this map (yaml-cpp would silently use the first).
  void rejectUnknownKeys(std::initializer_list<const char*> allowed) const;
  void rejectUnknownKeys(const std::vector<std::string>& allowed) const;

  double asDouble() const;  ///< finite numbers only
  long asInteger() const;
  bool asBool() const;
  std::string asString() const;
  /// A sequence of finite numbers; expected_size 0 accepts any length.
  std::vector<double> asDoubles(std::size_t expected_size = 0) const;
  std::vector<long> asIntegers() const;

  // Optional forms: the default when the key is absent (or null), the checked value otherwise.
  double getDouble(const std::string& key, double fallback) const {
    return has(key) ? (*this)[key].asDouble() : fallback;
  }
  long getInteger(const std::string& key, long fallback) const {
    return has(key) ? (*this)[key].asInteger() : fallback;
  }
  bool getBool(const std::string& key, bool fallback) const { return has(key) ? (*this)[key].asBool() : fallback; }
  std::string getString(const std::string& key, const std::string& fallback) const {
    return has(key) ? (*this)[key].asString() : fallback;
  }

  [[noreturn]] void fail(const std::string& problem) const { throw ConfigError(path_, problem); }

 private:
  std::string describe() const;

  YAML::Node node_;
  std::string path_;
};

}  // namespace core
}  // namespace hrg_gyro

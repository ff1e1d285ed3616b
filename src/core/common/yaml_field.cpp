#include "hrg_gyro/core/common/yaml_field.h"

#include <cmath>
#include <cstdint>
#include <set>

namespace hrg_gyro {
namespace core {

std::string YamlField::describe() const {
  if (!node_.IsDefined() || node_.IsNull()) return "nothing";
  if (node_.IsMap()) return "a map";
  if (node_.IsSequence()) return "a list";
  std::string text = node_.Scalar();
  if (text.size() > 40) text = text.substr(0, 40) + "...";
  return "'" + text + "'";
}

YamlField YamlField::operator[](const std::string& key) const {
  requireMap();
  const std::string child = path_.empty() ? key : path_ + "." + key;
  YAML::Node n = node_[key];
  if (!n.IsDefined() || n.IsNull()) throw ConfigError(child, "missing required key");
  return YamlField(n, child);
}

YamlField YamlField::at(std::size_t index) const {
  requireSequence();
  const std::string child = path_ + "[" + std::to_string(index) + "]";
  if (index >= node_.size()) throw ConfigError(child, "index out of range");
  return YamlField(node_[index], child);
}

const YamlField& YamlField::requireMap() const {
  if (!node_.IsMap()) fail("expected a map, got " + describe());
  return *this;
}

const YamlField& YamlField::requireSequence() const {
  if (!node_.IsSequence()) fail("expected a list, got " + describe());
  return *this;
}

void YamlField::rejectUnknownKeys(std::initializer_list<const char*> allowed) const {
  rejectUnknownKeys(std::vector<std::string>(allowed.begin(), allowed.end()));
}

void YamlField::rejectUnknownKeys(const std::vector<std::string>& allowed) const {
  requireMap();
  const std::set<std::string> ok(allowed.begin(), allowed.end());
  std::set<std::string> seen;
  for (const auto& kv : node_) {
    // A key that is itself a list or a map ({a: 1}: 2) has no name to check: refuse it here rather
    // than let yaml-cpp's conversion error escape as something other than a ConfigError.
    if (!kv.first.IsScalar()) {
      fail(std::string("keys must be plain names, got ") + (kv.first.IsMap()        ? "a map"
                                                            : kv.first.IsSequence() ? "a list"
                                                                                    : "an empty key"));
    }
    const std::string key = kv.first.as<std::string>();
    if (!ok.count(key)) {
      std::string list;
      for (const auto& a : allowed) list += (list.empty() ? "" : ", ") + a;
      throw ConfigError(path_.empty() ? key : path_ + "." + key, "unknown key (allowed here: " + list + ")");
    }
    // yaml-cpp keeps every pair of a map but looks a key up to its first occurrence: a second one
    // (a pasted block, a merge gone wrong) would be ignored without a word.
    if (!seen.insert(key).second) {
      throw ConfigError(path_.empty() ? key : path_ + "." + key, "key given more than once in the same map");
    }
  }
}

double YamlField::asDouble() const {
  if (!node_.IsScalar()) fail("expected a number, got " + describe());
  double v = 0.0;
  try {
    v = node_.as<double>();
  } catch (const YAML::Exception&) {
    fail("expected a number, got " + describe());
  }
  if (!std::isfinite(v)) fail("expected a finite number, got " + describe());
  return v;
}

long YamlField::asInteger() const {
  if (!node_.IsScalar()) fail("expected an integer, got " + describe());
  try {
    return node_.as<long>();
  } catch (const YAML::Exception&) {
    fail("expected an integer, got " + describe());
  }
}

bool YamlField::asBool() const {
  if (!node_.IsScalar()) fail("expected true or false, got " + describe());
  try {
    return node_.as<bool>();
  } catch (const YAML::Exception&) {
    fail("expected true or false, got " + describe());
  }
}

namespace {

// Strict UTF-8 (no overlong forms, no surrogates, at most U+10FFFF). The emitter escapes what it
// cannot write as UTF-8, so a file with other bytes would not read back to the same text.
bool isValidUtf8(const std::string& s) {
  std::size_t i = 0;
  while (i < s.size()) {
    const unsigned char c = static_cast<unsigned char>(s[i]);
    std::size_t n = 0;
    std::uint32_t cp = 0, min = 0;
    if (c < 0x80) {
      ++i;
      continue;
    }
    if ((c & 0xE0) == 0xC0) {
      n = 1;
      cp = c & 0x1F;
      min = 0x80;
    } else if ((c & 0xF0) == 0xE0) {
      n = 2;
      cp = c & 0x0F;
      min = 0x800;
    } else if ((c & 0xF8) == 0xF0) {
      n = 3;
      cp = c & 0x07;
      min = 0x10000;
    } else
      return false;
    for (std::size_t k = 1; k <= n; ++k) {
      if (i + k >= s.size()) return false;
      const unsigned char cc = static_cast<unsigned char>(s[i + k]);
      if ((cc & 0xC0) != 0x80) return false;
      cp = (cp << 6) | (cc & 0x3F);
    }
    if (cp < min || cp > 0x10FFFF || (cp >= 0xD800 && cp <= 0xDFFF)) return false;
    i += n + 1;
  }
  return true;
}

}  // namespace

std::string YamlField::asString() const {
  if (!node_.IsScalar()) fail("expected a string, got " + describe());
  if (!isValidUtf8(node_.Scalar())) fail("text must be valid UTF-8");
  return node_.Scalar();
}

std::vector<double> YamlField::asDoubles(std::size_t expected_size) const {
  requireSequence();
  if (expected_size != 0 && node_.size() != expected_size) {
    fail("expected " + std::to_string(expected_size) + " values, got " + std::to_string(node_.size()));
  }
  std::vector<double> out;
  out.reserve(node_.size());
  for (std::size_t i = 0; i < node_.size(); ++i) out.push_back(at(i).asDouble());
  return out;
}

std::vector<long> YamlField::asIntegers() const {
  requireSequence();
  std::vector<long> out;
  for (std::size_t i = 0; i < node_.size(); ++i) out.push_back(at(i).asInteger());
  return out;
}

}  // namespace core
}  // namespace hrg_gyro

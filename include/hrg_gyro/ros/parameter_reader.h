// Reads a node's private parameters and keeps account of them, so that a typo in a launch or YAML
// file never passes silently: a key set in the node's private namespace that nothing reads is an
// unknown key (warned at start-up), and a key the node reads but nobody set falls back to its
// default (listed, so a test can prove the shipped parameter template lacks none).
//
// Parameters that a core parser reads from the private tree (calibrator settings, simulator
// scenarios) are declared with claim(): the parser checks their values and refuses unknown keys
// itself; the reader only accounts for them.
#pragma once

#include <ros/node_handle.h>

#include <set>
#include <string>
#include <vector>

namespace hrg_gyro {

class ParameterReader {
 public:
  /// `node` names the node in messages ("processor").
  ParameterReader(const ros::NodeHandle& private_nh, std::string node);

  /// ~key, or `fallback` when it is not set (then listed by defaultedKeys()).
  /// Throws std::invalid_argument when ~key is set to a value of another type (say "1.0e6",
  /// which YAML reads as text): a mistyped value must not fall back to the default silently.
  template <typename T>
  T get(const std::string& key, const T& fallback) {
    T value = fallback;
    getOptional(key, &value);
    return value;
  }
  /// ~key into *value; false (and *value untouched) when it is not set. Throws as get().
  template <typename T>
  bool getOptional(const std::string& key, T* value) {
    const bool set = pnh_.getParam(key, *value);
    if (!set && pnh_.hasParam(key)) failWrongType(key);
    note(key, set);
    return set;
  }

  // Numbers with a rule, checked at start-up: a value that breaks it (NaN, an infinity, 0 for a
  // queue, a negative period) throws std::invalid_argument naming the node, the key, the rule and
  // the value, as a core parser's ConfigError names its key; `unit` ("s", "Hz", "messages") is said
  // in the message. Unset keys take `fallback` (not checked: the node's own default).

  /// A finite number > 0.
  double getPositive(const std::string& key, double fallback, const std::string& unit);
  /// A finite number in [low, high].
  double getInRange(const std::string& key, double fallback, double low, double high, const std::string& unit);
  /// A finite number of either sign (a rule such as "<= 0: never" gives the sign its meaning).
  double getFinite(const std::string& key, double fallback, const std::string& unit);
  /// An integer >= low.
  int getAtLeast(const std::string& key, int fallback, int low, const std::string& unit);

  /// ~diagnostic_period, which diagnostic_updater::Updater reads itself when it is constructed (and
  /// again at each update): checked first, in (0, 3600] s, so that a bad one is refused naming the
  /// key (the updater would throw an unnamed "Duration is out of dual 32-bit range" on NaN or inf,
  /// and publish at every chance on 0). Returns the private handle to construct the updater with.
  const ros::NodeHandle& checkDiagnosticPeriod();

  /// Keys read by someone else (a core parser, diagnostic_updater): "a/b" names a leaf, and with
  /// `subtree` every key below it counts as read (a section whose keys the parser checks itself).
  void claim(const std::vector<std::string>& keys, bool subtree = false);

  /// Keys set under the private namespace ("a/b" for nested maps) that nothing read or claimed.
  std::vector<std::string> unknownKeys() const;
  /// Keys read or claimed as leaves that were not set: their defaults are in force.
  std::vector<std::string> defaultedKeys() const { return {defaulted_.begin(), defaulted_.end()}; }
  /// Every key read or claimed as a leaf.
  std::vector<std::string> readKeys() const { return {read_.begin(), read_.end()}; }

  /// One warning per unknown key (a typo must not pass silently); returns how many.
  std::size_t warnAboutUnknownKeys() const;

 private:
  void note(const std::string& key, bool set);
  [[noreturn]] void failWrongType(const std::string& key) const;
  [[noreturn]] void failRule(const std::string& key, const std::string& rule, const std::string& value) const;

  ros::NodeHandle pnh_;
  std::string node_;
  std::set<std::string> read_, subtrees_, defaulted_;
};

}  // namespace hrg_gyro

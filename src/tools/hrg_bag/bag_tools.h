// Shared plumbing of the hrg_bag subcommands: arguments, opening bags with clear errors, finding
// the gyro topics by type, progress on stderr, and the replay of a bag's channels through the
// same core::GyroProcessor the processor node runs.
#pragma once

#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include <rosbag/bag.h>
#include <rosbag/view.h>

#include "hrg_gyro/ChannelAmplitudes.h"
#include "hrg_gyro/core/gyro_processor.h"

namespace hrg_gyro {
namespace bag_tools {

/// A usage or input error: message printed, exit code 2.
struct UsageError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

/// "--key value" options, "--flag" switches and positional arguments.
class Args {
 public:
  /// `valued` and `flags` list the accepted options (without "--"); anything else is refused.
  Args(int argc, char** argv, const std::vector<std::string>& valued, const std::vector<std::string>& flags);
  bool help() const { return help_; }
  bool has(const std::string& key) const { return values_.count(key) > 0; }
  std::string get(const std::string& key, const std::string& fallback = "") const;
  std::string require(const std::string& key) const;
  double getDouble(const std::string& key, double fallback) const;
  bool flag(const std::string& name) const { return flags_.count(name) > 0; }
  const std::vector<std::string>& positional() const { return positional_; }

 private:
  std::map<std::string, std::string> values_;
  std::map<std::string, bool> flags_;
  std::vector<std::string> positional_;
  bool help_ = false;
};

/// Opens a bag for reading; missing, unindexed, truncated or corrupt files become UsageErrors
/// that say which.
std::unique_ptr<rosbag::Bag> openBag(const std::string& path);

/// The topics of the gyro in a bag. Explicit options win; otherwise the single topic of the right
/// type is taken. Throws UsageError when a required topic is missing, ambiguous or of the wrong type.
struct GyroTopics {
  std::string channels, turntable, truth;
};
GyroTopics findTopics(const rosbag::Bag& bag, const Args& args, bool need_channels, bool need_turntable);

/// Percentage and rate on stderr, at most twice a second.
class Progress {
 public:
  Progress(std::string what, double total);
  void update(double done, std::uint64_t items);
  void finish(std::uint64_t items);

 private:
  std::string what_;
  double total_;
  double start_, last_;
  double last_percent_ = -1.0;
  bool tty_;
};

/// The processor's limits from command-line options (the node's parameter names and defaults).
core::ProcessorConfig processorConfig(const Args& args);
extern const std::vector<std::string> kProcessorOptions;

/// Opens `path` for writing with the chunk compression named by --compression (none, lz4, bz2;
/// default lz4: readers then decompress whole chunks instead of seeking for every message).
std::unique_ptr<rosbag::Bag> createBag(const std::string& path, const Args& args);

/// Replays the channels topic of `bag` in record order through `processor`, calling `sink` with
/// every input message and its result.
std::uint64_t replayChannels(const rosbag::Bag& bag, const std::string& topic, core::GyroProcessor& processor,
                             const std::function<void(const ChannelAmplitudes&, const core::ProcessorResult&)>& sink,
                             const std::string& progress_label);

/// Runs scripts/plot_calibration.py (found through the package path) without a shell.
int runPlotter(const std::vector<std::string>& arguments);

}  // namespace bag_tools
}  // namespace hrg_gyro

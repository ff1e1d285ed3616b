#include "bag_tools.h"

#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>

#include <ros/package.h>
#include <rosbag/exceptions.h>

#include "hrg_gyro/GroundTruth.h"
#include "hrg_gyro/TurntableState.h"
#include "hrg_gyro/ros/conversions.h"

namespace hrg_gyro {
namespace bag_tools {
namespace {

double now() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

}  // namespace

Args::Args(int argc, char** argv, const std::vector<std::string>& valued, const std::vector<std::string>& flags) {
  for (int i = 0; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "-h" || a == "--help") {
      help_ = true;
    } else if (a.rfind("--", 0) == 0) {
      const std::string key = a.substr(2);
      if (std::find(flags.begin(), flags.end(), key) != flags.end()) {
        flags_[key] = true;
      } else if (std::find(valued.begin(), valued.end(), key) != valued.end()) {
        if (i + 1 >= argc) throw UsageError("option --" + key + " needs a value");
        values_[key] = argv[++i];
      } else {
        throw UsageError("unknown option " + a);
      }
    } else {
      positional_.push_back(a);
    }
  }
}

std::string Args::get(const std::string& key, const std::string& fallback) const {
  const auto it = values_.find(key);
  return it == values_.end() ? fallback : it->second;
}

std::string Args::require(const std::string& key) const {
  if (!has(key)) throw UsageError("option --" + key + " is required");
  return get(key);
}

double Args::getDouble(const std::string& key, double fallback) const {
  if (!has(key)) return fallback;
  try {
    std::size_t used = 0;
    const double v = std::stod(get(key), &used);
    if (used != get(key).size() || !std::isfinite(v)) throw std::invalid_argument("");
    return v;
  } catch (const std::exception&) {
    throw UsageError("option --" + key + " expects a number, got '" + get(key) + "'");
  }
}

std::unique_ptr<rosbag::Bag> createBag(const std::string& path, const Args& args) {
  const std::string name = args.get("compression", "lz4");
  rosbag::compression::CompressionType type;
  if (name == "none") {
    type = rosbag::compression::Uncompressed;
  } else if (name == "lz4") {
    type = rosbag::compression::LZ4;
  } else if (name == "bz2") {
    type = rosbag::compression::BZ2;
  } else {
    throw UsageError("--compression must be none, lz4 or bz2, got '" + name + "'");
  }
  auto bag = std::make_unique<rosbag::Bag>();
  try {
    bag->open(path, rosbag::bagmode::Write);
  } catch (const rosbag::BagException& e) {
    throw UsageError("cannot write " + path + ": " + e.what());
  }
  bag->setCompression(type);
  return bag;
}

std::unique_ptr<rosbag::Bag> openBag(const std::string& path) {
  std::ifstream probe(path, std::ios::binary);
  if (!probe) throw UsageError("cannot read bag '" + path + "' (missing or unreadable)");
  auto bag = std::make_unique<rosbag::Bag>();
  try {
    bag->open(path, rosbag::bagmode::Read);
  } catch (const rosbag::BagUnindexedException&) {
    throw UsageError("bag '" + path + "' is unindexed (recording interrupted?): run `rosbag reindex` on a copy");
  } catch (const rosbag::BagFormatException& e) {
    throw UsageError("bag '" + path + "' is truncated or corrupt: " + e.what());
  } catch (const rosbag::BagIOException& e) {
    // The header points at an index past the end of the file: cut short after it was closed.
    throw UsageError("bag '" + path + "' is truncated or unindexed (copy cut short?): run `rosbag reindex` on a copy (" +
                     e.what() + ")");
  } catch (const rosbag::BagException& e) {
    throw UsageError("cannot open bag '" + path + "': " + e.what());
  }
  return bag;
}

GyroTopics findTopics(const rosbag::Bag& bag, const Args& args, bool need_channels, bool need_turntable) {
  rosbag::View all(bag);
  std::map<std::string, std::string> types;
  for (const rosbag::ConnectionInfo* c : all.getConnections()) types[c->topic] = c->datatype;
  auto pick = [&](const std::string& option, const std::string& type, bool required) {
    if (args.has(option)) {
      const std::string topic = args.get(option);
      const auto it = types.find(topic);
      if (it == types.end()) throw UsageError("topic " + topic + " (--" + option + ") is not in the bag");
      if (it->second != type) throw UsageError("topic " + topic + " has type " + it->second + ", expected " + type);
      return topic;
    }
    std::vector<std::string> found;
    for (const auto& kv : types) {
      if (kv.second == type) found.push_back(kv.first);
    }
    if (found.size() > 1) {
      throw UsageError("several " + type + " topics in the bag; choose one with --" + option);
    }
    if (found.empty()) {
      if (required) {
        std::string listing;
        for (const auto& kv : types) listing += "\n  " + kv.first + " [" + kv.second + "]";
        throw UsageError("no " + type + " topic in the bag; it holds:" + (listing.empty() ? " nothing" : listing));
      }
      return std::string();
    }
    return found.front();
  };
  GyroTopics t;
  t.channels = pick("channels-topic", ros::message_traits::datatype<ChannelAmplitudes>(), need_channels);
  t.turntable = pick("turntable-topic", ros::message_traits::datatype<TurntableState>(), need_turntable);
  t.truth = pick("truth-topic", ros::message_traits::datatype<GroundTruth>(), false);
  return t;
}

Progress::Progress(std::string what, double total)
    : what_(std::move(what)), total_(total), start_(now()), last_(0), tty_(::isatty(2) != 0) {}

void Progress::update(double done, std::uint64_t items) {
  const double t = now();
  if (t - last_ < 0.5) return;
  const double percent = total_ > 0 ? 100.0 * std::min(1.0, done / total_) : 0.0;
  // On a terminal, one line updated in place; in a log, a line per 10 %.
  if (!tty_ && std::floor(percent / 10.0) <= std::floor(last_percent_ / 10.0)) return;
  last_ = t;
  last_percent_ = percent;
  const double rate = items / std::max(1e-9, t - start_);
  std::fprintf(stderr, tty_ ? "\r%s: %5.1f %% (%.0f samples/s)   " : "%s: %5.1f %% (%.0f samples/s)\n",
               what_.c_str(), percent, rate);
  std::fflush(stderr);
}

void Progress::finish(std::uint64_t items) {
  const double dt = now() - start_;
  std::fprintf(stderr, "%s%s: done, %lu samples in %.2f s (%.0f samples/s)\n", tty_ ? "\r" : "", what_.c_str(),
               static_cast<unsigned long>(items), dt, items / std::max(1e-9, dt));
}

const std::vector<std::string> kProcessorOptions = {"max-gap", "backward-reset", "max-rate", "min-anisotropy",
                                                    "min-amplitude", "max-amplitude"};

core::ProcessorConfig processorConfig(const Args& args) {
  core::ProcessorConfig c;
  c.max_gap = args.getDouble("max-gap", c.max_gap);
  c.backward_reset = args.getDouble("backward-reset", c.backward_reset);
  c.max_rate = args.getDouble("max-rate", c.max_rate);
  c.limits.min_anisotropy = args.getDouble("min-anisotropy", c.limits.min_anisotropy);
  c.limits.min_amplitude = args.getDouble("min-amplitude", c.limits.min_amplitude);
  c.limits.max_amplitude = args.getDouble("max-amplitude", c.limits.max_amplitude);
  return c;
}

std::uint64_t replayChannels(const rosbag::Bag& bag, const std::string& topic, core::GyroProcessor& processor,
                             const std::function<void(const ChannelAmplitudes&, const core::ProcessorResult&)>& sink,
                             const std::string& progress_label) {
  rosbag::View view(bag, rosbag::TopicQuery(topic));
  Progress progress(progress_label, view.size());
  std::uint64_t n = 0;
  try {
    for (const rosbag::MessageInstance& m : view) {
      const ChannelAmplitudes::ConstPtr msg = m.instantiate<ChannelAmplitudes>();
      if (!msg) continue;
      sink(*msg, processor.process(fromMessage(*msg)));
      ++n;
      progress.update(n, n);
    }
  } catch (const rosbag::BagException& e) {
    throw UsageError(std::string("bag read error after ") + std::to_string(n) + " samples (truncated?): " + e.what());
  }
  progress.finish(n);
  return n;
}

namespace {

/// plot_calibration.py is installed beside hrg_bag (lib/hrg_gyro, devel and install space alike);
/// a source checkout without that copy falls back to the package's scripts/.
std::string plotScript() {
  char self[4096];
  const ssize_t n = ::readlink("/proc/self/exe", self, sizeof self - 1);
  if (n > 0) {
    std::string dir(self, static_cast<std::size_t>(n));
    dir.erase(dir.find_last_of('/') + 1);
    const std::string beside = dir + "plot_calibration.py";
    if (::access(beside.c_str(), R_OK) == 0) return beside;
  }
  return ros::package::getPath("hrg_gyro") + "/scripts/plot_calibration.py";
}

}  // namespace

int runPlotter(const std::vector<std::string>& arguments) {
  const std::string script = plotScript();
  std::vector<std::string> argv_s{"/usr/bin/python3", script};
  argv_s.insert(argv_s.end(), arguments.begin(), arguments.end());
  std::vector<char*> argv;
  for (std::string& a : argv_s) argv.push_back(a.data());
  argv.push_back(nullptr);
  const pid_t pid = ::fork();
  if (pid < 0) return -1;
  if (pid == 0) {
    ::execv(argv[0], argv.data());  // no shell: arguments are passed as they are
    _exit(127);
  }
  int status = 0;
  ::waitpid(pid, &status, 0);
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

}  // namespace bag_tools
}  // namespace hrg_gyro

#include "bag_tools.h"

#include <ros/names.h>
#include <ros/package.h>
#include <rosbag/exceptions.h>
#include <sys/stat.h>
#include <sys/statvfs.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cctype>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>

#include "../cli_checks.h"
#include "hrg_gyro/GroundTruth.h"
#include "hrg_gyro/TurntableState.h"
#include "hrg_gyro/core/common/output_directory.h"
#include "hrg_gyro/core/common/yaml_field.h"
#include "hrg_gyro/ros/conversions.h"
#include "read_messages.h"
#include "reused_message_reader.h"
#include "serial_worker.h"

namespace hrg_gyro {
namespace bag_tools {
namespace {

double now() { return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count(); }

}  // namespace

void addCompressionOption(CLI::App& command, std::string* compression) {
  command.add_option("--compression", *compression, "chunk compression of the written bag")
      ->check(CLI::IsMember({"none", "lz4", "bz2"}))
      ->capture_default_str();
}

namespace {

BagFileWriter::Compression compressionType(const std::string& name) {
  if (name == "none") return BagFileWriter::Compression::kNone;
  if (name == "lz4") return BagFileWriter::Compression::kLz4;
  if (name == "bz2") return BagFileWriter::Compression::kBz2;
  throw UsageError("--compression must be none, lz4 or bz2, got '" + name + "'");
}

core::AtomicOutputFile& openOutput(std::unique_ptr<core::AtomicOutputFile>* file, const std::string& path,
                                   const core::OutputFileOptions& options = {}) {
  try {
    *file = std::make_unique<core::AtomicOutputFile>(path, options);
  } catch (const std::exception& e) {
    throw OutputError(std::string("cannot write ") + path + ": " + e.what());
  }
  return **file;
}

}  // namespace

void checkDistinctAxisTopics(const std::array<std::string, 3>& axes, const std::array<std::string, 3>& topics) {
  for (std::size_t i = 0; i < 3; ++i) {
    for (std::size_t j = i + 1; j < 3; ++j) {
      if (topics[i] != topics[j]) continue;
      throw UsageError("axes " + axes[i] + " and " + axes[j] + " both read the channels topic " + topics[i] +
                       " (--axis-channels): each axis needs its own, /NAME/channels by default");
    }
  }
}

void checkOutputPaths(const std::vector<std::string>& inputs, const std::vector<std::string>& outputs) {
  std::vector<std::string> given_inputs, given_outputs;
  for (const std::string& p : inputs) {
    if (!p.empty()) given_inputs.push_back(p);
  }
  for (const std::string& p : outputs) {
    if (p.empty()) continue;
    given_outputs.push_back(p);
    struct stat st {};
    if (::stat(p.c_str(), &st) == 0 && !S_ISREG(st.st_mode)) {
      throw UsageError("output '" + p + "' " + (S_ISDIR(st.st_mode) ? "is a directory" : "is not a regular file") +
                       ": give a file name");
    }
  }
  try {
    core::checkDistinct(given_inputs, given_outputs);
  } catch (const std::runtime_error& e) {
    throw UsageError(std::string("refused: ") + e.what());
  }
}

OutputBag::OutputBag(const std::string& path, const std::string& compression) : path_(path) {
  const BagFileWriter::Compression type = compressionType(compression);
  openOutput(&file_, path);
  try {
    // The writer truncates and rewrites the temporary in place; file_ renames it on commit.
    bag_ = std::make_unique<BagFileWriter>(file_->temporaryPath(), type);
  } catch (const BagWriteError& e) {
    failed(e.what(), e.error);
  }
}

OutputBag::~OutputBag() { abandon(); }

void OutputBag::abandon() noexcept { bag_.reset(); }

void OutputBag::failed(const std::string& why, int error) {
  // A full file system is the usual reason of a failed write; say it even when errno was lost.
  std::string reason = why;
  struct statvfs fs {};
  const bool nearly_full = ::statvfs(core::directoryOf(file_->targetPath()).c_str(), &fs) == 0 &&
                           static_cast<double>(fs.f_bavail) * fs.f_frsize < 1024.0 * 1024.0;
  if (error == ENOSPC || error == EDQUOT || nearly_full) {
    reason += std::string(": ") + std::strerror(error == EDQUOT ? EDQUOT : ENOSPC);
  } else if (error != 0) {
    reason += std::string(" (") + std::strerror(error) + ")";
  }
  abandon();
  file_->discard();
  throw OutputError("cannot write " + path_ + ": " + reason + " (nothing written" +
                    (::access(path_.c_str(), F_OK) == 0 ? "; the existing file is unchanged)" : ")"));
}

void OutputBag::commit() {
  try {
    bag_->close();  // writes the index; a full disk shows here at the latest
    bag_.reset();
  } catch (const BagWriteError& e) {
    failed(e.what(), e.error);
  }
  try {
    file_->commit();
  } catch (const std::exception& e) {
    throw OutputError(e.what());
  }
}

OutputText::OutputText(const std::string& path) : path_(path) {
  core::OutputFileOptions options;
  options.direct_io = true;  // CSV files of a long session run to gigabytes
  openOutput(&file_, path, options);
}

void OutputText::commit() {
  try {
    file_->commit();
  } catch (const std::exception& e) {
    throw OutputError(e.what());
  }
}

namespace {

/// `text` with every `from` replaced by `to` (rosbag's messages name the file it opened).
std::string replaceAll(std::string text, const std::string& from, const std::string& to) {
  for (std::size_t at = text.find(from); at != std::string::npos; at = text.find(from, at + to.size())) {
    text.replace(at, from.size(), to);
  }
  return text;
}

}  // namespace

std::unique_ptr<rosbag::Bag> openBag(const std::string& path) {
  int fd = -1;
  try {
    fd = core::openRegularFileForReading(path, "bag");  // a FIFO would block rosbag's open forever
  } catch (const std::runtime_error& e) {
    throw UsageError(e.what());
  }
  struct Closer {
    int fd;
    ~Closer() { ::close(fd); }
  } closer{fd};
  // rosbag opens by name. /proc/self/fd/N names the very file just checked, so a path swapped for a
  // FIFO since cannot make it block; without /proc the checked path is the next best thing.
  const std::string checked = "/proc/self/fd/" + std::to_string(fd);
  const std::string name = ::access(checked.c_str(), R_OK) == 0 ? checked : path;
  auto bag = std::make_unique<rosbag::Bag>();
  auto why = [&](const rosbag::BagException& e) { return replaceAll(e.what(), name, path); };
  try {
    bag->open(name, rosbag::bagmode::Read);
  } catch (const rosbag::BagUnindexedException&) {
    throw UsageError("bag '" + path + "' is unindexed (recording interrupted?): run `rosbag reindex` on a copy");
  } catch (const rosbag::BagFormatException& e) {
    throw UsageError("bag '" + path + "' is truncated or corrupt: " + why(e));
  } catch (const rosbag::BagIOException& e) {
    // The header points at an index past the end of the file: cut short after it was closed.
    throw UsageError("bag '" + path +
                     "' is truncated or unindexed (copy cut short?): run `rosbag reindex` on a copy (" + why(e) + ")");
  } catch (const rosbag::BagException& e) {
    throw UsageError("cannot open bag '" + path + "': " + why(e));
  }
  return bag;
}

CLI::Validator topicName() {
  return CLI::Validator(
      [](std::string& text) -> std::string {
        std::string why;
        if (text.empty()) return "must not be empty";
        if (!ros::names::validate(text, why)) {
          return "is not a ROS topic name: a letter or '/' first, then only letters, digits, '_' and '/'";
        }
        if (text.front() != '/') return "must be a global name, starting with '/' (as rosbag record writes topics)";
        if (text.size() == 1 || ros::names::clean(text) != text) return "must not hold '//' or end with '/'";
        return "";
      },
      "");
}

void addTopicOptions(CLI::App& command, GyroTopics* chosen, bool turntable_and_truth) {
  command
      .add_option("--channels-topic", chosen->channels,
                  "hrg_gyro/ChannelAmplitudes topic (default: the only one in the bag)")
      ->check(tools::notEmpty());
  if (!turntable_and_truth) return;
  command
      .add_option("--turntable-topic", chosen->turntable,
                  "hrg_gyro/TurntableState topic (default: the only one in the bag)")
      ->check(tools::notEmpty());
  command.add_option("--truth-topic", chosen->truth, "hrg_gyro/GroundTruth topic (default: the only one in the bag)")
      ->check(tools::notEmpty());
}

namespace {

/// Each topic of the bag with its type.
std::map<std::string, std::string> topicTypes(const rosbag::Bag& bag) {
  rosbag::View all(bag);
  std::map<std::string, std::string> types;
  for (const rosbag::ConnectionInfo* c : all.getConnections()) types[c->topic] = c->datatype;
  return types;
}

/// findTopic among `types`.
std::string findTopicOfType(const std::map<std::string, std::string>& types, const std::string& chosen,
                            const std::string& type, const std::string& option, bool required,
                            const std::string& missing_hint) {
  if (!chosen.empty()) {
    const auto it = types.find(chosen);
    if (it == types.end()) throw UsageError("topic " + chosen + " (--" + option + ") is not in the bag");
    if (it->second != type) throw UsageError("topic " + chosen + " has type " + it->second + ", expected " + type);
    return chosen;
  }
  std::vector<std::string> found;
  for (const auto& kv : types) {
    if (kv.second == type) found.push_back(kv.first);
  }
  if (found.size() > 1) throw UsageError("several " + type + " topics in the bag; choose one with --" + option);
  if (!found.empty()) return found.front();
  if (required) {
    std::string listing;
    for (const auto& kv : types) listing += "\n  " + kv.first + " [" + kv.second + "]";
    throw UsageError("no " + type + " topic in the bag" + missing_hint +
                     "; it holds:" + (listing.empty() ? " nothing" : listing));
  }
  return std::string();
}

}  // namespace

std::string findTopic(const rosbag::Bag& bag, const std::string& chosen, const std::string& type,
                      const std::string& option, bool required, const std::string& missing_hint) {
  return findTopicOfType(topicTypes(bag), chosen, type, option, required, missing_hint);
}

[[noreturn]] void rethrowBagReadError(std::uint64_t samples) {
  try {
    throw;
  } catch (const rosbag::BagException& e) {
    throw UsageError(std::string("bag read error after ") + std::to_string(samples) +
                     " samples (truncated?): " + e.what());
  } catch (const ros::serialization::StreamOverrunException& e) {
    throw UsageError(std::string("bag read error after ") + std::to_string(samples) +
                     " samples: a message shorter than its type (corrupt?): " + e.what());
  }
}

GyroTopics findTopics(const rosbag::Bag& bag, const GyroTopics& chosen, bool need_channels, bool need_turntable,
                      TopicNeed precession) {
  const std::map<std::string, std::string> types = topicTypes(bag);
  const auto pick = [&](const std::string& topic, const std::string& option, const std::string& type, bool required) {
    return findTopicOfType(types, topic, type, option, required, std::string());
  };
  GyroTopics t;
  t.channels =
      pick(chosen.channels, "channels-topic", ros::message_traits::datatype<ChannelAmplitudes>(), need_channels);
  t.turntable =
      pick(chosen.turntable, "turntable-topic", ros::message_traits::datatype<TurntableState>(), need_turntable);
  t.truth = pick(chosen.truth, "truth-topic", ros::message_traits::datatype<GroundTruth>(), false);
  if (precession != TopicNeed::kNo) {
    t.precession = pick(chosen.precession, "precession-topic", ros::message_traits::datatype<PrecessionState>(),
                        precession == TopicNeed::kRequired);
  }
  return t;
}

namespace {

// The MD5 sum of hrg_gyro/PrecessionState before `source` was appended (header, rate, angle,
// commands): the same bytes up to where `source` begins.
constexpr const char* kPrecessionStateWithoutSourceMd5 = "a072295d8b564159c1f704b73deafe65";

}  // namespace

struct PrecessionStateReader::Impl {
  ReusedMessageReader<PrecessionState> current;
  std::vector<std::uint8_t> bytes;
  const std::string* checked_md5sum = nullptr;
  bool legacy = false;
  // The output-stream interface rosbag::MessageInstance::write fills.
  std::uint8_t* advance(std::uint32_t length) {
    const std::size_t at = bytes.size();
    bytes.resize(at + length);
    return bytes.data() + at;
  }
};

PrecessionStateReader::PrecessionStateReader() : impl_(std::make_unique<Impl>()) {}
PrecessionStateReader::~PrecessionStateReader() = default;

bool PrecessionStateReader::read(const rosbag::MessageInstance& instance, PrecessionState* message) {
  Impl& d = *impl_;
  const std::string& md5sum = instance.getMD5Sum();
  if (&md5sum != d.checked_md5sum) {
    d.checked_md5sum = &md5sum;
    d.legacy = md5sum == kPrecessionStateWithoutSourceMd5;
  }
  if (!d.legacy) return d.current.read(instance, message);
  d.bytes.clear();
  instance.write(d);
  ros::serialization::IStream stream(d.bytes.data(), static_cast<std::uint32_t>(d.bytes.size()));
  stream.next(message->header);
  stream.next(message->rate);
  stream.next(message->angle);
  stream.next(message->commands);
  message->source.clear();
  return true;
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
  std::fprintf(stderr, tty_ ? "\r%s: %5.1f %% (%.0f samples/s)   " : "%s: %5.1f %% (%.0f samples/s)\n", what_.c_str(),
               percent, rate);
  std::fflush(stderr);
}

void Progress::finish(std::uint64_t items) {
  const double dt = now() - start_;
  std::fprintf(stderr, "%s%s: done, %lu samples in %.2f s (%.0f samples/s)\n", tty_ ? "\r" : "", what_.c_str(),
               static_cast<unsigned long>(items), dt, items / std::max(1e-9, dt));
}

void addProcessorOptions(CLI::App& command, core::ProcessorConfig* c) {
  const std::string group = "Processor limits (the processor node's parameters; same rules)";
  auto number = [&](const char* name, double* value, const char* meaning) {
    command.add_option(name, *value, meaning)->transform(tools::finiteNumber())->capture_default_str()->group(group);
  };
  number("--max-gap", &c->max_gap,
         "s, > 0: a forward stamp step above this is a jump: a dropped glitch, or (persisting) a gap not integrated "
         "across");
  number("--backward-reset", &c->backward_reset,
         "s, > 0: a backward stamp step above this is a jump: a dropped glitch, or (persisting) a reset");
  command.add_option("--jump-persist", c->jump_persist, "samples in a row, in [1, 1000], that make a stamp jump real")
      ->capture_default_str()
      ->group(group);
  number("--max-rate", &c->max_rate, "rad/s, > 0: body rate above which a wave-angle step is a glitch");
  number("--min-anisotropy", &c->limits.min_anisotropy,
         "in (0, 1): floor of (A^2 - B^2)/(A^2 + B^2); a rounder wave is rejected");
  number("--min-amplitude", &c->limits.min_amplitude, "amplitude units, >= 0: smaller wave amplitudes are rejected");
  number("--max-amplitude", &c->limits.max_amplitude,
         "amplitude units, > --min-amplitude: larger wave amplitudes are rejected");
}

void checkProcessorConfig(const core::ProcessorConfig& config) {
  try {
    core::validate(config);
  } catch (const core::ConfigError& e) {
    // The core names the node's parameters (max_gap); here they are options (--max-gap).
    auto option = [](std::string key) {
      std::replace(key.begin(), key.end(), '_', '-');
      return "--" + key;
    };
    std::string problem = e.problem();
    for (const char* key : {"min_amplitude", "max_amplitude"}) {
      const std::size_t at = problem.find(key);
      if (at != std::string::npos) problem.replace(at, std::string(key).size(), option(key));
    }
    throw UsageError(option(e.key()) + ": " + problem);
  }
}

namespace {

// A run of input messages on its way from the reader to the processor and the sink.
struct ReplayBlock {
  static constexpr std::size_t kSize = 4096;
  std::vector<ChannelAmplitudes> messages = std::vector<ChannelAmplitudes>(kSize);
  std::vector<core::ChannelSample> samples = std::vector<core::ChannelSample>(kSize);
  std::vector<core::ProcessorResult> results = std::vector<core::ProcessorResult>(kSize);
  std::size_t count = 0;
  // Precession states read among these messages: each goes to the sink before message `before[i]`
  // (count: after the last). Reused from block to block.
  std::vector<PrecessionState> states;
  std::vector<std::size_t> before;
  std::size_t state_count = 0;
};

}  // namespace

std::uint64_t replayChannels(const rosbag::Bag& bag, const std::string& topic, core::GyroProcessor& processor,
                             const std::function<void(const ChannelAmplitudes&, const core::ProcessorResult&)>& sink,
                             const std::string& progress_label, const std::string& precession_topic,
                             const std::function<void(const PrecessionState&)>& state_sink) {
  std::vector<std::string> topics{topic};
  if (!precession_topic.empty()) topics.push_back(precession_topic);
  rosbag::View view(bag, rosbag::TopicQuery(topics));
  Progress progress(progress_label, view.size());
  // Two stages on two threads: this one reads the bag (the part no faster way of the rosbag API
  // avoids) into blocks of reused messages; the worker processes each block with processBatch (bit
  // for bit one process() per sample, in order) and hands every result to the sink. A ring of three
  // blocks: with at most one block waiting for the worker, the block being filled is never one the
  // worker still reads (the one before the waiting one has finished when submit returns).
  std::array<ReplayBlock, 3> blocks;
  SerialWorker worker(1);  // declared after the blocks: stopped before they go
  const auto submit = [&](ReplayBlock* block) {
    worker.submit([block, &processor, &sink, &state_sink] {
      for (std::size_t i = 0; i < block->count; ++i) block->samples[i] = fromMessage(block->messages[i]);
      processor.processBatch(block->samples.data(), block->count, block->results.data());
      std::size_t state = 0;
      for (std::size_t i = 0; i < block->count; ++i) {
        for (; state < block->state_count && block->before[state] == i; ++state) state_sink(block->states[state]);
        sink(block->messages[i], block->results[i]);
      }
      for (; state < block->state_count; ++state) state_sink(block->states[state]);
    });
  };
  ReusedMessageReader<ChannelAmplitudes> reader;
  PrecessionStateReader state_reader;
  std::size_t filling = 0;
  std::uint64_t n = 0;  // channel messages
  readMessages(view, progress, [&](const rosbag::MessageInstance& m) {
    ReplayBlock& block = blocks[filling];
    if (!precession_topic.empty() && m.getTopic() == precession_topic) {
      if (block.state_count == block.states.size()) {
        block.states.emplace_back();
        block.before.push_back(0);
      }
      if (!state_reader.read(m, &block.states[block.state_count])) return;
      block.before[block.state_count++] = block.count;
      return;
    }
    if (!reader.read(m, &block.messages[block.count])) return;
    ++n;
    if (++block.count == ReplayBlock::kSize) {
      submit(&block);
      filling = (filling + 1) % blocks.size();
      blocks[filling].count = 0;
      blocks[filling].state_count = 0;
    }
  });
  if (blocks[filling].count > 0 || blocks[filling].state_count > 0) submit(&blocks[filling]);
  worker.finish();  // rethrows what the processing or the sink threw
  progress.finish(n);
  return n;
}

std::string packageScript(const std::string& name) {
  char self[4096];
  const ssize_t n = ::readlink("/proc/self/exe", self, sizeof self - 1);
  if (n > 0) {
    std::string dir(self, static_cast<std::size_t>(n));
    dir.erase(dir.find_last_of('/') + 1);
    const std::string beside = dir + name;
    if (::access(beside.c_str(), R_OK) == 0) return beside;
  }
  return ros::package::getPath("hrg_gyro") + "/scripts/" + name;
}

namespace {

int runPlotter(const std::vector<std::string>& arguments) {
  const std::string script = packageScript("plot_calibration.py");
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

/// The extension of `path` (".png"), which the plotter reads to choose the image format; ".png"
/// when there is none fit for a temporary's name.
std::string imageExtension(const std::string& path) {
  const std::size_t dot = path.find_last_of('.'), slash = path.find_last_of('/');
  if (dot == std::string::npos || (slash != std::string::npos && dot < slash)) return ".png";
  const std::string extension = path.substr(dot);
  const bool plain =
      extension.size() >= 2 && extension.size() <= 8 &&
      std::all_of(extension.begin() + 1, extension.end(), [](unsigned char c) { return std::isalnum(c) != 0; });
  return plain ? extension : ".png";
}

}  // namespace

void plot(const std::string& kind, const std::string& input, const std::string& png) {
  core::OutputFileOptions options;
  options.temporary_suffix = imageExtension(png);
  std::unique_ptr<core::AtomicOutputFile> file;
  openOutput(&file, png, options);
  if (runPlotter({kind, input, file->temporaryPath()}) != 0) {
    throw OutputError("plot " + png + " not written: the plotter failed (is python3-matplotlib installed?)");
  }
  try {
    file->commit([&](const std::string& temporary) {
      struct stat st {};
      if (::stat(temporary.c_str(), &st) != 0 || st.st_size == 0) throw std::runtime_error("the plotter wrote nothing");
    });
  } catch (const std::exception& e) {
    throw OutputError("plot " + png + " not written: " + e.what());
  }
}

}  // namespace bag_tools
}  // namespace hrg_gyro

// Shared plumbing of the hrg_bag subcommands: their common options, opening bags with clear errors, finding
// the gyro topics by type, progress on stderr, and the replay of a bag's channels through the
// same core::GyroProcessor the processor node runs.
#pragma once

#include <rosbag/bag.h>
#include <rosbag/view.h>

#include <CLI/CLI.hpp>
#include <array>
#include <cerrno>
#include <cstdint>
#include <functional>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "bag_file_writer.h"
#include "hrg_gyro/ChannelAmplitudes.h"
#include "hrg_gyro/PrecessionState.h"
#include "hrg_gyro/core/common/atomic_file.h"
#include "hrg_gyro/core/processing/gyro_processor.h"

namespace hrg_gyro {
namespace bag_tools {

/// A usage or input error: message printed, exit code 2.
struct UsageError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

/// An output that could not be written (a full disk, a write or rename error, a plotter that
/// failed): message printed, exit code 3. Nothing is left at the output's path; a file that was
/// there before is unchanged.
struct OutputError : std::runtime_error {
  using std::runtime_error::runtime_error;
};
constexpr int kExitOutputError = 3;

/// One subcommand, run after its options have been parsed into the state it holds. Returns the
/// exit code.
using Command = std::function<int()>;

/// The subcommands; each adds itself (options, help) to the hrg_bag command line.
Command addSimulateCommand(CLI::App& root);
Command addInfoCommand(CLI::App& root);
Command addProcessCommand(CLI::App& root);
Command addCalibrateCommand(CLI::App& root);
Command addAllanCommand(CLI::App& root);
/// report and batch: the HTML report and the campaign, run by the Python scripts beside hrg_bag.
Command addReportCommand(CLI::App& root);
Command addBatchCommand(CLI::App& root);
Command addImportCommand(CLI::App& root);
Command addExportCommand(CLI::App& root);
/// align: north-finding from a recorded session (the gyrocompass offline).
Command addAlignCommand(CLI::App& root);

/// Opens a bag for reading; missing, unindexed, truncated or corrupt files become UsageErrors
/// that say which.
std::unique_ptr<rosbag::Bag> openBag(const std::string& path);

/// The topics of the gyro in a bag (also the --channels-topic, --turntable-topic and --truth-topic
/// options: empty means "the single topic of the right type").
struct GyroTopics {
  std::string channels, turntable, truth;
  std::string precession;  ///< hrg_gyro/PrecessionState: the field method's stand-in for the turntable
};
/// A topic to write: a valid ROS graph resource name (ros::names::validate: a letter or '/' first,
/// then letters, digits, '_' and '/'), global ('/' first, as rosbag record writes topics), without
/// '//' or a trailing '/'.
CLI::Validator topicName();
/// Adds --channels-topic and, when asked, --turntable-topic and --truth-topic.
void addTopicOptions(CLI::App& command, GyroTopics* chosen, bool turntable_and_truth);
/// Whether a subcommand looks for a topic: not at all, when the bag has one, or as a requirement.
enum class TopicNeed { kNo, kIfPresent, kRequired };
/// Explicit topics win; otherwise the single topic of the right type is taken. Throws UsageError
/// when a required topic is missing, ambiguous or of the wrong type. The precession state is looked
/// for only when asked (empty when not found and not required).
GyroTopics findTopics(const rosbag::Bag& bag, const GyroTopics& chosen, bool need_channels, bool need_turntable,
                      TopicNeed precession = TopicNeed::kNo);

/// `chosen` (an option's topic: its type checked), or else the bag's single topic of `type`; "" when
/// there is none and none is `required`. A UsageError names `option` for a topic not in the bag or of
/// another type, and for several of the type; one that is required and missing says what the bag
/// holds (after `missing_hint`).
std::string findTopic(const rosbag::Bag& bag, const std::string& chosen, const std::string& type,
                      const std::string& option, bool required, const std::string& missing_hint = std::string());

/// For a `catch (...)` around a loop over a bag's messages: a truncated or corrupt bag
/// (rosbag::BagException, a message shorter than its type) becomes a UsageError saying after how many
/// `samples`; anything else is rethrown as it is.
[[noreturn]] void rethrowBagReadError(std::uint64_t samples);

/// Reads hrg_gyro/PrecessionState records, also those of bags recorded before the message had its
/// `source` field (an earlier MD5 sum; `source` is then empty). Like ReusedMessageReader, without a
/// heap allocation per message once warm.
class PrecessionStateReader {
 public:
  PrecessionStateReader();
  ~PrecessionStateReader();
  /// False (message untouched) when the record is of neither layout.
  bool read(const rosbag::MessageInstance& instance, PrecessionState* message);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

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

/// The processor's limits as options (the node's parameter names with dashes, its defaults):
/// --max-gap, --backward-reset, --max-rate, --min-anisotropy, --min-amplitude, --max-amplitude.
void addProcessorOptions(CLI::App& command, core::ProcessorConfig* config);
/// The node's rules for those limits (core::validate): a refusal is a UsageError naming the option.
void checkProcessorConfig(const core::ProcessorConfig& config);

/// --compression none|lz4|bz2 (default lz4: readers then decompress whole chunks instead of
/// seeking for every message).
void addCompressionOption(CLI::App& command, std::string* compression);
/// Checked before anything is read or written; a refusal is a UsageError (exit 2) naming the
/// paths: an output that is the same file as an input or as another output (core::checkDistinct:
/// links followed, hard links, other spellings), or one that exists and is not a regular file (a
/// directory). Empty paths (options not given) are skipped.
void checkOutputPaths(const std::vector<std::string>& inputs, const std::vector<std::string>& outputs);

/// A triad's axes each read their own channels: two axes given one topic (--axis-channels y=/x/channels,
/// which /x/channels also serves by default) is a UsageError (exit 2) naming both axes and the topic.
void checkDistinctAxisTopics(const std::array<std::string, 3>& axes, const std::array<std::string, 3>& topics);

/// A bag written whole or not at all: a BagFileWriter (whole chunks, no per-message system call)
/// writes a temporary beside `path` (core::AtomicOutputFile), and commit() closes it and renames it
/// over `path`. Every error while writing or closing becomes an OutputError naming `path`.
/// Destroyed without a commit (an error, a refusal), the temporary is removed and `path` is left as
/// it was.
class OutputBag {
 public:
  OutputBag(const std::string& path, const std::string& compression);
  ~OutputBag();
  OutputBag(const OutputBag&) = delete;
  OutputBag& operator=(const OutputBag&) = delete;

  template <class Message>
  void write(const std::string& topic, const ros::Time& time, const Message& message) {
    try {
      bag_->write(topic, time, message);
    } catch (const BagWriteError& e) {
      failed(e.what(), e.error);
    }
  }
  void commit();

 private:
  /// `error`: errno right after the failure (rosbag's messages do not say why a write failed).
  [[noreturn]] void failed(const std::string& why, int error);
  /// Drops the bag after a failure (its file descriptor closed, nothing more written).
  void abandon() noexcept;

  std::string path_;
  std::unique_ptr<core::AtomicOutputFile> file_;
  std::unique_ptr<BagFileWriter> bag_;
};

/// A text output (CSV, report) written whole or not at all, like OutputBag.
class OutputText {
 public:
  explicit OutputText(const std::string& path);
  std::ostream& stream() { return file_->stream(); }
  /// Renames the complete file over the path; OutputError on any failure (the path unchanged).
  void commit();

 private:
  std::string path_;
  std::unique_ptr<core::AtomicOutputFile> file_;
};

/// Replays the channels topic of `bag` in record order through `processor`, calling `sink` with
/// every input message and its result, in order, on a second thread (while this one reads on): the
/// sink may keep its own state but must not share it with the caller until the call returns.
/// With a `precession_topic`, that topic's PrecessionState records are read too and handed to
/// `state_sink`, on the sink's thread, in their record order among the channels.
std::uint64_t replayChannels(const rosbag::Bag& bag, const std::string& topic, core::GyroProcessor& processor,
                             const std::function<void(const ChannelAmplitudes&, const core::ProcessorResult&)>& sink,
                             const std::string& progress_label, const std::string& precession_topic = std::string(),
                             const std::function<void(const PrecessionState&)>& state_sink = {});

/// The package's Python script `name`: installed beside hrg_bag (lib/hrg_gyro, devel and install
/// space alike); a source checkout without that copy falls back to the package's scripts/.
std::string packageScript(const std::string& name);

/// Runs scripts/plot_calibration.py (found by packageScript) without a shell: `kind`
/// (calibration, allan) drawn from `input` into `png`. The plotter writes a temporary beside `png`
/// that replaces it only when the plotter succeeded; otherwise OutputError and `png` unchanged.
void plot(const std::string& kind, const std::string& input, const std::string& png);

}  // namespace bag_tools
}  // namespace hrg_gyro

// hrg_bag align: north-finding from a recorded session. The bag's records feed one core::Gyrocompass
// as the gyrocompass node feeds it: the triad's body samples (its triad/output, or its axes' channels
// through core::TriadProcessor as the processors and the triad node run them), one gyro's outputs
// (single_gyro), each axis's outputs and precession state (sweep, from the channels), the indexer's
// state (turntable/state) and the accelerometer (accel/data_raw), each in record order; or any IMU's
// sensor_msgs/Imu (gyro_input imu, --imu-topic) through core::ImuIncrementConverter as the node runs it,
// its linear_acceleration the level. Prints the heading with its
// uncertainty and writes the result's YAML.
#include <rosbag/view.h>
#include <sensor_msgs/Imu.h>

#include <algorithm>
#include <iostream>
#include <map>
#include <memory>
#include <optional>

#include "align_run.h"
#include "bag_tools.h"
#include "hrg_gyro/GyroOutput.h"
#include "hrg_gyro/PrecessionState.h"
#include "hrg_gyro/TriadOutput.h"
#include "hrg_gyro/TurntableState.h"
#include "hrg_gyro/core/common/number_format.h"
#include "hrg_gyro/core/model/parameter_file.h"
#include "hrg_gyro/core/model/triad_file.h"
#include "hrg_gyro/ros/conversions.h"
#include "process_triad.h"
#include "read_messages.h"
#include "reused_message_reader.h"

namespace hrg_gyro {
namespace bag_tools {
namespace {

struct AlignCommand {
  AlignOptions align;
  TriadOptions triad;  // --triad: the axes' channels through the triad's chain
  core::ProcessorConfig processor;
  CLI::Option* triad_option = nullptr;
};

/// A key as a settings file writes it ("noise.residual_bias"), from the settings' own naming ("noise/...").
std::string dottedKey(std::string key) {
  std::replace(key.begin(), key.end(), '/', '.');
  return key;
}

/// The settings file, --duration in place of its duration; refusals name the file and the key.
core::AlignmentSettings loadSettings(const AlignOptions& o) {
  core::AlignmentSettings s;
  try {
    s = core::AlignmentSettings::load(o.settings);
  } catch (const std::exception& e) {  // ConfigError (the key), unreadable, not YAML
    throw UsageError("--settings " + o.settings + ": " + e.what());
  }
  if (o.duration > 0.0) {
    s.duration = o.duration;
    try {
      s.validate();
    } catch (const core::ConfigError& e) {
      throw UsageError("--duration: " + e.problem());
    }
  }
  return s;
}

/// Where the bag holds each stream the mode needs.
struct AlignInputs {
  std::string triad, gyro, turntable, accelerometer;
  std::string imu;                 // gyro_input imu: the IMU's sensor_msgs/Imu
  bool imu_accelerometer = false;  // the level's specific force from the IMU's messages
  bool channels = false;           // the triad from its axes' channels (--triad)
  bool sweep = false;              // each axis's outputs and precession state to the sweep mode
  std::array<AxisInput, 3> axes;
  std::array<std::string, 3> precession;  // sweep: each axis's /NAME/precession/state
};

/// A sensor_msgs/Imu topic: `chosen` (--OPTION), or the bag's one ending in `suffix` (accel/data_raw:
/// the bag may hold the triad's imu/data_raw too; imu/data_raw: an IMU's raw stream beside its filter's).
std::string imuTopic(const rosbag::Bag& bag, const std::string& chosen, const std::string& suffix,
                     const std::string& option, const std::string& hint) {
  const std::string type = ros::message_traits::datatype<sensor_msgs::Imu>();
  if (!chosen.empty()) return findTopic(bag, chosen, type, option, true, hint);
  std::vector<std::string> found;
  rosbag::View all(bag);
  for (const rosbag::ConnectionInfo* c : all.getConnections()) {
    const bool ends = c->topic.size() >= suffix.size() &&
                      c->topic.compare(c->topic.size() - suffix.size(), suffix.size(), suffix) == 0;
    if (c->datatype == type && ends && std::find(found.begin(), found.end(), c->topic) == found.end()) {
      found.push_back(c->topic);
    }
  }
  if (found.size() == 1) return found.front();
  if (found.size() > 1)
    throw UsageError("several " + type + " topics end in " + suffix + ": choose one with --" + option);
  throw UsageError("no " + type + " topic ending in " + suffix + " in the bag" + hint + "; name another with --" +
                   option);
}

AlignInputs findInputs(const rosbag::Bag& bag, const AlignCommand& c, const core::AlignmentSettings& s,
                       const std::array<AxisInput, 3>& axes) {
  AlignInputs in;
  const AlignOptions& o = c.align;
  if (s.mode == core::AlignmentMode::kSweep && !*c.triad_option) {
    throw UsageError(
        "--triad: mode sweep aligns each axis's outputs, from its channels and its precession state "
        "(--triad FILE --axis-params NAME=FILE for each axis)");
  }
  if (s.single_gyro) {
    in.gyro = findTopic(bag, o.gyro_topic, ros::message_traits::datatype<GyroOutput>(), "gyro-topic", true,
                        " (single_gyro: the gyro's outputs)");
  } else if (*c.triad_option) {
    in.channels = true;
    in.axes = axes;
    findAxisTopics(bag, c.triad, &in.axes);
    in.sweep = s.mode == core::AlignmentMode::kSweep;
    for (std::size_t a = 0; in.sweep && a < 3; ++a) {
      const std::string topic = "/" + triadAxisTopic(in.axes[a].name, "precession/state");
      try {
        in.precession[a] = findTopic(bag, topic, ros::message_traits::datatype<PrecessionState>(), "triad", true);
      } catch (const UsageError& e) {
        throw UsageError("mode sweep needs each axis's precession loop state, as its driver publishes it: " +
                         std::string(e.what()));
      }
    }
  } else if (s.gyro_input == core::GyroInput::kImu) {
    in.imu = imuTopic(bag, o.imu_topic, "imu/data_raw", "imu-topic", " (gyro_input imu: the IMU's messages)");
  } else {
    in.triad = findTopic(bag, o.triad_topic, ros::message_traits::datatype<TriadOutput>(), "triad-topic", true,
                         " (or give the axes' channels: --triad FILE --axis-params NAME=FILE for each axis)");
  }
  if (s.mode == core::AlignmentMode::kIndexed) {
    in.turntable = findTopic(bag, o.turntable_topic, ros::message_traits::datatype<TurntableState>(), "turntable-topic",
                             true, " (mode indexed: the indexer's angle)");
  }
  if (s.level.source == core::LevelSource::kAccelerometer) {
    if (!in.imu.empty() && s.imu.accelerometer && o.accelerometer_topic.empty()) {
      in.imu_accelerometer = true;
    } else {
      in.accelerometer =
          imuTopic(bag, o.accelerometer_topic, "accel/data_raw", "accelerometer-topic",
                   " for level/source accelerometer (or declare the level in the settings: level/source declared)");
    }
  }
  return in;
}

/// Feeds the run with the bag's records in record order until its window is full. Gyro samples
/// stamped before the first one plus --start are skipped.
class BagFeed {
 public:
  BagFeed(const AlignInputs& in, double start, const core::ImuInputSettings& imu, AlignmentRun* run)
      : in_(in), start_(core::toNanoseconds(start)), run_(run), imu_converter_(imu) {}

  const core::ImuIncrementConverter& imuConverter() const { return imu_converter_; }

  void setChain(core::TriadProcessor* chain) { chain_ = chain; }

  void read(const rosbag::Bag& bag) {
    std::vector<std::string> topics;
    for (const std::string& t : {in_.triad, in_.gyro, in_.turntable, in_.accelerometer, in_.imu}) {
      if (!t.empty()) topics.push_back(t);
    }
    std::map<std::string, std::size_t> axis_of_topic, axis_of_precession;
    for (std::size_t a = 0; in_.channels && a < 3; ++a) {
      topics.push_back(in_.axes[a].topic);
      axis_of_topic[in_.axes[a].topic] = a;
      if (!in_.sweep) continue;
      topics.push_back(in_.precession[a]);
      axis_of_precession[in_.precession[a]] = a;
    }
    rosbag::View view(bag, rosbag::TopicQuery(topics));
    Progress progress("align", view.size());
    records_ = readMessages(view, progress, [&](const rosbag::MessageInstance& m) {
      const std::string& topic = m.getTopic();
      const auto axis = axis_of_topic.find(topic);
      const auto precessing = axis_of_precession.find(topic);
      if (axis != axis_of_topic.end()) {
        channels(m, axis->second);
      } else if (precessing != axis_of_precession.end()) {
        precession(m, precessing->second);
      } else if (topic == in_.triad) {
        if (triad_reader_.read(m, &triad_) && admit(toNanoseconds(triad_.header.stamp))) {
          run_->addTriad(fromMessage(triad_));
        }
      } else if (topic == in_.gyro) {
        if (gyro_reader_.read(m, &gyro_) && admit(toNanoseconds(gyro_.header.stamp))) {
          run_->addAxis(toAxisOutput(gyro_));
        }
      } else if (topic == in_.imu) {
        if (accelerometer_reader_.read(m, &imu_)) imuSample();
      } else if (topic == in_.turntable) {
        if (table_reader_.read(m, &table_)) run_->addIndexer(fromMessage(table_));
      } else if (accelerometer_reader_.read(m, &imu_)) {
        run_->addAccelerometer(fromAccelerometerMessage(imu_));
      }
      return !run_->complete();
    });
    progress.finish(records_);
    if (chain_ && !run_->complete()) {
      std::vector<core::TriadAxisOutput> decided;
      std::vector<core::TriadBodySample> completed;
      chain_->finish(&decided, &completed);
      hand(decided, completed);
    }
    if (!run_->complete()) run_->inputEnded("the bag");
  }

 private:
  /// A gyro sample at or after the first one plus --start.
  bool admit(core::Nanoseconds ns) {
    if (first_ == 0) first_ = ns;
    return ns >= first_ + start_;
  }

  /// An IMU's message: its increment (from --start on) and, as the level's, its specific force. The
  /// force is fed from the window's start on too: before it, nothing reads it.
  void imuSample() {
    const core::ImuSample in = fromImuMessage(imu_);
    const std::optional<core::TriadBodySample> sample = imu_converter_.convert(in);
    const bool take = sample && admit(sample->stamp);
    if (in_.imu_accelerometer && (take || (first_ != 0 && in.stamp >= first_ + start_))) {
      if (const auto force = imu_converter_.specificForce(in)) run_->addAccelerometer({in.stamp, *force});
    }
    if (take) run_->addTriad(*sample);
  }

  /// One axis's channels through the triad's chain; the samples it completes go to the run.
  void channels(const rosbag::MessageInstance& m, std::size_t axis) {
    if (!channel_reader_.read(m, &channels_)) return;
    chain_->process(axis, fromMessage(channels_), &result_);
    if (!result_.has_output) return;
    release();
  }

  /// One axis's precession state to its processor's watch (and, sweep, to the run); the outputs it
  /// decides go on.
  void precession(const rosbag::MessageInstance& m, std::size_t axis) {
    if (!precession_reader_.read(m, &precession_)) return;
    const core::PrecessionStateRecord record = fromMessage(precession_);
    chain_->addPrecessionState(axis, record);
    run_->addPrecession(axis, record);
    release();
  }

  void release() {
    decided_.clear();
    completed_.clear();
    chain_->release(&decided_, &completed_);
    hand(decided_, completed_);
  }

  /// The chain's decided outputs to the sweep, or its completed body samples to the other modes.
  void hand(const std::vector<core::TriadAxisOutput>& decided, const std::vector<core::TriadBodySample>& completed) {
    if (in_.sweep) {
      for (const core::TriadAxisOutput& o : decided) {
        if (admit(o.output.stamp)) run_->addSweepAxis(o.axis, o.output);
      }
      return;
    }
    for (const core::TriadBodySample& s : completed) {
      if (admit(s.stamp)) run_->addTriad(s);
    }
  }

  const AlignInputs& in_;
  core::Nanoseconds start_ = 0, first_ = 0;
  AlignmentRun* run_;
  core::TriadProcessor* chain_ = nullptr;
  core::ImuIncrementConverter imu_converter_;
  std::uint64_t records_ = 0;
  ReusedMessageReader<TriadOutput> triad_reader_;
  ReusedMessageReader<GyroOutput> gyro_reader_;
  ReusedMessageReader<TurntableState> table_reader_;
  ReusedMessageReader<sensor_msgs::Imu> accelerometer_reader_;
  ReusedMessageReader<ChannelAmplitudes> channel_reader_;
  PrecessionStateReader precession_reader_;
  PrecessionState precession_;
  TriadOutput triad_;
  GyroOutput gyro_;
  TurntableState table_;
  sensor_msgs::Imu imu_;
  ChannelAmplitudes channels_;
  core::ProcessorResult result_;
  std::vector<core::TriadAxisOutput> decided_;
  std::vector<core::TriadBodySample> completed_;
};

void printResult(const AlignmentRun& run, const core::AlignmentResult& r, const std::vector<WindowResult>& windows) {
  const core::AlignmentProgress p = run.window().progress();
  std::cerr << "align: " << p.samples << " gyro samples, " << p.gaps << " gaps, " << p.indexer << " indexer records, "
            << p.accelerometer << " accelerometer records, " << p.dropped << " records dropped\n";
  std::cout << r.summary() << "\n";
  for (const WindowResult& w : windows) {
    char line[256];
    if (w.result.accepted) {
      std::snprintf(line, sizeof line, "  first %8.1f s: heading %.4f deg +- %.4f deg (noise %.4f mrad)\n", w.seconds,
                    w.result.heading, w.result.heading_sigma, 1e3 * w.result.budget.noise);
    } else {
      std::snprintf(line, sizeof line, "  first %8.1f s: refused (%s)\n", w.seconds, w.result.gate.c_str());
    }
    std::cout << line;
  }
}

/// --scan: one alignment per window of the settings' duration, every `o.scan` s from --start, each
/// from a fresh read of the bag, until a window cannot fill. Prints a line per window and the agreement
/// of the accepted ones; exit 0 when at least one was accepted.
int runScan(const AlignOptions& o, const core::AlignmentSettings& settings, const core::TriadParameters& triad,
            const AlignInputs& in, const rosbag::Bag& bag) {
  std::vector<ScanWindow> scan;
  for (double start = o.start;; start += o.scan) {
    AlignmentRun run(settings, {}, triad);
    BagFeed feed(in, start, settings.imu.converter, &run);
    feed.read(bag);
    const core::AlignmentResult r = run.finish();
    if (!r.accepted && r.gate == "aborted") break;  // the bag ended inside this window
    char line[320];
    if (r.accepted) {
      std::snprintf(line, sizeof line, "scan: from %8.1f s: heading %9.4f deg +- %.4f deg (noise %.4f mrad, %s)\n",
                    start, r.heading, r.heading_sigma, 1e3 * r.budget.noise, r.estimator.c_str());
    } else {
      std::snprintf(line, sizeof line, "scan: from %8.1f s: refused (%s): %.200s\n", start, r.gate.c_str(),
                    r.reason.c_str());
    }
    std::cout << line << std::flush;
    scan.push_back({start, r});
  }
  const ScanAgreement agreement = scanAgreement(scan);
  std::cout << "scan: " << agreement.accepted << " of " << scan.size() << " windows accepted; consecutive accepted "
            << "headings differ by at most " << core::formatDouble(agreement.largest_consecutive) << " deg, spread "
            << core::formatDouble(agreement.spread) << " deg\n";
  if (!o.output.empty()) {
    try {
      writeScanFile(o.output, emitScan(scan, o.bag, o.settings), scan);
    } catch (const std::exception& e) {
      throw OutputError("--output " + o.output + " not written: " + e.what());
    }
  }
  return agreement.accepted == 0 ? 1 : 0;
}

int runAlign(const AlignCommand& c) {
  const AlignOptions& o = c.align;
  core::AlignmentSettings settings = loadSettings(o);
  if (!o.imu_topic.empty()) {
    settings.gyro_input = core::GyroInput::kImu;  // --imu-topic: the gyros are that IMU's
    try {
      settings.validate();
    } catch (const core::ConfigError& e) {
      throw UsageError("--imu-topic: " + dottedKey(e.key()) + ": " + e.problem());
    }
  }
  if (settings.gyro_input == core::GyroInput::kImu && *c.triad_option)
    throw UsageError("--triad: the gyros are an IMU's sensor_msgs/Imu (gyro_input imu), not the triad's channels");
  std::vector<double> windows;
  try {
    windows = parseWindows(o.windows, settings.duration);
  } catch (const std::invalid_argument& e) {
    throw UsageError(std::string("--windows: ") + e.what());
  }
  std::vector<std::string> inputs{o.bag, o.settings};
  if (!settings.allan_file.empty()) inputs.push_back(settings.allan_file);  // read by the settings: an input too
  std::shared_ptr<const core::TriadParameters> triad;
  std::array<AxisInput, 3> axes;
  std::unique_ptr<core::TriadProcessor> chain;
  if (*c.triad_option) {
    if (settings.single_gyro) throw UsageError("--triad: single_gyro aligns on one gyro's outputs, not a triad");
    const core::TriadProcessorSettings chain_settings = checkedSettings(c.processor, c.triad);
    triad = std::make_shared<const core::TriadParameters>(core::loadTriadFile(c.triad.triad_file));
    axes = axisInputs(c.triad, *triad);
    inputs.push_back(c.triad.triad_file);
    for (const AxisInput& a : axes) inputs.push_back(a.parameter_file);
    std::array<core::GyroParameters, 3> parameters;
    for (std::size_t a = 0; a < 3; ++a) parameters[a] = core::loadParameterFile(axes[a].parameter_file);
    chain = std::make_unique<core::TriadProcessor>(chain_settings, parameters, triad);
  }
  checkOutputPaths(inputs, {o.output});
  // No noise model, no alignment: every term given, from the Allan file, or the residual bias from a
  // calibrated triad file, resolved as the gyrocompass will.
  try {
    settings = core::Gyrocompass(settings, triad ? *triad : core::TriadParameters()).settings();
  } catch (const core::ConfigError& e) {
    throw UsageError("--settings " + o.settings + ": " + dottedKey(e.key()) + ": " + e.problem());
  }
  const std::unique_ptr<rosbag::Bag> bag = openBag(o.bag);
  const AlignInputs in = findInputs(*bag, c, settings, axes);
  if (!in.imu.empty()) std::cerr << "align: gyros from " << in.imu << " (sensor_msgs/Imu)\n";

  if (o.scan > 0.0) {
    if (chain) throw UsageError("--scan: the triad's output or an IMU's messages, not the axes' channels (--triad)");
    if (!windows.empty()) throw UsageError("--scan and --windows: one or the other");
    return runScan(o, settings, triad ? *triad : core::TriadParameters(), in, *bag);
  }
  AlignmentRun run(settings, windows, triad ? *triad : core::TriadParameters());
  BagFeed feed(in, o.start, settings.imu.converter, &run);
  feed.setChain(chain.get());
  feed.read(*bag);
  const core::AlignmentResult result = run.finish();
  const std::vector<WindowResult> window_results = run.finishWindows();
  if (!in.imu.empty()) {
    const core::ImuInputCounts& n = feed.imuConverter().counts();
    std::cerr << "align: " << in.imu << ": " << n.samples << " increments (typical period "
              << core::formatDouble(feed.imuConverter().typicalPeriod()) << " s), " << n.gaps << " gaps, " << n.dropped
              << " dropped\n";
  }
  printResult(run, result, window_results);
  if (!o.output.empty()) {
    try {
      writeAlignmentFile(o.output, emitAlignmentRun(result, window_results, o.bag, o.settings), result, window_results);
    } catch (const std::exception& e) {
      throw OutputError("--output " + o.output + " not written: " + e.what());
    }
  }
  return result.accepted ? 0 : 1;
}

constexpr const char* kAlignFooter =
    "North-finding from the Earth's rate (docs/recorded_sessions.md): the settings' mode (static, indexed; one\n"
    "gyro with single_gyro; sweep), site and gates, as the gyrocompass node's parameters. The triad's body\n"
    "samples come from its triad/output, or from its axes' channels through the processors and the triad's\n"
    "combiner (--triad FILE --axis-params NAME=FILE for each axis, as process --triad); mode indexed reads\n"
    "the indexer's turntable/state; mode sweep (with --triad) each axis's outputs from its channels and its\n"
    "/NAME/precession/state, and the triad file's M and bias; level/source accelerometer reads the\n"
    "sensor_msgs/Imu topic ending in accel/data_raw. Any IMU (gyro_input imu, or --imu-topic): its\n"
    "sensor_msgs/Imu as the gyros, turned back into increments through the settings' imu/ keys, its\n"
    "linear_acceleration the level (docs/north_finding.md, \"North from any IMU\").\n"
    "Prints the true heading (deg clockwise from North) +- 1 sigma and the error budget; --output writes the\n"
    "whole result. Exit 0 accepted, 1 refused by a gate (named) or the bag ended before the window was full,\n"
    "2 bad usage or unreadable input, 3 the result could not be written (nothing left at its path).";

}  // namespace

Command addAlignCommand(CLI::App& root) {
  auto c = std::make_shared<AlignCommand>();
  CLI::App* cmd = root.add_subcommand("align", "north-finding: true heading from the Earth's rate, with its budget");
  addAlignOptions(*cmd, &c->align);
  c->triad_option = addTriadOptions(*cmd, &c->triad);
  addProcessorOptions(*cmd, &c->processor);
  cmd->footer(kAlignFooter);
  return [c] { return runAlign(*c); };
}

}  // namespace bag_tools
}  // namespace hrg_gyro

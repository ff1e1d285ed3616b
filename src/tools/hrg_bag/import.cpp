// hrg_bag import: a test bench's delimited text logs (channel amplitudes, turntable) into a gyro
// bag that `hrg_bag calibrate/process` read like a recorded one. Both logs are streamed record by
// record and merged by stamp as they are read, so memory stays flat for a log of any size. With
// --imu instead, an IMU's text log into sensor_msgs/Imu (imu_import.cpp); the two modes share the
// command and its common options, and each refuses the other's own.
#include <algorithm>
#include <cmath>
#include <iostream>
#include <memory>
#include <optional>

#include "../cli_checks.h"
#include "bag_tools.h"
#include "gyro_logs.h"
#include "hrg_gyro/TurntableState.h"
#include "hrg_gyro/core/common/atomic_file.h"
#include "hrg_gyro/ros/conversions.h"
#include "imu_import.h"

namespace hrg_gyro {

namespace {

struct ImportOptions {
  std::string channels, turntable, out, compression = "lz4", frame_id = "gyro_link";
  std::string channels_topic = "/channels", turntable_topic = "/turntable/state";
  std::string angle_unit = "rad", rate_unit = "rad/s", stamp_format = "auto", delimiter = "auto";
  std::vector<std::string> columns;
  bool skip_bad_rows = false, quiet = false, no_header = false;
  bag_tools::ImuImportOptions imu;  ///< --imu and the options only it takes
};

/// The options only the bench logs' import takes, which --imu refuses.
const std::vector<std::string> kBenchOnlyOptions = {"--channels",       "--turntable",    "--angle-unit",
                                                    "--rate-unit",      "--stamp-format", "--channels-topic",
                                                    "--turntable-topic"};

const std::vector<std::string> kChannelKeys = {"stamp", "ac", "bc", "as", "bs", "frequency", "temperature", "periods"};
const std::vector<std::string> kTurntableKeys = {"stamp", "angle", "rate"};

/// The settings of each log from the options; --column entries are "key=column", "stamp=" for both
/// logs, "channels.stamp=" or "turntable.stamp=" for one.
void logSettings(const ImportOptions& o, csv::LogSettings* channels, csv::LogSettings* turntable) {
  using bag_tools::UsageError;
  csv::LogSettings common;
  common.stamp_format = csv::parseStampFormat(o.stamp_format);  // checked by the option's validator
  common.delimiter = o.delimiter == "comma" ? ',' : o.delimiter == "semicolon" ? ';' : o.delimiter == "tab" ? '\t' : 0;
  common.angle_scale = o.angle_unit == "deg" ? M_PI / 180.0 : 1.0;
  common.rate_scale = o.rate_unit == "deg/s" ? M_PI / 180.0 : 1.0;
  common.skip_bad_rows = o.skip_bad_rows;
  common.has_header = !o.no_header;
  // A bag's time is a ros::Time (32-bit seconds), and rosbag writes nothing before TIME_MIN: a stamp
  // outside is a bad record of the log, not a failure of the output.
  common.earliest_stamp = static_cast<core::Nanoseconds>(ros::TIME_MIN.toNSec());
  common.latest_stamp = static_cast<core::Nanoseconds>(ros::TIME_MAX.toNSec());
  common.stamp_range_holder = "a bag";
  *channels = common;
  *turntable = common;
  auto is = [](const std::vector<std::string>& keys, const std::string& key) {
    return std::find(keys.begin(), keys.end(), key) != keys.end();
  };
  for (const std::string& entry : o.columns) {
    const std::size_t eq = entry.find('=');
    if (eq == std::string::npos || eq == 0 || eq + 1 == entry.size()) {
      throw UsageError("--column expects KEY=COLUMN (e.g. ac=Ac_V or ac=#2), got '" + entry + "'");
    }
    const std::string key = entry.substr(0, eq), column = entry.substr(eq + 1);
    if (key == "stamp") {
      channels->columns[key] = column;
      turntable->columns[key] = column;
    } else if (key == "channels.stamp") {
      channels->columns["stamp"] = column;
    } else if (key == "turntable.stamp") {
      turntable->columns["stamp"] = column;
    } else if (is(kChannelKeys, key)) {
      channels->columns[key] = column;
    } else if (is(kTurntableKeys, key)) {
      turntable->columns[key] = column;
    } else {
      throw UsageError("--column: unknown key '" + key +
                       "' (keys: stamp, channels.stamp, turntable.stamp, ac, bc, as, bs, frequency, temperature, "
                       "periods, angle, rate)");
    }
  }
}

/// An input log, open for streaming. Only a regular file is read: a FIFO, a device, a socket or a
/// directory is refused before it is opened for reading (a FIFO would wait for a writer forever);
/// that and a missing or unreadable file are UsageErrors naming the option.
struct InputLog {
  std::unique_ptr<csv::DescriptorInputBuffer> buffer;
  std::unique_ptr<std::istream> stream;
};
InputLog openLog(const std::string& path, const char* option, double* bytes) {
  std::uint64_t size = 0;
  int fd = -1;
  try {
    fd = core::openRegularFileForReading(path, "log", &size);
  } catch (const std::runtime_error& e) {
    throw bag_tools::UsageError(std::string(option) + ": " + e.what());
  }
  InputLog log;
  log.buffer = std::make_unique<csv::DescriptorInputBuffer>(fd);
  log.stream = std::make_unique<std::istream>(log.buffer.get());
  *bytes += static_cast<double>(size);
  return log;
}

/// The IMU mode: the shared options handed over, the bench logs' own refused.
int runImuMode(ImportOptions& o, const CLI::App& command) {
  using namespace bag_tools;
  for (const std::string& name : kBenchOnlyOptions) {
    if (command.count(name) > 0) throw UsageError(name + " is for a bench's logs, not with --imu");
  }
  ImuImportOptions& imu = o.imu;
  imu.out = o.out;
  imu.compression = o.compression;
  imu.frame_id = command.count("--frame-id") > 0 ? o.frame_id : "imu_link";
  imu.delimiter = o.delimiter;
  imu.columns = o.columns;
  imu.no_header = o.no_header;
  imu.skip_bad_rows = o.skip_bad_rows;
  imu.quiet = o.quiet;
  imu.command = &command;
  checkOutputPaths({imu.log}, {imu.out});
  double bytes = 0;
  const InputLog log = openLog(imu.log, "--imu", &bytes);
  return runImuImport(imu, *log.stream, bytes);
}

/// A logged record's header: its stamp, its place in its stream, the frame the log is in.
std_msgs::Header recordHeader(core::Nanoseconds stamp, std::uint64_t seq, const std::string& frame_id) {
  std_msgs::Header h;
  h.stamp = toRosTime(stamp);
  h.seq = static_cast<std::uint32_t>(seq);
  h.frame_id = frame_id;
  return h;
}

ChannelAmplitudes channelMessage(const csv::ChannelRecord& c, std::uint64_t seq, const std::string& frame_id) {
  ChannelAmplitudes m;
  m.header = recordHeader(c.stamp, seq, frame_id);
  m.c_in = c.ac;
  m.c_quad = c.bc;
  m.s_in = c.as;
  m.s_quad = c.bs;
  m.frequency = c.frequency;
  m.temperature = c.temperature;
  m.periods = c.periods;
  return m;
}

TurntableState turntableMessage(const csv::TurntableRecord& t, std::uint64_t seq, const std::string& frame_id) {
  TurntableState m;
  m.header = recordHeader(t.stamp, seq, frame_id);
  m.angle = t.angle;
  m.rate = t.rate;
  return m;
}

/// What was written, and with --skip-bad-rows what each log's skipped records were (no turntable log:
/// `turntable_skips` null).
void printSummary(const ImportOptions& o, std::uint64_t channel_count, const csv::BadRowCounts& channel_skips,
                  const csv::BadRowCounts* turntable_skips, std::uint64_t turntable_count) {
  std::cerr << "import: wrote " << o.out << ": " << channel_count << " channel records on " << o.channels_topic;
  if (turntable_skips) std::cerr << ", " << turntable_count << " turntable records on " << o.turntable_topic;
  std::cerr << "\n";
  if (!o.skip_bad_rows) return;
  std::cerr << "import: skipped records in " << o.channels << ": " << channel_skips.summary() << "\n";
  if (turntable_skips)
    std::cerr << "import: skipped records in " << o.turntable << ": " << turntable_skips->summary() << "\n";
}

int runImport(const ImportOptions& o) {
  using namespace bag_tools;
  if (o.channels.empty()) throw UsageError("--channels (a bench's logs) or --imu (an IMU's log) is required");
  if (o.delimiter == "whitespace") throw UsageError("--delimiter whitespace is for --imu logs");
  if (!o.turntable.empty() && o.channels_topic == o.turntable_topic) {
    throw UsageError("--channels-topic and --turntable-topic are both " + o.channels_topic +
                     ": one topic cannot carry both message types");
  }
  checkOutputPaths({o.channels, o.turntable}, {o.out});
  csv::LogSettings channel_settings, turntable_settings;
  logSettings(o, &channel_settings, &turntable_settings);
  double total_bytes = 0;
  const InputLog channel_file = openLog(o.channels, "--channels", &total_bytes);
  const InputLog turntable_file = o.turntable.empty() ? InputLog() : openLog(o.turntable, "--turntable", &total_bytes);
  csv::BadRowCounts channel_skips, turntable_skips;
  std::optional<csv::ChannelLogReader> channels;
  std::optional<csv::TurntableLogReader> turntable;
  try {
    channels.emplace(*channel_file.stream, o.channels, channel_settings, &channel_skips);
    if (turntable_file.stream) {
      turntable.emplace(*turntable_file.stream, o.turntable, turntable_settings, &turntable_skips);
    }
  } catch (const std::runtime_error& e) {
    throw UsageError(e.what());  // no header, no delimiter, a missing column: the mapping is wrong
  }
  if (turntable && turntable->derivesRate()) {
    std::cerr << "import: " << o.turntable << " has no rate column: the rate is the central difference of the "
              << "neighbouring angles\n";
  }

  OutputBag bag(o.out, o.compression);
  std::optional<Progress> progress;
  if (!o.quiet) progress.emplace("import", total_bytes);
  std::uint64_t channel_count = 0, turntable_count = 0;
  try {
    csv::ChannelRecord c;
    csv::TurntableRecord t;
    bool have_channel = channels->next(&c);
    bool have_turntable = turntable && turntable->next(&t);
    while (have_channel || have_turntable) {
      // Both logs are sorted by stamp: the older head goes first (a channel record before a
      // turntable record of the same stamp, as the simulator records them).
      if (have_channel && (!have_turntable || c.stamp <= t.stamp)) {
        // A skipped record leaves a gap in the sequence, which the processor node reports as a lost sample.
        const ChannelAmplitudes m = channelMessage(c, channel_count++ + channel_skips.total(), o.frame_id);
        bag.write(o.channels_topic, m.header.stamp, m);
        have_channel = channels->next(&c);
      } else {
        const TurntableState m = turntableMessage(t, turntable_count++, o.frame_id);
        bag.write(o.turntable_topic, m.header.stamp, m);
        have_turntable = turntable->next(&t);
      }
      if (progress) {
        const double done = channels->csv().bytesRead() + (turntable ? turntable->csv().bytesRead() : 0);
        progress->update(done, channel_count + turntable_count);
      }
    }
  } catch (const OutputError&) {
    throw;  // exit 3, not a bad input
  } catch (const csv::BadRowError& e) {
    std::cerr << "hrg_bag import: " << e.what() << "\nhrg_bag import: " << o.out
              << " not written (--skip-bad-rows skips and counts such records)\n";
    return 1;  // `bag` is destroyed uncommitted: nothing is left at --out
  } catch (const csv::ReadError& e) {
    std::cerr << "hrg_bag import: " << e.what() << "\nhrg_bag import: " << o.out << " not written\n";
    return 2;  // an unreadable log, as documented
  } catch (const std::runtime_error& e) {
    std::cerr << "hrg_bag import: " << e.what() << "\nhrg_bag import: " << o.out << " not written\n";
    return 1;
  }
  if (channel_count == 0) {
    std::cerr << "hrg_bag import: " << o.channels << " holds no usable channel record; " << o.out << " not written\n";
    return 1;
  }
  bag.commit();
  if (progress) progress->finish(channel_count + turntable_count);
  printSummary(o, channel_count, channel_skips, turntable ? &turntable_skips : nullptr, turntable_count);
  return 0;
}

}  // namespace

namespace bag_tools {

Command addImportCommand(CLI::App& root) {
  auto o = std::make_shared<ImportOptions>();
  CLI::App* cmd = root.add_subcommand(
      "import", "a test bench's CSV logs (channels, turntable) into a gyro bag, or an IMU's text log (--imu)");
  cmd->add_option("--channels", o->channels,
                  "channel-amplitude log: stamp, ac, bc, as, bs [, frequency, temperature, periods] (or --imu)")
      ->check(tools::notEmpty());
  cmd->add_option("--turntable", o->turntable, "turntable log: stamp and angle and/or rate")->check(tools::notEmpty());
  cmd->add_option("--out", o->out, "output bag")->required()->check(tools::notEmpty());
  cmd->add_option("--column", o->columns,
                  "KEY=COLUMN, repeatable: the header name (any case) or #N (N-th column, from 1) holding KEY")
      ->take_all();
  cmd->add_flag("--no-header", o->no_header,
                "the logs have no header row: every column by index (--column stamp=#1 ac=#2 ...)");
  cmd->add_option("--stamp-format", o->stamp_format,
                  "auto (ISO 8601 if it holds a T, seconds if it holds a '.', else nanoseconds), s, ns, iso")
      ->check(CLI::IsMember({"auto", "s", "ns", "iso"}))
      ->capture_default_str();
  cmd->add_option("--delimiter", o->delimiter,
                  "auto (the one of , ; tab in the header; --imu: blanks when it holds none), comma, semicolon, tab, "
                  "whitespace (--imu: runs of blanks and tabs)")
      ->check(CLI::IsMember({"auto", "comma", "semicolon", "tab", "whitespace"}))
      ->capture_default_str();
  cmd->add_option("--angle-unit", o->angle_unit, "unit of the logged angle")
      ->check(CLI::IsMember({"rad", "deg"}))
      ->capture_default_str();
  cmd->add_option("--rate-unit", o->rate_unit, "unit of the logged rate")
      ->check(CLI::IsMember({"rad/s", "deg/s"}))
      ->capture_default_str();
  cmd->add_flag("--skip-bad-rows", o->skip_bad_rows, "skip bad records and count them by reason (default: refuse)");
  cmd->add_flag("--quiet", o->quiet, "no progress on stderr (the summary and notes stay)");
  cmd->add_option("--channels-topic", o->channels_topic, "topic of the channel amplitudes")
      ->check(topicName())
      ->capture_default_str();
  cmd->add_option("--turntable-topic", o->turntable_topic, "topic of the turntable states (not --channels-topic)")
      ->check(topicName())
      ->capture_default_str();
  cmd->add_option("--frame-id", o->frame_id, "frame_id of the written messages (--imu: default imu_link)")
      ->check(tools::frameId())
      ->capture_default_str();
  addCompressionOption(*cmd, &o->compression);
  addImuImportOptions(*cmd, &o->imu);
  cmd->footer(
      "Each log: '#' comment lines, then a header row naming the columns, then one record a line,\n"
      "sorted by stamp (strictly increasing). Default column names (any case): stamp, ac, bc, as, bs,\n"
      "frequency, temperature, periods; stamp, angle, rate. Stamps: seconds (1700000000.123456789),\n"
      "whole nanoseconds (1700000000123456789) or ISO 8601 with a zone (2026-11-23T10:00:00.5Z,\n"
      "...+01:00), all read exactly as integer nanoseconds. Missing frequency/temperature are NaN.\n"
      "Turntable with only an angle: the rate is the central difference of the neighbouring records,\n"
      "(angle[i+1] - angle[i-1]) / (t[i+1] - t[i-1]), one-sided at the ends; its noise is the angle's\n"
      "noise / (sqrt(2) x record spacing). With only a rate, the angle is written as NaN.\n"
      "A bad record (a line over 1 MiB, field count, unreadable stamp or number, a stamp a bag cannot\n"
      "hold: before 1 ns or from 2^32 s, NaN or infinity where a number is required, also a derived rate\n"
      "that overflows, stamp not increasing) is refused with file:line and the reason, or skipped and\n"
      "counted with --skip-bad-rows. Messages quote at most 64 bytes of a field. Topics are global ROS\n"
      "names; a frame id has no blank, control character or leading '/'.\n"
      "The bag is written to a temporary and renamed over --out when complete.\n"
      "Exit 0 success, 1 a bad record or no usable record (nothing written), 2 bad usage, a log that is\n"
      "no regular file (a FIFO, a device, a directory: refused before it is opened), unreadable, without\n"
      "a header row within 1 MiB or without the columns, 3 the bag could not be written.\n"
      "\n"
      "--imu LOG: an IMU's text log into sensor_msgs/Imu on --imu-topic (angular velocity rad/s and specific\n"
      "force m/s^2 in FLU; orientation_covariance[0] = -1, angular velocity covariance 0 = unknown,\n"
      "linear_acceleration_covariance[0] = -1 without accelerometer columns) and, when the site is known,\n"
      "one sensor_msgs/NavSatFix on --fix-topic at the first stamp. Columns (a header row naming them, or\n"
      "--no-header and --column KEY=#N): time (optional, s), gx gy gz, ax ay az (optional). Increments are\n"
      "divided by the interval their row closes (its stamp difference; without a time column --interval).\n"
      "Rows are checked like the bench logs' records (file:line and the column named, or --skip-bad-rows).\n"
      "Example: hrg_bag import --imu lasergyro.imu --format psins --epoch 1395394311 --out lasergyro.bag");
  return [o, cmd] {
    if (!o->imu.log.empty()) return runImuMode(*o, *cmd);
    for (const std::string& name : imuOnlyOptions()) {
      if (cmd->count(name) > 0) throw UsageError(name + " is for an IMU's log (--imu)");
    }
    return runImport(*o);
  };
}

}  // namespace bag_tools
}  // namespace hrg_gyro

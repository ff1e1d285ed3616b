// The two logs a test bench keeps beside the gyro, read record by record from delimited text: the
// channel amplitudes (stamp, Ac, Bc, As, Bs and optionally frequency, temperature, periods) and the
// turntable (stamp and angle and/or rate). Each reader checks every record (line length, field
// count, numbers, NaN where none may stand, stamps strictly increasing) and either refuses the first
// bad one with file:line and the reason, or skips it and counts it by reason. Where the turntable
// log holds only the angle, the rate is derived from it by the central difference of the
// neighbouring records.
// No ROS: `hrg_bag import` turns the records into messages.
#pragma once

#include <array>
#include <cstdint>
#include <functional>
#include <limits>
#include <map>
#include <memory>
#include <stdexcept>
#include <string>

#include "csv_reader.h"

namespace hrg_gyro {
namespace csv {

enum class BadRowReason { kLineTooLong, kFieldCount, kStamp, kStampRange, kStampOrder, kNumber, kNotANumber };
constexpr std::size_t kBadRowReasons = 7;
const char* describe(BadRowReason reason);

/// A record refused while it is read, before the file:line is added (the readers' own signal to their
/// loop, which turns it into a BadRowError or a skipped row).
struct RowRefusal {
  BadRowReason reason;
  std::string detail;
};

/// The shortest text that reads back to `value` ("inf", "1e+308"), for the readers' messages.
std::string shortestText(double value);

/// Records skipped by reason (with --skip-bad-rows).
struct BadRowCounts {
  std::array<std::uint64_t, kBadRowReasons> by_reason{};
  std::uint64_t total() const;
  /// "3 (wrong field count 1, stamp not increasing 2)", or "0".
  std::string summary() const;
};

/// A refused record: "file:line: reason: detail". Exit code 1 in hrg_bag.
struct BadRowError : std::runtime_error {
  BadRowError(BadRowReason why, const std::string& message) : std::runtime_error(message), reason(why) {}
  BadRowReason reason;
};

struct LogSettings {
  StampFormat stamp_format = StampFormat::kAuto;
  char delimiter = 0;      ///< 0: taken from the header
  bool has_header = true;  ///< false: no header row, every column mapped by "#N"
  /// Column of each key ("ac" -> "Ac_V" or "#3"); a key not given is looked up by its own name.
  std::map<std::string, std::string> columns;
  double angle_scale = 1.0;  ///< to rad
  double rate_scale = 1.0;   ///< to rad/s
  bool skip_bad_rows = false;
  /// The stamps the output can hold (a bag: ros::TIME_MIN to ros::TIME_MAX); a stamp outside is a
  /// bad record, `stamp_range_holder` saying whose range it is in the message.
  core::Nanoseconds earliest_stamp = 0;
  core::Nanoseconds latest_stamp = std::numeric_limits<core::Nanoseconds>::max();
  std::string stamp_range_holder = "the output";
};

struct ChannelRecord {
  core::Nanoseconds stamp = 0;
  double ac = 0, bc = 0, as = 0, bs = 0;
  double frequency = 0, temperature = 0;  ///< NaN when not logged
  std::uint32_t periods = 0;              ///< 0 when not logged
};

struct TurntableRecord {
  core::Nanoseconds stamp = 0;
  double angle = 0;  ///< rad; NaN when only the rate is logged
  double rate = 0;   ///< rad/s
};

/// The column of `key` in `csv`: `columns[key]` when given (a header name or "#N"), else the header
/// column named `key` (any case); -1 when there is none and the key is neither `required` nor given.
/// Otherwise std::runtime_error naming the file and the key, with the header's names (or, in a file
/// `has_header` false, the #N range to map it with).
int findColumn(const CsvReader& csv, const std::map<std::string, std::string>& columns, bool has_header,
               const std::string& key, bool required);

/// The records of one log and the rules every record meets; shared by the two readers below.
class RecordSource {
 public:
  RecordSource(std::istream& in, const std::string& name, const LogSettings& settings, BadRowCounts* skipped);
  /// The column of `key`, -1 when absent and not `required`; std::runtime_error naming the key and
  /// the file when a required column, or one named by an option, is missing.
  int column(const std::string& key, bool required) const;
  /// Reads records until one passes `parse` (called with the record's stamp); false at the end.
  template <class Parse>
  bool next(Parse&& parse);
  /// A number of the current record; NaN only where `nan_allowed`, infinities never.
  double number(int column, const char* key, bool nan_allowed) const;
  /// A whole number in [0, 2^32 - 1] of the current record.
  std::uint32_t count(int column, const char* key) const;
  const CsvReader& csv() const { return csv_; }
  /// A record found bad after it was read (a rate derived from its neighbours): BadRowError naming
  /// `line`, or counted when bad records are skipped.
  void refuseOrCount(BadRowReason reason, std::uint64_t line, const std::string& detail);

 private:
  [[noreturn]] void bad(BadRowReason reason, const std::string& detail) const;
  bool nextRecord(const std::function<void(core::Nanoseconds)>& parse);

  CsvReader csv_;
  LogSettings settings_;
  BadRowCounts* skipped_;
  int stamp_column_;
  bool have_last_ = false;
  core::Nanoseconds last_ = 0;
};

class ChannelLogReader {
 public:
  ChannelLogReader(std::istream& in, const std::string& name, const LogSettings& settings, BadRowCounts* skipped);
  bool next(ChannelRecord* record);
  const CsvReader& csv() const { return source_.csv(); }

 private:
  RecordSource source_;
  int ac_, bc_, as_, bs_, frequency_, temperature_, periods_;
};

class TurntableLogReader {
 public:
  TurntableLogReader(std::istream& in, const std::string& name, const LogSettings& settings, BadRowCounts* skipped);
  bool next(TurntableRecord* record);
  const CsvReader& csv() const { return source_.csv(); }
  /// True when the rate is derived from the angle (no rate column).
  bool derivesRate() const { return rate_ < 0; }

 private:
  /// A record of the log with its line, for the refusal of a rate derived later.
  struct Reading {
    TurntableRecord record;
    std::uint64_t line = 0;
  };
  bool readRecord(TurntableRecord* record);
  bool readRecord(Reading* reading);

  RecordSource source_;
  int angle_, rate_;
  double angle_scale_, rate_scale_;
  // The derivation's window: the record before, the one being returned, the one after. Every record
  // read without fault passes through it, also one whose own rate is then refused (its angle is
  // good), so that skipping a record never changes the rate of another.
  Reading before_, current_, after_;
  bool primed_ = false, have_before_ = false, have_current_ = false, have_after_ = false;
};

template <class Parse>
bool RecordSource::next(Parse&& parse) {
  return nextRecord(std::function<void(core::Nanoseconds)>(std::forward<Parse>(parse)));
}

}  // namespace csv
}  // namespace hrg_gyro

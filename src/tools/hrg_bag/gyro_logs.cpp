#include "gyro_logs.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <limits>

namespace hrg_gyro {
namespace csv {

std::string shortestText(double value) {
  char text[32];
  return std::string(text, std::to_chars(text, text + sizeof text, value).ptr);
}

const char* describe(BadRowReason reason) {
  switch (reason) {
    case BadRowReason::kLineTooLong:
      return "line too long";
    case BadRowReason::kFieldCount:
      return "wrong field count";
    case BadRowReason::kStamp:
      return "unreadable stamp";
    case BadRowReason::kStampRange:
      return "stamp out of range";
    case BadRowReason::kStampOrder:
      return "stamp not increasing";
    case BadRowReason::kNumber:
      return "unreadable number";
    case BadRowReason::kNotANumber:
    default:
      return "NaN or infinity not allowed";
  }
}

std::uint64_t BadRowCounts::total() const {
  std::uint64_t n = 0;
  for (std::uint64_t c : by_reason) n += c;
  return n;
}

std::string BadRowCounts::summary() const {
  std::string s = std::to_string(total());
  std::string parts;
  for (std::size_t i = 0; i < kBadRowReasons; ++i) {
    if (by_reason[i] == 0) continue;
    parts += (parts.empty() ? "" : ", ") + std::string(describe(static_cast<BadRowReason>(i))) + " " +
             std::to_string(by_reason[i]);
  }
  return parts.empty() ? s : s + " (" + parts + ")";
}

RecordSource::RecordSource(std::istream& in, const std::string& name, const LogSettings& settings,
                           BadRowCounts* skipped)
    : csv_(in, name, settings.delimiter, settings.has_header),
      settings_(settings),
      skipped_(skipped),
      stamp_column_(column("stamp", true)) {}

int findColumn(const CsvReader& csv, const std::map<std::string, std::string>& columns, bool has_header,
               const std::string& key, bool required) {
  const auto given = columns.find(key);
  const std::string wanted = given == columns.end() ? key : given->second;
  const int index = csv.column(wanted);
  if (index < 0 && (required || given != columns.end())) {
    if (!has_header) {
      throw std::runtime_error(csv.name() + ": no header row, so " + key + " needs its column by index: --column " +
                               key + "=#N (N from 1 to " + std::to_string(csv.header().size()) + ")");
    }
    // The names, each an excerpt, and not more of them than a reader takes in.
    constexpr std::size_t kListedColumns = 16;
    const std::vector<std::string>& header = csv.header();
    std::string names;
    for (std::size_t i = 0; i < std::min(header.size(), kListedColumns); ++i) {
      names += (i == 0 ? "'" : ", '") + excerpt(header[i]) + "'";
    }
    if (header.size() > kListedColumns) names += ", ... (" + std::to_string(header.size()) + " columns)";
    throw std::runtime_error(csv.name() + ":" + std::to_string(csv.line()) + ": no column '" + excerpt(wanted) +
                             "' for " + key + " in the header (" + names + "): name it with the column option");
  }
  return index;
}

int RecordSource::column(const std::string& key, bool required) const {
  return findColumn(csv_, settings_.columns, settings_.has_header, key, required);
}

void RecordSource::bad(BadRowReason reason, const std::string& detail) const { throw RowRefusal{reason, detail}; }

double RecordSource::number(int column, const char* key, bool nan_allowed) const {
  double value = 0.0;
  try {
    value = parseNumber(csv_.fields()[column]);
  } catch (const FieldError& e) {
    bad(BadRowReason::kNumber, std::string(key) + ": " + e.what());
  }
  if (std::isinf(value) || (std::isnan(value) && !nan_allowed)) {
    bad(BadRowReason::kNotANumber, std::string(key) + " is " + excerpt(csv_.fields()[column]) +
                                       (nan_allowed ? "" : " (a number is required here)"));
  }
  return value;
}

std::uint32_t RecordSource::count(int column, const char* key) const {
  const std::string_view field = csv_.fields()[column];
  std::uint32_t value = 0;
  const auto r = std::from_chars(field.data(), field.data() + field.size(), value);
  if (field.empty() || r.ec != std::errc() || r.ptr != field.data() + field.size()) {
    bad(BadRowReason::kNumber, std::string(key) + ": '" + excerpt(field) + "' is not a whole number in [0, 2^32 - 1]");
  }
  return value;
}

bool RecordSource::nextRecord(const std::function<void(core::Nanoseconds)>& parse) {
  for (;;) {
    try {
      try {
        if (!csv_.next()) return false;
      } catch (const LineTooLongError& e) {
        bad(BadRowReason::kLineTooLong, e.what());  // the reader goes on after it, should it be skipped
      }
      if (csv_.fields().size() != csv_.header().size()) {
        bad(BadRowReason::kFieldCount,
            std::to_string(csv_.fields().size()) + " fields, the header has " + std::to_string(csv_.header().size()));
      }
      core::Nanoseconds stamp = 0;
      try {
        stamp = parseStamp(csv_.fields()[stamp_column_], settings_.stamp_format);
      } catch (const OutOfRangeError& e) {
        bad(BadRowReason::kStampRange, e.what());
      } catch (const FieldError& e) {
        bad(BadRowReason::kStamp, e.what());
      }
      if (stamp < settings_.earliest_stamp || stamp > settings_.latest_stamp) {
        bad(BadRowReason::kStampRange,
            "stamp " + secondsText(stamp) + " s is outside [" + secondsText(settings_.earliest_stamp) + " s, " +
                secondsText(settings_.latest_stamp) + " s], the stamps " + settings_.stamp_range_holder + " can hold");
      }
      if (have_last_ && stamp <= last_) {
        bad(BadRowReason::kStampOrder, "stamp " + std::to_string(stamp) + " ns is not after the previous record's " +
                                           std::to_string(last_) + " ns (the log must be sorted by stamp)");
      }
      parse(stamp);
      have_last_ = true;
      last_ = stamp;
      return true;
    } catch (const RowRefusal& r) {
      refuseOrCount(r.reason, csv_.line(), r.detail);
    }
  }
}

void RecordSource::refuseOrCount(BadRowReason reason, std::uint64_t line, const std::string& detail) {
  if (!settings_.skip_bad_rows || skipped_ == nullptr) {
    throw BadRowError(reason, csv_.name() + ":" + std::to_string(line) + ": " + describe(reason) + ": " + detail);
  }
  ++skipped_->by_reason[static_cast<std::size_t>(reason)];
}

ChannelLogReader::ChannelLogReader(std::istream& in, const std::string& name, const LogSettings& settings,
                                   BadRowCounts* skipped)
    : source_(in, name, settings, skipped),
      ac_(source_.column("ac", true)),
      bc_(source_.column("bc", true)),
      as_(source_.column("as", true)),
      bs_(source_.column("bs", true)),
      frequency_(source_.column("frequency", false)),
      temperature_(source_.column("temperature", false)),
      periods_(source_.column("periods", false)) {}

bool ChannelLogReader::next(ChannelRecord* r) {
  return source_.next([&](core::Nanoseconds stamp) {
    constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
    r->stamp = stamp;
    r->ac = source_.number(ac_, "ac", false);
    r->bc = source_.number(bc_, "bc", false);
    r->as = source_.number(as_, "as", false);
    r->bs = source_.number(bs_, "bs", false);
    r->frequency = frequency_ < 0 ? kNaN : source_.number(frequency_, "frequency", true);
    r->temperature = temperature_ < 0 ? kNaN : source_.number(temperature_, "temperature", true);
    r->periods = periods_ < 0 ? 0 : source_.count(periods_, "periods");
  });
}

TurntableLogReader::TurntableLogReader(std::istream& in, const std::string& name, const LogSettings& settings,
                                       BadRowCounts* skipped)
    : source_(in, name, settings, skipped),
      angle_(source_.column("angle", false)),
      rate_(source_.column("rate", false)),
      angle_scale_(settings.angle_scale),
      rate_scale_(settings.rate_scale) {
  if (angle_ < 0 && rate_ < 0) {
    throw std::runtime_error(name + ": the turntable log needs an angle or a rate column (or both)");
  }
}

bool TurntableLogReader::readRecord(TurntableRecord* r) {
  return source_.next([&](core::Nanoseconds stamp) {
    r->stamp = stamp;
    // With a rate logged the calibration can integrate it, so a missing angle (NaN) is allowed;
    // without one the angle is all there is.
    r->angle = angle_ < 0 ? std::numeric_limits<double>::quiet_NaN()
                          : source_.number(angle_, "angle", rate_ >= 0) * angle_scale_;
    r->rate = rate_ < 0 ? 0.0 : source_.number(rate_, "rate", false) * rate_scale_;
  });
}

bool TurntableLogReader::readRecord(Reading* reading) {
  if (!readRecord(&reading->record)) return false;
  reading->line = source_.csv().line();
  return true;
}

bool TurntableLogReader::next(TurntableRecord* record) {
  if (!derivesRate()) return readRecord(record);
  if (!primed_) {
    primed_ = true;
    have_current_ = readRecord(&current_);
    have_after_ = have_current_ && readRecord(&after_);
    if (have_current_ && !have_after_) {
      throw std::runtime_error(source_.csv().name() +
                               ": one turntable record: the rate cannot be derived from the "
                               "angle without a neighbour (log the rate, or more records)");
    }
  }
  while (have_current_) {
    // Central difference over the neighbours; one-sided at the two ends of the log.
    const Reading& a = have_before_ ? before_ : current_;
    const Reading& b = have_after_ ? after_ : current_;
    const double span = static_cast<double>(b.record.stamp - a.record.stamp) * 1e-9;
    const double rate = (b.record.angle - a.record.angle) / span;
    // Finite angles can still differ by more than a double holds (1e308 and -1e308).
    const bool finite = std::isfinite(rate);
    if (finite) {
      *record = current_.record;
      record->rate = rate;
    } else {
      source_.refuseOrCount(BadRowReason::kNotANumber, current_.line,
                            "rate derived from the angle is " + shortestText(rate) +
                                ": the central difference of lines " + std::to_string(a.line) + " and " +
                                std::to_string(b.line) + " overflows (angles " + shortestText(a.record.angle) +
                                " and " + shortestText(b.record.angle) + " rad, " + shortestText(span) + " s apart)");
    }
    before_ = current_;
    have_before_ = true;
    current_ = after_;
    have_current_ = have_after_;
    have_after_ = have_current_ && readRecord(&after_);
    if (finite) return true;
  }
  return false;
}

}  // namespace csv
}  // namespace hrg_gyro

#include "csv_reader.h"

#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <charconv>
#include <cstdio>
#include <cstring>
#include <limits>

namespace hrg_gyro {
namespace csv {
namespace {

constexpr std::int64_t kNanosecondsPerSecond = 1000000000LL;

std::string_view trim(std::string_view s) {
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t' || s.front() == '\r')) s.remove_prefix(1);
  while (!s.empty() && (s.back() == ' ' || s.back() == '\t' || s.back() == '\r')) s.remove_suffix(1);
  return s;
}

std::string quoted(std::string_view s) { return "'" + excerpt(s) + "'"; }

bool allDigits(std::string_view s) {
  return !s.empty() && std::all_of(s.begin(), s.end(), [](char c) { return c >= '0' && c <= '9'; });
}

/// A whole number of digits only, overflow checked.
std::int64_t digitsValue(std::string_view digits, std::string_view field) {
  std::int64_t value = 0;
  const auto r = std::from_chars(digits.data(), digits.data() + digits.size(), value);
  if (r.ec == std::errc::result_out_of_range) throw OutOfRangeError("stamp " + quoted(field) + " is out of range");
  if (r.ec != std::errc() || r.ptr != digits.data() + digits.size()) {
    throw FieldError("stamp " + quoted(field) + " is not a whole number");
  }
  return value;
}

std::int64_t checkedAdd(std::int64_t a, std::int64_t b, std::string_view field) {
  std::int64_t sum = 0;
  if (__builtin_add_overflow(a, b, &sum)) throw OutOfRangeError("stamp " + quoted(field) + " is out of range");
  return sum;
}

std::int64_t checkedScale(std::int64_t a, std::int64_t b, std::string_view field) {
  std::int64_t product = 0;
  if (__builtin_mul_overflow(a, b, &product)) throw OutOfRangeError("stamp " + quoted(field) + " is out of range");
  return product;
}

/// Nanoseconds of a decimal fraction's digits (after the point), rounded half up at the 9th.
std::int64_t fractionNanoseconds(std::string_view digits, bool* carry) {
  std::int64_t ns = 0;
  for (std::size_t i = 0; i < 9; ++i) ns = ns * 10 + (i < digits.size() ? digits[i] - '0' : 0);
  *carry = false;
  if (digits.size() > 9 && digits[9] >= '5') ++ns;
  if (ns == kNanosecondsPerSecond) {
    ns = 0;
    *carry = true;
  }
  return ns;
}

core::Nanoseconds parseSeconds(std::string_view s, std::string_view field) {
  const std::size_t point = s.find('.');
  const std::string_view whole = s.substr(0, point);
  const std::string_view fraction = point == std::string_view::npos ? std::string_view() : s.substr(point + 1);
  if (!allDigits(whole) || (point != std::string_view::npos && !fraction.empty() && !allDigits(fraction))) {
    throw FieldError("stamp " + quoted(field) + " is not a plain decimal number of seconds");
  }
  bool carry = false;
  const std::int64_t ns = fractionNanoseconds(fraction, &carry);
  const std::int64_t seconds = checkedAdd(digitsValue(whole, field), carry ? 1 : 0, field);
  return checkedAdd(checkedScale(seconds, kNanosecondsPerSecond, field), ns, field);
}

/// Days from 1970-01-01 to a proleptic Gregorian date (the civil-calendar count by eras of 400 years).
std::int64_t daysFromCivil(std::int64_t y, unsigned m, unsigned d) {
  y -= m <= 2 ? 1 : 0;
  const std::int64_t era = (y >= 0 ? y : y - 399) / 400;
  const unsigned year_of_era = static_cast<unsigned>(y - era * 400);
  const unsigned day_of_year = (153 * (m + (m > 2 ? -3 : 9)) + 2) / 5 + d - 1;
  const unsigned day_of_era = year_of_era * 365 + year_of_era / 4 - year_of_era / 100 + day_of_year;
  return era * 146097 + static_cast<std::int64_t>(day_of_era) - 719468;
}

bool leapYear(std::int64_t y) { return (y % 4 == 0 && y % 100 != 0) || y % 400 == 0; }

core::Nanoseconds parseIso8601(std::string_view s, std::string_view field) {
  auto bad = [&](const std::string& why) { return FieldError("ISO 8601 stamp " + quoted(field) + ": " + why); };
  // YYYY-MM-DDTHH:MM:SS[.f...](Z|+HH:MM|-HH:MM|+HHMM|-HHMM)
  auto number = [&](std::size_t at, std::size_t digits) -> int {
    if (s.size() < at + digits || !allDigits(s.substr(at, digits))) {
      throw bad("expected YYYY-MM-DDTHH:MM:SS[.fraction] and a zone (Z or +hh:mm)");
    }
    int v = 0;
    for (std::size_t i = 0; i < digits; ++i) v = v * 10 + (s[at + i] - '0');
    return v;
  };
  auto expect = [&](std::size_t at, char c) {
    if (s.size() <= at || s[at] != c) throw bad("expected YYYY-MM-DDTHH:MM:SS[.fraction] and a zone (Z or +hh:mm)");
  };
  const int year = number(0, 4);
  expect(4, '-');
  const int month = number(5, 2);
  expect(7, '-');
  const int day = number(8, 2);
  if (s.size() <= 10 || (s[10] != 'T' && s[10] != 't')) throw bad("expected a 'T' between date and time");
  const int hour = number(11, 2);
  expect(13, ':');
  const int minute = number(14, 2);
  expect(16, ':');
  const int second = number(17, 2);
  static const int kDaysInMonth[] = {31, 28, 31, 30, 31, 30, 31, 31, 30, 31, 30, 31};
  if (month < 1 || month > 12) throw bad("month out of range");
  const int month_days = kDaysInMonth[month - 1] + (month == 2 && leapYear(year) ? 1 : 0);
  if (day < 1 || day > month_days) throw bad("day out of range");
  if (hour > 23 || minute > 59 || second > 59) throw bad("time of day out of range (leap seconds are not accepted)");
  std::size_t at = 19;
  std::int64_t ns = 0;
  bool carry = false;
  if (at < s.size() && (s[at] == '.' || s[at] == ',')) {
    const std::size_t begin = ++at;
    while (at < s.size() && s[at] >= '0' && s[at] <= '9') ++at;
    if (at == begin) throw bad("a decimal point without digits");
    ns = fractionNanoseconds(s.substr(begin, at - begin), &carry);
  }
  if (at >= s.size()) throw bad("no zone: add Z (UTC) or an offset such as +01:00");
  std::int64_t offset_seconds = 0;
  if (s[at] == 'Z' || s[at] == 'z') {
    ++at;
  } else if (s[at] == '+' || s[at] == '-') {
    const int sign = s[at] == '-' ? -1 : 1;
    const int oh = number(at + 1, 2);
    std::size_t mm = at + 3;
    if (mm < s.size() && s[mm] == ':') ++mm;
    const int om = number(mm, 2);
    if (oh > 23 || om > 59) throw bad("zone offset out of range");
    offset_seconds = sign * (oh * 3600 + om * 60);
    at = mm + 2;
  } else {
    throw bad("unexpected " + quoted(s.substr(at)) + " where the zone (Z or +hh:mm) belongs");
  }
  if (at != s.size()) throw bad("trailing " + quoted(s.substr(at)));
  const std::int64_t seconds =
      daysFromCivil(year, month, day) * 86400 + hour * 3600 + minute * 60 + second - offset_seconds + (carry ? 1 : 0);
  if (seconds < 0) throw OutOfRangeError("ISO 8601 stamp " + quoted(field) + ": before 1970-01-01T00:00:00Z");
  return checkedAdd(checkedScale(seconds, kNanosecondsPerSecond, field), ns, field);
}

/// The layout of a bench log: '#' comments, no preamble, the delimiter and header as given.
TextLayout benchLayout(char delimiter, bool has_header) {
  TextLayout layout;
  layout.delimiter = delimiter;
  layout.has_header = has_header;
  return layout;
}

}  // namespace

std::string excerpt(std::string_view text) {
  std::size_t keep = std::min(text.size(), kQuotedBytes);
  if (keep < text.size()) {
    while (keep > 0 && (static_cast<unsigned char>(text[keep]) & 0xC0) == 0x80) --keep;  // a continuation byte
  }
  std::string out;
  out.reserve(keep + 32);
  for (const char c : text.substr(0, keep)) {
    const auto byte = static_cast<unsigned char>(c);
    if (byte < 0x20 || byte == 0x7F) {
      static const char kHex[] = "0123456789ABCDEF";
      out += {'\\', 'x', kHex[byte >> 4], kHex[byte & 0xF]};
    } else {
      out += c;
    }
  }
  if (keep < text.size()) out += "... (" + std::to_string(text.size()) + " bytes)";
  return out;
}

DescriptorInputBuffer::DescriptorInputBuffer(int fd) : fd_(fd), buffer_(new char[kBufferBytes]) {}

DescriptorInputBuffer::~DescriptorInputBuffer() { ::close(fd_); }

DescriptorInputBuffer::int_type DescriptorInputBuffer::underflow() {
  for (;;) {
    const ssize_t n = ::read(fd_, buffer_.get(), kBufferBytes);
    if (n > 0) {
      setg(buffer_.get(), buffer_.get(), buffer_.get() + n);
      return traits_type::to_int_type(buffer_[0]);
    }
    if (n == 0) return traits_type::eof();
    if (errno != EINTR) throw std::runtime_error(std::string("read error: ") + std::strerror(errno));
  }
}

std::string secondsText(core::Nanoseconds ns) {
  const char* sign = ns < 0 ? "-" : "";
  const auto magnitude = ns < 0 ? -static_cast<std::uint64_t>(ns) : static_cast<std::uint64_t>(ns);
  char fraction[16];
  std::snprintf(fraction, sizeof fraction, ".%09llu", static_cast<unsigned long long>(magnitude % 1000000000ULL));
  return sign + std::to_string(magnitude / 1000000000ULL) + fraction;
}

StampFormat parseStampFormat(const std::string& name) {
  if (name == "auto") return StampFormat::kAuto;
  if (name == "s") return StampFormat::kSeconds;
  if (name == "ns") return StampFormat::kNanoseconds;
  if (name == "iso") return StampFormat::kIso8601;
  throw std::invalid_argument("stamp format must be auto, s, ns or iso, got '" + name + "'");
}

double parseNumber(std::string_view field) {
  std::string_view s = trim(field);
  if (!s.empty() && s.front() == '+') s.remove_prefix(1);  // from_chars takes no '+'
  double value = 0.0;
  const auto r = std::from_chars(s.data(), s.data() + s.size(), value);
  if (s.empty()) throw FieldError("empty field where a number belongs");
  if (r.ec == std::errc::result_out_of_range) throw FieldError(quoted(field) + " is out of the double range");
  if (r.ec != std::errc() || r.ptr != s.data() + s.size()) throw FieldError(quoted(field) + " is not a number");
  return value;
}

core::Nanoseconds parseStamp(std::string_view field, StampFormat format) {
  const std::string_view s = trim(field);
  if (s.empty()) throw FieldError("empty stamp");
  if (s.front() == '-') throw OutOfRangeError("stamp " + quoted(field) + " is negative");
  if (format == StampFormat::kAuto) {
    format = s.find_first_of("Tt") != std::string_view::npos ? StampFormat::kIso8601
             : s.find('.') != std::string_view::npos         ? StampFormat::kSeconds
                                                             : StampFormat::kNanoseconds;
  }
  switch (format) {
    case StampFormat::kSeconds:
      return parseSeconds(s, field);
    case StampFormat::kNanoseconds:
      if (!allDigits(s)) throw FieldError("stamp " + quoted(field) + " is not a whole number of nanoseconds");
      return digitsValue(s, field);
    case StampFormat::kIso8601:
    default:
      return parseIso8601(s, field);
  }
}

LineTooLongError::LineTooLongError()
    : std::runtime_error("more than " + std::to_string(kMaxLineBytes) + " bytes (" +
                         std::to_string(kMaxLineBytes >> 20) + " MiB), the limit of a line") {}

CsvReader::CsvReader(std::istream& in, std::string name, char delimiter, bool has_header)
    : CsvReader(in, std::move(name), benchLayout(delimiter, has_header)) {}

CsvReader::CsvReader(std::istream& in, std::string name, const TextLayout& layout)
    : in_(in),
      name_(std::move(name)),
      delimiter_(layout.delimiter),
      comment_(layout.comment),
      line_buffer_(new char[kMaxLineBytes + 2]) {
  const bool has_header = layout.has_header;
  bool found = false;
  try {
    for (std::size_t i = 0; i <= layout.preamble_lines; ++i) {
      found = readLine();
      if (!found) break;
      if (i < layout.preamble_lines) preamble_.push_back({line_, std::string(text_)});
    }
  } catch (const LineTooLongError& e) {
    throw std::runtime_error(name_ + ":" + std::to_string(line_) + ": line too long: " + e.what() +
                             (has_header ? " (is this a log? no header row within the limit)" : ""));
  }
  if (!found) {
    const std::string lacking = preamble_.size() < layout.preamble_lines
                                    ? ": " + std::to_string(preamble_.size()) + " of its " +
                                          std::to_string(layout.preamble_lines) + " header lines"
                                    : (has_header ? ": no header row" : ": no record");
    throw std::runtime_error(name_ + lacking + " (the file is empty or only comments" +
                             (layout.preamble_lines > 0 ? " after them)" : ")"));
  }
  if (delimiter_ == 0) {
    int kinds = 0;
    for (char c : {',', ';', '\t'}) {
      if (text_.find(c) != std::string::npos) {
        delimiter_ = c;
        ++kinds;
      }
    }
    if (kinds == 0 && layout.blanks_when_no_delimiter) {
      delimiter_ = kWhitespace;
    } else if (kinds != 1) {
      throw std::runtime_error(name_ + ":" + std::to_string(line_) + ": cannot tell the delimiter from the header (" +
                               (kinds == 0 ? "none" : "several") + " of ',' ';' tab): give --delimiter");
    }
  }
  split();
  if (has_header) {
    for (std::string_view f : fields_) header_.emplace_back(f);
  } else {
    header_.assign(fields_.size(), std::string());
    first_record_pending_ = true;
  }
}

bool CsvReader::readLine() {
  for (;;) {
    if (discard_rest_) {
      discard_rest_ = false;
      in_.ignore(std::numeric_limits<std::streamsize>::max(), '\n');  // read past, nothing stored
      bytes_ += static_cast<std::uint64_t>(in_.gcount());
    }
    // getline stores at most kMaxLineBytes + 1 bytes; it stops with failbit alone when the buffer is
    // full before the line ends, with eofbit when the file ends without a line end.
    in_.getline(line_buffer_.get(), static_cast<std::streamsize>(kMaxLineBytes + 2), '\n');
    const auto extracted = static_cast<std::size_t>(in_.gcount());
    if (in_.bad() || (extracted == 0 && !in_.good())) break;  // a read error, or the end of the file
    const bool cut_short = in_.fail() && !in_.eof();
    const bool ended = !in_.fail() && !in_.eof();  // the line end was extracted with the line
    std::size_t length = ended ? extracted - 1 : extracted;
    ++line_;
    bytes_ += extracted;
    if (cut_short) {
      in_.clear();
      discard_rest_ = true;
      throw LineTooLongError();
    }
    if (length > kMaxLineBytes && !(length == kMaxLineBytes + 1 && line_buffer_[kMaxLineBytes] == '\r')) {
      throw LineTooLongError();
    }
    text_ = std::string_view(line_buffer_.get(), length);
    if (line_ == 1 && text_.substr(0, 3) == "\xEF\xBB\xBF") text_.remove_prefix(3);  // UTF-8 byte-order mark
    const std::string_view t = trim(text_);
    if (t.empty() || (!comment_.empty() && t.substr(0, comment_.size()) == comment_)) continue;
    return true;
  }
  // A failed read ends getline like the end of the file: never take a cut-off log for a whole one.
  if (in_.bad()) throw ReadError(name_ + ": read error after line " + std::to_string(line_) + " (an I/O error)");
  return false;
}

void CsvReader::split() {
  fields_.clear();
  std::string_view rest(text_);
  if (delimiter_ == kWhitespace) {
    // Runs of blanks and tabs part the fields; the line is not empty (readLine skips those).
    for (;;) {
      const std::size_t begin = rest.find_first_not_of(" \t\r");
      if (begin == std::string_view::npos) break;
      rest.remove_prefix(begin);
      const std::size_t cut = rest.find_first_of(" \t\r");
      std::string_view f = rest.substr(0, cut);
      if (f.size() >= 2 && f.front() == '"' && f.back() == '"') f = f.substr(1, f.size() - 2);
      fields_.push_back(f);
      if (cut == std::string_view::npos) break;
      rest.remove_prefix(cut);
    }
    return;
  }
  for (;;) {
    const std::size_t cut = rest.find(delimiter_);
    std::string_view f = trim(rest.substr(0, cut));
    if (f.size() >= 2 && f.front() == '"' && f.back() == '"') f = f.substr(1, f.size() - 2);
    fields_.push_back(f);
    if (cut == std::string_view::npos) break;
    rest.remove_prefix(cut + 1);
  }
}

bool CsvReader::next() {
  if (first_record_pending_) {
    first_record_pending_ = false;
    return true;
  }
  if (!readLine()) return false;
  split();
  return true;
}

int CsvReader::column(const std::string& wanted) const {
  if (!wanted.empty() && wanted.front() == '#') {
    const std::string_view digits = std::string_view(wanted).substr(1);
    int index = 0;
    const auto r = std::from_chars(digits.data(), digits.data() + digits.size(), index);
    if (!allDigits(digits) || r.ec != std::errc() || index < 1 || index > static_cast<int>(header_.size())) {
      throw std::runtime_error(name_ + ": column " + quoted(wanted) + " is not one of #1..#" +
                               std::to_string(header_.size()));
    }
    return index - 1;
  }
  auto lower = [](std::string s) {
    std::transform(s.begin(), s.end(), s.begin(), [](unsigned char c) { return std::tolower(c); });
    return s;
  };
  int found = -1;
  for (std::size_t i = 0; i < header_.size(); ++i) {
    if (header_[i].empty() || lower(header_[i]) != lower(wanted)) continue;
    if (found >= 0) throw std::runtime_error(name_ + ": the header names column " + quoted(wanted) + " twice");
    found = static_cast<int>(i);
  }
  return found;
}

}  // namespace csv
}  // namespace hrg_gyro

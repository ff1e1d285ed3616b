// A streaming reader of the delimited text logs a test bench writes (one record a line, a header
// row naming the columns), and the strict field parsers behind `hrg_bag import`. It holds one line
// at a time in a buffer of fixed size (kMaxLineBytes), so a log of any size, even one without a
// single line end, is read in constant memory. Numbers are read whole ("1.5abc" and "1,5" are
// errors, never 1.5 or 1), stamps exactly as integer nanoseconds. Messages quote fields and header
// names cut to an excerpt. An IMU's text log is laid out more freely (other comment prefixes, fields
// apart by blanks, header lines of numbers before the records): TextLayout says how. No ROS.
#pragma once

#include <cstdint>
#include <istream>
#include <memory>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include "hrg_gyro/core/common/units.h"

namespace hrg_gyro {
namespace csv {

/// How the stamp column is written. kAuto decides per field: an ISO 8601 date-time when it holds a
/// 'T', seconds when it holds a '.', otherwise a whole number of nanoseconds.
enum class StampFormat { kAuto, kSeconds, kNanoseconds, kIso8601 };
/// "auto", "s", "ns", "iso"; std::invalid_argument otherwise.
StampFormat parseStampFormat(const std::string& name);

/// The longest line a log may hold, in bytes without its line end ("\n" or "\r\n"). A record of
/// eight numbers takes about 150; the limit only stops a file that is no log (a binary file, one
/// without line ends) from being held whole.
constexpr std::size_t kMaxLineBytes = std::size_t{1} << 20;

/// At most this many bytes of a field or a header name are quoted in a message (excerpt()).
constexpr std::size_t kQuotedBytes = 64;
/// `text` for a message: whole up to kQuotedBytes, else its first kQuotedBytes bytes (never half a
/// UTF-8 character) and "... (N bytes)"; control characters as \xNN, so that a binary field can
/// neither flood nor drive the terminal.
std::string excerpt(std::string_view text);

/// A field that is not what its column holds; the message says why (the caller adds file:line).
struct FieldError : std::invalid_argument {
  using std::invalid_argument::invalid_argument;
};
/// A stamp that reads as a number but lies outside what a stamp can be: negative, before 1970, or
/// beyond the signed 64-bit nanosecond range.
struct OutOfRangeError : FieldError {
  using FieldError::FieldError;
};
/// A line longer than kMaxLineBytes; the message says so (the caller adds file:line).
struct LineTooLongError : std::runtime_error {
  LineTooLongError();
};

/// The log could not be read to its end (an I/O error); the message names the file.
struct ReadError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

/// An input stream buffer over a file descriptor, which it owns (closes): for a log opened with
/// core::openRegularFileForReading, which an std::ifstream cannot take.
class DescriptorInputBuffer : public std::streambuf {
 public:
  explicit DescriptorInputBuffer(int fd);
  ~DescriptorInputBuffer() override;
  DescriptorInputBuffer(const DescriptorInputBuffer&) = delete;
  DescriptorInputBuffer& operator=(const DescriptorInputBuffer&) = delete;

 protected:
  int_type underflow() override;

 private:
  static constexpr std::size_t kBufferBytes = 64 << 10;
  int fd_;
  std::unique_ptr<char[]> buffer_;
};

/// A decimal number, the whole field ("nan" allowed here; the caller decides where NaN may stand).
/// Surrounding blanks are ignored; "1.5abc", "1,5", "", "0x10" throw FieldError.
double parseNumber(std::string_view field);
/// A stamp as nanoseconds since the Unix epoch, read without floating point:
///   seconds      "1700000000.123456789" (decimals beyond the 9th round to the nearest ns)
///   nanoseconds  "1700000000123456789"
///   ISO 8601     "2026-11-23T10:00:00.123456789Z" or with an offset "+01:00", "-0530"; a
///                date-time without a zone is refused (local time would be a guess).
/// Negative stamps, stamps before 1970 and values beyond the signed 64-bit nanosecond range throw
/// OutOfRangeError, anything else that is not a stamp FieldError.
core::Nanoseconds parseStamp(std::string_view field, StampFormat format);
/// Nanoseconds as exact decimal seconds, for messages: 4294967296000000000 -> "4294967296.000000000".
std::string secondsText(core::Nanoseconds ns);

/// The delimiter value that splits a line at runs of blanks and tabs (leading and trailing ones
/// ignored), as IMU logs written by `fprintf("%d %d ...")` or MATLAB's `save -ascii` have them.
constexpr char kWhitespace = ' ';

/// How the lines of a delimited file are laid out. The defaults are a bench log's (the channel and
/// turntable logs of `hrg_bag import`); an IMU's log sets the rest.
struct TextLayout {
  /// ',' ';' '\t', kWhitespace, or 0: taken from the header line (the one of ',' ';' '\t' it holds).
  char delimiter = 0;
  /// With delimiter 0, a header line holding none of ',' ';' '\t' is split at blanks instead of
  /// refused (a log of numbers apart by spaces); several of them are refused either way.
  bool blanks_when_no_delimiter = false;
  /// A line whose first non-blank characters are this prefix is a comment, wherever it stands (empty:
  /// no line is).
  std::string comment = "#";
  /// Lines (neither empty nor comments) before the header row or the first record, kept whole for the
  /// caller (an IMU log's header lines of numbers: its site, interval, scales).
  std::size_t preamble_lines = 0;
  bool has_header = true;
};

/// A line of the file kept whole, with its 1-based number.
struct NumberedLine {
  std::uint64_t number = 0;
  std::string text;
};

/// The reader of one delimited file. The first line that is neither empty nor a comment ('#'
/// first) is the header; every following such line is a record. A file without a header row
/// (`has_header` false) has columns named only by index ("#N"), as many as its first record's.
/// TextLayout's preamble lines, when asked for, come before the header (or the first record).
/// A UTF-8 byte-order mark (as spreadsheet programs write) before the first line is ignored.
/// No line may be longer than kMaxLineBytes: the reader never holds more of a line than that.
class CsvReader {
 public:
  /// `delimiter` 0: taken from the header line (the one of ',' ';' '\t' it holds; a header holding
  /// none or several of them is refused: give it). std::runtime_error (naming `name`) on an empty
  /// file, an undecidable delimiter or a first line longer than kMaxLineBytes.
  CsvReader(std::istream& in, std::string name, char delimiter = 0, bool has_header = true);
  /// The same for a file laid out as `layout` says; a file that ends within the preamble is refused
  /// like an empty one.
  CsvReader(std::istream& in, std::string name, const TextLayout& layout);

  const std::vector<std::string>& header() const { return header_; }
  /// The layout's preamble lines, in file order.
  const std::vector<NumberedLine>& preamble() const { return preamble_; }
  char delimiter() const { return delimiter_; }
  /// Reads the next record; false at the end of the file, ReadError when reading failed before it.
  /// A line longer than kMaxLineBytes throws LineTooLongError, line() being its number; the next
  /// call goes on after it (the rest of the line is read past, never stored).
  bool next();
  /// The fields of the current record, blanks and surrounding double quotes removed.
  const std::vector<std::string_view>& fields() const { return fields_; }
  /// 1-based line number of the current record (or of the header before the first next()).
  std::uint64_t line() const { return line_; }
  std::uint64_t bytesRead() const { return bytes_; }
  const std::string& name() const { return name_; }

  /// The index of a column: "#N" is the N-th column (1-based), anything else a header name (never
  /// found in a file without a header)
  /// compared without regard to case. -1 when no header name matches; std::runtime_error for a
  /// "#N" out of range or a name the header holds twice.
  int column(const std::string& wanted) const;

 private:
  bool readLine();
  void split();

  std::istream& in_;
  std::string name_;
  char delimiter_;
  std::string comment_;
  std::vector<NumberedLine> preamble_;
  /// The current line, in a buffer of kMaxLineBytes + 2 bytes (one more to tell a line of the limit
  /// ended by "\r\n" from a longer one, and getline's terminating zero) allocated once: the pages no
  /// line reaches are never touched.
  std::unique_ptr<char[]> line_buffer_;
  std::string_view text_;
  bool discard_rest_ = false;  ///< the last line was too long: its rest is still to be read past
  std::vector<std::string_view> fields_;
  std::vector<std::string> header_;
  std::uint64_t line_ = 0;
  std::uint64_t bytes_ = 0;
  bool first_record_pending_ = false;  ///< without a header, the first line read is already a record
};

}  // namespace csv
}  // namespace hrg_gyro

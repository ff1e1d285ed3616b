// CSV text formatted straight into one growing buffer (no per-field string or stream call), for
// the CSV outputs of hrg_bag process. Numbers in the shortest form that reads back to the same
// double (std::to_chars), several times faster than printf's %.17g and just as exact.
#pragma once

#include <charconv>
#include <cstdint>
#include <cstdio>
#include <string>

namespace hrg_gyro {
namespace bag_tools {

class CsvText {
 public:
  void clear() { used_ = 0; }
  const char* data() const { return buffer_.data(); }
  std::size_t size() const { return used_; }
  /// Room for one row (at most 19 fields of 32 characters) at the end of the buffer.
  void beginRow() {
    if (buffer_.size() < used_ + kRowRoom) buffer_.resize(2 * (used_ + kRowRoom));
    cursor_ = buffer_.data() + used_;
    first_ = true;
  }
  void number(double v, bool present = true) {
    separator();
    if (present) cursor_ = std::to_chars(cursor_, cursor_ + 32, v).ptr;
  }
  void integer(std::uint64_t v) {
    separator();
    cursor_ = std::to_chars(cursor_, cursor_ + 32, v).ptr;
  }
  /// sec.nsec with nine digits after the point, as printf's "%u.%09u".
  void stamp(std::uint32_t sec, std::uint32_t nsec) {
    separator();
    if (nsec >= 1000000000u) {  // not normalised: printf's own form, as many digits as it takes
      cursor_ += std::snprintf(cursor_, 32, "%u.%09u", sec, nsec);
      return;
    }
    cursor_ = std::to_chars(cursor_, cursor_ + 16, sec).ptr;
    *cursor_++ = '.';
    for (int digit = 8; digit >= 0; --digit, nsec /= 10) cursor_[digit] = static_cast<char>('0' + nsec % 10);
    cursor_ += 9;
  }
  void text(const char* t) {
    separator();
    while (*t != '\0') *cursor_++ = *t++;
  }
  void endRow() {
    *cursor_++ = '\n';
    used_ = static_cast<std::size_t>(cursor_ - buffer_.data());
  }

 private:
  static constexpr std::size_t kRowRoom = 19 * 33 + 1;
  void separator() {
    if (!first_) *cursor_++ = ',';
    first_ = false;
  }

  std::string buffer_;
  std::size_t used_ = 0;
  char* cursor_ = nullptr;
  bool first_ = true;
};

}  // namespace bag_tools
}  // namespace hrg_gyro

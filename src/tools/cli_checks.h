// Argument checks shared by the offline tools (hrg_bag, hrg_session), on top of CLI11.
//
// CLI11's own number conversion is lenient: it accepts "nan", "inf", hexadecimal and octal
// integers, leading blanks, and reads "-1" as 18446744073709551615 for an unsigned option. The
// validators here read every number whole, in decimal, and rewrite it in its canonical form before
// CLI11 converts it, so what the tool uses is exactly what was typed; the range validators then
// refuse values outside the meaningful range. A refusal names the option (CLI11 prefixes it) and
// says why; runCommandLine turns it into exit code 2.
#pragma once

#include <CLI/CLI.hpp>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <iostream>
#include <limits>
#include <string>

namespace hrg_gyro {
namespace tools {

/// A finite decimal number, the whole argument ("12x", "nan", "inf", "" refused).
inline CLI::Validator finiteNumber() {
  return CLI::Validator(
      [](std::string& text) -> std::string {
        double value = 0.0;
        const char* end = text.data() + text.size();
        const auto r = std::from_chars(text.data(), end, value);
        if (text.empty() || r.ec != std::errc() || r.ptr != end || !std::isfinite(value)) {
          return "expects a finite number, got '" + text + "'";
        }
        char canonical[32];
        text.assign(canonical, std::to_chars(canonical, canonical + sizeof canonical, value).ptr);
        return "";
      },
      "");
}

/// A whole decimal number in [low, high], the whole argument ("12x", "1e3", "0x10", "" refused).
inline CLI::Validator wholeNumber(long long low, long long high) {
  return CLI::Validator(
      [low, high](std::string& text) -> std::string {
        long long value = 0;
        const char* end = text.data() + text.size();
        const auto r = std::from_chars(text.data(), end, value);
        if (text.empty() || r.ec != std::errc() || r.ptr != end || value < low || value > high) {
          return "expects a whole number in [" + std::to_string(low) + ", " + std::to_string(high) + "], got '" + text +
                 "'";
        }
        text = std::to_string(value);
        return "";
      },
      "");
}

/// A whole decimal number in [0, 2^64 - 1] (random seeds).
inline CLI::Validator unsignedWholeNumber() {
  return CLI::Validator(
      [](std::string& text) -> std::string {
        std::uint64_t value = 0;
        const char* end = text.data() + text.size();
        const auto r = std::from_chars(text.data(), end, value);
        if (text.empty() || r.ec != std::errc() || r.ptr != end) {
          return "expects a whole number in [0, " + std::to_string(std::numeric_limits<std::uint64_t>::max()) +
                 "], got '" + text + "'";
        }
        text = std::to_string(value);
        return "";
      },
      "");
}

/// Shortest decimal text of a double (messages).
inline std::string shortest(double value) {
  char text[32];
  return std::string(text, std::to_chars(text, text + sizeof text, value).ptr);
}

/// A number strictly above `low` (after finiteNumber()).
inline CLI::Validator above(double low) {
  return CLI::Validator(
      [low](std::string& text) -> std::string {
        double value = 0.0;
        std::from_chars(text.data(), text.data() + text.size(), value);
        if (!(value > low)) return "must be above " + shortest(low) + ", got " + text;
        return "";
      },
      "");
}

/// Refuses an empty value ("--channels-topic ''").
inline CLI::Validator notEmpty() {
  return CLI::Validator(
      [](std::string& text) -> std::string { return text.empty() ? std::string("must not be empty") : std::string(); },
      "");
}

/// A frame_id for the written messages: not empty, no blank or control character (a newline would
/// split the CSV row or the log line it is written into), and no leading '/' (tf2 refuses such a
/// frame id in every lookup).
inline CLI::Validator frameId() {
  return CLI::Validator(
      [](std::string& text) -> std::string {
        if (text.empty()) return "must not be empty";
        for (const char c : text) {
          const auto byte = static_cast<unsigned char>(c);
          if (byte <= 0x20 || byte == 0x7F) return "must not hold blanks or control characters (a newline, a tab)";
        }
        if (text.front() == '/') return "must not start with '/' (tf2 refuses such a frame id)";
        return "";
      },
      "");
}

/// Parses argv; --help prints the help on stdout and gives 0, a refused argument prints
/// "<tool>: <option>: <reason>" on stderr and gives 2. Otherwise -1: go on.
inline int parseCommandLine(CLI::App& app, int argc, char** argv) {
  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForAllHelp& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    std::string name = app.get_name();  // with the subcommand, when one was recognised
    for (const CLI::App* sub : app.get_subcommands()) name += " " + sub->get_name();
    std::cerr << name << ": " << e.what() << "\n(" << name << " --help for the options)\n";
    return 2;
  }
  return -1;
}

}  // namespace tools
}  // namespace hrg_gyro

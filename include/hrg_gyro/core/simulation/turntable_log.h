// What the table controller logs of the true table motion, as a real controller does it: records at
// its own log rate (or, by default, one with every output sample of the gyro, stamped like it), the
// angle read through an encoder (white noise, quantisation to whole counts), the rate either the
// drive's (true) rate or the logged angle differenced at the log rate, lost records (StreamDelivery),
// and glitched records (a NaN or absurd rate, an infinite angle, a zero or backward stamp) at a
// given rate per record, and an error of the angle each rest stops at (an indexer's position error:
// the logged angle of rest k is the true one plus e_k, given or drawn). The controller may stamp on its own computer's
// clock (TableClockConfig): an offset from the gyro's clock, a rate error, steps and white jitter; the records are
// still taken at their true times, only their stamps move (out of order when the jitter exceeds the spacing: they are
// left so, as a real log would hold them). Each random effect draws from its own seeded stream, so a scenario gives the
// same log run after run and switching one effect on leaves the others' draws unchanged. Defaults: the exact table
// state and stamps, nothing lost, nothing glitched.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "hrg_gyro/core/common/units.h"
#include "hrg_gyro/core/common/yaml_field.h"
#include "hrg_gyro/core/simulation/gaussian_noise.h"
#include "hrg_gyro/core/simulation/stream_delivery.h"

namespace hrg_gyro {
namespace core {

/// Where the logged rate comes from.
enum class LoggedRate {
  kTable,             ///< the drive's rate (the true table rate)
  kDifferencedAngle,  ///< (logged angle - previous logged angle) / log period, stamped at the later one
};

/// The kinds of glitched record, in the order of TurntableGlitchRates.
enum class TurntableGlitch { kNanRate, kAbsurdRate, kInfiniteAngle, kZeroStamp, kBackwardStamp, kNone };
constexpr int kTurntableGlitchKinds = 5;

/// Rate at which each kind of glitch replaces a record (a probability per record).
struct TurntableGlitchRates {
  std::array<double, kTurntableGlitchKinds> per_record{};  ///< indexed by TurntableGlitch
  double total() const;
};

/// The rate an absurd-rate glitch reports (no table turns at 1000 rad/s), and how far back a
/// backward-stamp glitch puts its stamp.
constexpr double kAbsurdTableRate = 1000.0;  // rad/s
constexpr double kBackwardStampJump = 0.5;   // s

/// A step of the controller's clock (an NTP correction, a manual reset): from true time `at` on, its
/// stamps are `size` later.
struct TableClockStep {
  double at = 0.0;    ///< s from the scenario start
  double size = 0.0;  ///< s (negative: the clock steps back)
};

/// The controller's own clock: a record taken at true time t (s from the scenario start) is stamped
///   exact stamp + offset + rate_error t + (the steps at or before t) + jitter N(0, 1).
/// Default: the gyro's clock, exactly.
struct TableClockConfig {
  double offset = 0.0;      ///< s, the controller's clock minus the gyro's
  double jitter = 0.0;      ///< s, standard deviation of white stamp jitter
  double rate_error = 0.0;  ///< s per s: the controller's clock runs 1 + rate_error times as fast
  std::vector<TableClockStep> steps;

  bool enabled() const { return offset != 0.0 || jitter != 0.0 || rate_error != 0.0 || !steps.empty(); }
  /// The clock's error at true time t without its jitter, s.
  double errorAt(double t) const;
  /// Parses turntable.log.clock. Throws ConfigError naming the key.
  static TableClockConfig parse(const YamlField& clock);
};

/// Each rest's angle error: while the table is at rest (its true rate exactly 0), the logged angle is
/// the true one plus e_k, k counting the rests from 0 in the order the table comes to them (a fixture
/// move of a triad session is a rest too). e_k is errors[k] when given, else drawn N(0, sigma) from a
/// stream of its own; every rest takes one draw whether given or not, so giving one rest's error
/// changes no other's. The logged angle steps by e_k when the table stops and back when it starts.
struct RestAngleErrorConfig {
  std::vector<double> errors;  ///< rad, given, rest by rest
  double sigma = 0.0;          ///< rad, 1 sigma of the rests beyond `errors`
  bool enabled() const { return !errors.empty() || sigma > 0.0; }
};

struct TurntableLogConfig {
  double rate = 0.0;              ///< Hz; 0: one record with every output sample, at its stamp
  double angle_noise = 0.0;       ///< rad, white noise of the logged angle
  double angle_resolution = 0.0;  ///< rad per encoder count; 0: not quantised
  RestAngleErrorConfig rest_errors;
  LoggedRate logged_rate = LoggedRate::kTable;
  DeliveryConfig delivery;  ///< lost records
  TurntableGlitchRates glitches;
  TableClockConfig clock;  ///< the controller's clock (default: the gyro's)

  /// Parses turntable.log. Throws ConfigError naming the key.
  static TurntableLogConfig parse(const YamlField& log);
};

struct TurntableLogRecord {
  std::uint64_t index = 0;  ///< the controller's record count (a lost record leaves a gap in it)
  double time = 0.0;        ///< true time of the record, s from the scenario start
  Nanoseconds stamp = 0;    ///< as logged: on the controller's clock (a stamp glitch spoils it)
  double angle = 0.0;       ///< rad, as logged
  double rate = 0.0;        ///< rad/s, as logged
  TurntableGlitch glitch = TurntableGlitch::kNone;
};

struct TurntableLogCounters {
  std::uint64_t logged = 0;                                     ///< records the controller made
  std::uint64_t lost = 0;                                       ///< of those, not delivered
  std::array<std::uint64_t, kTurntableGlitchKinds> glitches{};  ///< delivered glitched records by kind
};

class TurntableLogger {
 public:
  TurntableLogger(const TurntableLogConfig& config, std::uint64_t seed);

  const TurntableLogConfig& config() const { return config_; }
  const TurntableLogCounters& counters() const { return counters_; }

  /// Logs the true table state (angle rad, rate rad/s) of true time t (s from the scenario start,
  /// `stamp` its exact stamp on the gyro's clock): appends the record, stamped on the controller's
  /// clock, to `out` unless it is lost.
  void log(double t, Nanoseconds stamp, double angle, double rate, std::vector<TurntableLogRecord>* out);

 private:
  TurntableLogConfig config_;
  GaussianNoise encoder_noise_;
  GaussianNoise glitch_draws_;
  GaussianNoise clock_jitter_;
  GaussianNoise rest_draws_;
  StreamDelivery delivery_;
  bool at_rest_ = false;
  std::size_t rests_ = 0;    // rests begun so far
  double rest_error_ = 0.0;  // rad, the current rest's
  bool has_previous_ = false;
  double previous_time_ = 0.0;
  double previous_angle_ = 0.0;  // as logged, before any glitch
  TurntableLogCounters counters_;
};

}  // namespace core
}  // namespace hrg_gyro

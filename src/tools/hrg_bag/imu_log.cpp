#include "imu_log.h"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <stdexcept>

#include "hrg_gyro/core/common/units.h"
#include "hrg_gyro/core/model/earth_rate.h"

namespace hrg_gyro {
namespace csv {
namespace {

constexpr double kDegree = core::kPi / 180.0;
constexpr double kArcsecond = kDegree / 3600.0;  // PSINS's glv.sec, bit for bit

std::string fixed(double value, int decimals) {
  char text[64];
  std::snprintf(text, sizeof text, "%.*f", decimals, value);
  return text;
}

std::string upper(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(), [](unsigned char c) { return std::toupper(c); });
  return s;
}

/// The log's time of a time column: signed decimal seconds, read exactly as nanoseconds.
core::Nanoseconds signedSeconds(std::string_view field) {
  std::string_view s = field;
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t')) s.remove_prefix(1);
  const bool negative = !s.empty() && s.front() == '-';
  if (!s.empty() && (s.front() == '-' || s.front() == '+')) s.remove_prefix(1);
  if (!s.empty() && (s.front() == '-' || s.front() == '+')) throw FieldError("'" + excerpt(field) + "' is no time");
  const core::Nanoseconds magnitude = parseStamp(s, StampFormat::kSeconds);
  return negative ? -magnitude : magnitude;
}

const char* const kGyroKeys[3] = {"gx", "gy", "gz"};
const char* const kAccelKeys[3] = {"ax", "ay", "az"};

}  // namespace

SensorUnit gyroUnit(const std::string& name) {
  if (name == "rad/s") return {Quantity::kRate, 1.0};
  if (name == "deg/s") return {Quantity::kRate, kDegree};
  if (name == "deg/h") return {Quantity::kRate, kDegree / 3600.0};
  if (name == "rad") return {Quantity::kIncrement, 1.0};
  if (name == "deg") return {Quantity::kIncrement, kDegree};
  if (name == "arcsec") return {Quantity::kIncrement, kArcsecond};
  throw std::invalid_argument("gyro unit '" + excerpt(name) +
                              "' is none of rad/s, deg/s, deg/h (rates), rad, deg, arcsec (increments)");
}

SensorUnit accelUnit(const std::string& name, double gravity) {
  if (name == "m/s^2") return {Quantity::kRate, 1.0};
  if (name == "g") return {Quantity::kRate, gravity};
  if (name == "mg") return {Quantity::kRate, 1e-3 * gravity};
  if (name == "ug") return {Quantity::kRate, 1e-6 * gravity};
  if (name == "m/s") return {Quantity::kIncrement, 1.0};
  if (name == "g*s") return {Quantity::kIncrement, gravity};
  if (name == "mg*s") return {Quantity::kIncrement, 1e-3 * gravity};
  // PSINS's scale: imu(3,4:6) * (1e-6 * g), so a count of 125 ug*s is bit for bit PSINS's.
  if (name == "ug*s") return {Quantity::kIncrement, 1e-6 * gravity};
  throw std::invalid_argument("accelerometer unit '" + excerpt(name) +
                              "' is none of m/s^2, g, mg, ug (rates), m/s, g*s, mg*s, ug*s (increments)");
}

AxisMatrix frameAxes(const std::string& axes) {
  std::string name = upper(axes);
  if (name == "NED") name = "FRD";
  if (name == "ENU") name = "RFU";
  AxisMatrix m{};
  bool used[3] = {false, false, false};
  if (name.size() != 3) {
    throw std::invalid_argument("frame '" + excerpt(axes) +
                                "' is not three letters of F B L R U D (the log's x, y, z: FLU, RFU, FRD, NED, ...)");
  }
  for (int axis = 0; axis < 3; ++axis) {
    int line = -1;
    double sign = 1.0;
    switch (name[axis]) {
      case 'F':
        line = 0;
        break;
      case 'B':
        line = 0, sign = -1.0;
        break;
      case 'L':
        line = 1;
        break;
      case 'R':
        line = 1, sign = -1.0;
        break;
      case 'U':
        line = 2;
        break;
      case 'D':
        line = 2, sign = -1.0;
        break;
      default:
        throw std::invalid_argument("frame '" + excerpt(axes) + "': '" + excerpt(axes.substr(axis, 1)) +
                                    "' is none of F B L R U D");
    }
    if (used[line]) {
      throw std::invalid_argument("frame '" + excerpt(axes) + "' names the " +
                                  (line == 0   ? "forward-back"
                                   : line == 1 ? "left-right"
                                               : "up-down") +
                                  " line twice: three axes need three lines");
    }
    used[line] = true;
    m[line][axis] = sign;  // the log's axis `axis` is the column: its direction in FLU
  }
  return m;
}

AxisMatrix eulerAxes(double roll, double pitch, double yaw) {
  const double cr = std::cos(roll), sr = std::sin(roll), cp = std::cos(pitch), sp = std::sin(pitch);
  const double cy = std::cos(yaw), sy = std::sin(yaw);
  return AxisMatrix{{{cy * cp, cy * sp * sr - sy * cr, cy * sp * cr + sy * sr},
                     {sy * cp, sy * sp * sr + cy * cr, sy * sp * cr - cy * sr},
                     {-sp, cp * sr, cp * cr}}};
}

void checkSite(const Site& site) {
  if (!(std::abs(site.latitude_deg) <= 90.0)) {
    throw std::invalid_argument("latitude " + shortestText(site.latitude_deg) + " deg is outside [-90, 90]");
  }
  if (!(std::abs(site.longitude_deg) <= 180.0)) {
    throw std::invalid_argument("longitude " + shortestText(site.longitude_deg) + " deg is outside [-180, 180]");
  }
  if (std::isinf(site.height_m))
    throw std::invalid_argument("height " + shortestText(site.height_m) + " m is not finite");
}

double PsinsHeader::trueHeadingDeg() const {
  // PSINS's yaw turns counter-clockwise from north (a2mat.m); a heading turns clockwise.
  return core::positiveModulo(-yaw_deg, 360.0);
}

PsinsHeader parsePsinsHeader(const std::vector<NumberedLine>& lines, const std::string& name) {
  // Each field with what imufile.m says it is.
  static const char* const kMeaning[3][6] = {
      {"pitch0, deg", "roll0, deg", "yaw0, deg", "VE0, m/s", "VN0, m/s", "VU0, m/s"},
      {"latitude0, deg", "longitude0, deg", "height0, m", "t0, s", "sampling interval, ms", "g, m/s^2"},
      {"gf_x, arcsec/count", "gf_y, arcsec/count", "gf_z, arcsec/count", "af_x, ug*s/count", "af_y, ug*s/count",
       "af_z, ug*s/count"}};
  if (lines.size() != 3) {
    throw std::runtime_error(name + ": a PSINS log has 3 header lines, " + std::to_string(lines.size()) + " given");
  }
  double v[3][6];
  for (int k = 0; k < 3; ++k) {
    std::vector<std::string_view> fields;
    std::string_view rest(lines[k].text);
    for (;;) {
      const std::size_t begin = rest.find_first_not_of(" \t\r");
      if (begin == std::string_view::npos) break;
      rest.remove_prefix(begin);
      const std::size_t cut = rest.find_first_of(" \t\r");
      fields.push_back(rest.substr(0, cut));
      if (cut == std::string_view::npos) break;
      rest.remove_prefix(cut);
    }
    const std::string where =
        name + ":" + std::to_string(lines[k].number) + ": PSINS header line " + std::to_string(k + 1);
    if (fields.size() != 6) {
      throw std::runtime_error(
          where + ": " + std::to_string(fields.size()) + " fields, 6 expected (" + kMeaning[k][0] + " ... " +
          kMeaning[k][5] + ")" +
          (fields.size() == 7 ? "; the variant with a sampling-time dither column is not read" : ""));
    }
    for (int j = 0; j < 6; ++j) {
      const std::string field = where + " field " + std::to_string(j + 1) + " (" + kMeaning[k][j] + ")";
      try {
        v[k][j] = parseNumber(fields[j]);
      } catch (const FieldError& e) {
        throw std::runtime_error(field + ": " + e.what());
      }
      if (!std::isfinite(v[k][j])) throw std::runtime_error(field + ": '" + excerpt(fields[j]) + "' is not finite");
    }
    auto refuse = [&](int j, const std::string& why) {
      throw std::runtime_error(where + " field " + std::to_string(j + 1) + " (" + kMeaning[k][j] +
                               "): " + shortestText(v[k][j]) + " " + why);
    };
    if (k == 1) {
      if (!(std::abs(v[1][0]) <= 90.0)) refuse(0, "is outside [-90, 90]");
      if (!(std::abs(v[1][1]) <= 180.0)) refuse(1, "is outside [-180, 180]");
      if (!(std::abs(v[1][3]) <= 4294967296.0)) refuse(3, "is beyond the 2^32 s a bag's time holds");
      if (!(v[1][4] >= 1e-6 && v[1][4] <= 1e9)) refuse(4, "is no interval (1 ns to 1e6 s)");
      if (!(v[1][5] > 0.0)) refuse(5, "is no gravity (positive)");
    }
    if (k == 2) {
      for (int j = 0; j < 6; ++j) {
        if (v[2][j] == 0.0) refuse(j, "would make every count 0");
      }
    }
  }
  PsinsHeader h;
  h.pitch_deg = v[0][0], h.roll_deg = v[0][1], h.yaw_deg = v[0][2];
  h.ve = v[0][3], h.vn = v[0][4], h.vu = v[0][5];
  h.site = Site{v[1][0], v[1][1], v[1][2]};
  h.t0 = v[1][3], h.interval_ms = v[1][4], h.gravity = v[1][5];
  for (int j = 0; j < 3; ++j) {
    h.gyro_scale[j] = v[2][j];
    h.accel_scale[j] = v[2][3 + j];
  }
  return h;
}

namespace {

TextLayout psinsLayout() {
  TextLayout layout;
  layout.delimiter = kWhitespace;
  layout.comment = "%";
  layout.preamble_lines = 3;
  layout.has_header = false;
  return layout;
}

}  // namespace

ImuLogReader::ImuLogReader(std::istream& in, const std::string& name, const ImuLogSettings& settings,
                           BadRowCounts* skipped)
    : name_(name),
      settings_(settings),
      csv_(in, name, settings.format == ImuLogFormat::kPsins ? psinsLayout() : settings.layout),
      skipped_(skipped) {
  const bool psins = settings.format == ImuLogFormat::kPsins;
  std::map<std::string, std::string> columns = settings.columns;
  if (psins) {
    setup_.psins = parsePsinsHeader(csv_.preamble(), name);
    if (csv_.header().size() != kPsinsFields) {
      throw std::runtime_error(
          name + ":" + std::to_string(csv_.line()) + ": " + std::to_string(csv_.header().size()) +
          " fields, a PSINS row has 6 (gx gy gz ax ay az)" +
          (csv_.header().size() == 7 ? "; the variant with a sampling-time dither column is not read" : ""));
    }
    columns.clear();
    for (int i = 0; i < 3; ++i) {
      columns[kGyroKeys[i]] = "#" + std::to_string(i + 1);
      columns[kAccelKeys[i]] = "#" + std::to_string(i + 4);
    }
  }
  const PsinsHeader* header = setup_.psins ? &*setup_.psins : nullptr;
  has_header_ = !psins && settings.layout.has_header;

  setupUnits(header);
  setupTime(header, columns);
  setupColumns(columns);
  setupAxes(header);
  setupSite(header);
}

void ImuLogReader::setupUnits(const PsinsHeader* header) {
  // Quantities and units: a setting given wins, else the header's, else the default.
  setup_.gravity = settings_.gravity ? *settings_.gravity : header ? header->gravity : kStandardGravity;
  if (!(setup_.gravity > 0.0) || !std::isfinite(setup_.gravity)) {
    throw std::invalid_argument("gravity " + shortestText(setup_.gravity) + " m/s^2 is not a positive number");
  }
  setup_.gyro_unit = settings_.gyro_unit ? *settings_.gyro_unit : header ? "arcsec" : "rad/s";
  setup_.accel_unit = settings_.accel_unit ? *settings_.accel_unit : header ? "ug*s" : "m/s^2";
  setup_.gyro = gyroUnit(setup_.gyro_unit);
  setup_.accel = accelUnit(setup_.accel_unit, setup_.gravity);
  setup_.gyro_scale = settings_.gyro_scale ? *settings_.gyro_scale
                      : header             ? header->gyro_scale
                                           : std::array{1., 1., 1.};
  setup_.accel_scale = settings_.accel_scale ? *settings_.accel_scale
                       : header              ? header->accel_scale
                                             : std::array{1., 1., 1.};
  auto check_scale = [](const char* what, double scale, int axis) {
    if (scale == 0.0 || !std::isfinite(scale)) {
      throw std::invalid_argument(std::string(what) + " scale " + shortestText(scale) + " of the log's " + "xyz"[axis] +
                                  " axis is not a finite non-zero number");
    }
  };
  for (int i = 0; i < 3; ++i) {
    check_scale("gyro", setup_.gyro_scale[i], i);
    check_scale("accelerometer", setup_.accel_scale[i], i);
    setup_.gyro_factor[i] = setup_.gyro_scale[i] * setup_.gyro.to_si;
    setup_.accel_factor[i] = setup_.accel_scale[i] * setup_.accel.to_si;
  }
}

void ImuLogReader::setupTime(const PsinsHeader* header, const std::map<std::string, std::string>& columns) {
  // Time: a time column, else row n closes start + n interval.
  setup_.interval = settings_.interval;
  if (!setup_.interval && header) setup_.interval = header->interval_ms / 1000.0;
  if (setup_.interval && !(*setup_.interval >= 1e-9 && *setup_.interval <= 1e6)) {
    throw std::invalid_argument("interval " + shortestText(*setup_.interval) + " s is outside [1e-9, 1e6] s");
  }
  setup_.start = settings_.start ? *settings_.start : header ? header->t0 : 0.0;
  if (!(std::abs(setup_.start) <= 4294967296.0)) {
    throw std::invalid_argument("start " + shortestText(setup_.start) + " s is beyond the 2^32 s a bag's time holds");
  }
  setup_.epoch = settings_.epoch;
  time_ = setup_.psins ? -1 : findColumn(csv_, columns, has_header_, "time", false);
  setup_.time_column = time_ >= 0;
}

void ImuLogReader::setupColumns(const std::map<std::string, std::string>& columns) {
  // Columns: the gyro's three, the accelerometer's three or none.
  int accel_found = 0;
  std::string accel_names;
  for (int i = 0; i < 3; ++i) {
    gyro_columns_[i] = findColumn(csv_, columns, has_header_, kGyroKeys[i], true);
    accel_columns_[i] = findColumn(csv_, columns, has_header_, kAccelKeys[i], false);
    if (accel_columns_[i] >= 0) {
      ++accel_found;
      accel_names += std::string(accel_names.empty() ? "" : ", ") + kAccelKeys[i];
    }
  }
  if (accel_found != 0 && accel_found != 3) {
    throw std::runtime_error(name_ + ": the accelerometer needs ax, ay and az or none of them, found " + accel_names);
  }
  setup_.accelerometer = accel_found == 3;
  if (!setup_.time_column && !setup_.interval) {
    throw std::invalid_argument(name_ + ": no time column" + (has_header_ ? " ('time' or --column time=...)" : "") +
                                ": give the rows' spacing with --interval S");
  }
  increments_ = setup_.gyro.quantity == Quantity::kIncrement ||
                (setup_.accelerometer && setup_.accel.quantity == Quantity::kIncrement);
}

void ImuLogReader::setupAxes(const PsinsHeader* header) {
  // Axes: to FLU.
  if (settings_.frame && settings_.rotation) {
    throw std::invalid_argument("the log's axes are given twice: a frame (" + *settings_.frame +
                                ") and a rotation; give one");
  }
  if (settings_.rotation) {
    const auto& r = *settings_.rotation;
    for (double angle : r) {
      if (!std::isfinite(angle))
        throw std::invalid_argument("rotation angle " + shortestText(angle) + " is not finite");
    }
    setup_.axes = eulerAxes(r[0], r[1], r[2]);
    setup_.frame = "rotation " + shortestText(r[0]) + "," + shortestText(r[1]) + "," + shortestText(r[2]) + " rad";
  } else {
    setup_.frame = upper(settings_.frame ? *settings_.frame : header ? "RFU" : "FLU");
    setup_.axes = frameAxes(setup_.frame);
  }
}

void ImuLogReader::setupSite(const PsinsHeader* header) {
  // The site: the header's, each field given replacing its own.
  if (header) setup_.site = header->site;
  if (!header && settings_.latitude.has_value() != settings_.longitude.has_value()) {
    throw std::invalid_argument(std::string("a latitude without a longitude or the reverse: give both (") +
                                (settings_.latitude ? "no longitude" : "no latitude") + ")");
  }
  if (!header && settings_.height && !settings_.latitude) {
    throw std::invalid_argument("a height without a latitude and longitude");
  }
  if (settings_.latitude || settings_.longitude) {
    if (!setup_.site) setup_.site = Site{0.0, 0.0, std::numeric_limits<double>::quiet_NaN()};
    if (settings_.latitude) setup_.site->latitude_deg = *settings_.latitude;
    if (settings_.longitude) setup_.site->longitude_deg = *settings_.longitude;
  }
  if (settings_.height) setup_.site->height_m = *settings_.height;
  if (setup_.site) checkSite(*setup_.site);
}

void ImuLogReader::bad(BadRowReason reason, const std::string& detail) const { throw RowRefusal{reason, detail}; }

core::Nanoseconds ImuLogReader::logTime(const std::vector<std::string_view>& fields, std::uint64_t n) const {
  if (time_ < 0) {
    // Row n closes start + n interval; computed from n, so no error accumulates.
    return core::toNanoseconds(setup_.start) +
           static_cast<core::Nanoseconds>(std::llround(static_cast<double>(n) * (*setup_.interval * 1e9)));
  }
  try {
    return signedSeconds(fields[time_]);
  } catch (const OutOfRangeError& e) {
    bad(BadRowReason::kStampRange, "time (#" + std::to_string(time_ + 1) + "): " + e.what());
  } catch (const FieldError& e) {
    bad(BadRowReason::kStamp, "time (#" + std::to_string(time_ + 1) + "): " + e.what());
  }
}

double ImuLogReader::columnValue(const std::vector<std::string_view>& fields, int column, const char* key,
                                 double factor) const {
  double v = 0.0;
  try {
    v = parseNumber(fields[column]);
  } catch (const FieldError& e) {
    bad(BadRowReason::kNumber, std::string(key) + " (#" + std::to_string(column + 1) + "): " + e.what());
  }
  if (!std::isfinite(v)) {
    bad(BadRowReason::kNotANumber, std::string(key) + " (#" + std::to_string(column + 1) + ") is " +
                                       excerpt(fields[column]) + " (a number is required here)");
  }
  const double si = v * factor;
  if (!std::isfinite(si)) {
    bad(BadRowReason::kNotANumber, std::string(key) + " (#" + std::to_string(column + 1) + ") " +
                                       excerpt(fields[column]) + " times its scale and unit overflows");
  }
  return si;
}

bool ImuLogReader::readRow(Row* row) {
  for (;;) {
    try {
      try {
        if (!csv_.next()) return false;
      } catch (const LineTooLongError& e) {
        ++rows_;
        bad(BadRowReason::kLineTooLong, e.what());
      }
      const std::uint64_t n = ++rows_;
      const std::vector<std::string_view>& fields = csv_.fields();
      if (fields.size() != csv_.header().size()) {
        bad(BadRowReason::kFieldCount, std::to_string(fields.size()) + " fields, " +
                                           (has_header_ ? "the header has " : "the first row has ") +
                                           std::to_string(csv_.header().size()));
      }
      const core::Nanoseconds log_time = logTime(fields, n);
      core::Nanoseconds stamp = 0;
      if (__builtin_add_overflow(log_time, setup_.epoch, &stamp) || stamp < settings_.earliest_stamp ||
          stamp > settings_.latest_stamp) {
        bad(BadRowReason::kStampRange,
            "time " + secondsText(log_time) + " s + epoch " + secondsText(setup_.epoch) + " s is outside [" +
                secondsText(settings_.earliest_stamp) + " s, " + secondsText(settings_.latest_stamp) +
                " s], the stamps " + settings_.stamp_range_holder + " can hold" +
                (setup_.epoch == 0 ? ": pass --epoch S, the Unix time of the log's t = 0" : ": check --epoch"));
      }
      if (have_last_ && stamp <= last_) {
        bad(BadRowReason::kStampOrder, "time " + secondsText(log_time) + " s is not after the previous row's " +
                                           secondsText(last_ - setup_.epoch) + " s (the log must be sorted by time)");
      }
      // The stamp is good: the next row's interval is taken from it even if this row's numbers are not.
      row->have_previous = have_last_;
      row->record.interval = have_last_ ? static_cast<double>(stamp - last_) / 1e9 : 0.0;
      have_last_ = true;
      last_ = stamp;
      row->record.stamp = stamp;
      row->record.line = csv_.line();
      row->record.row = n - 1;
      for (int i = 0; i < 3; ++i) {
        row->gyro[i] = columnValue(fields, gyro_columns_[i], kGyroKeys[i], setup_.gyro_factor[i]);
        row->accel[i] =
            setup_.accelerometer ? columnValue(fields, accel_columns_[i], kAccelKeys[i], setup_.accel_factor[i]) : 0.0;
      }
      return true;
    } catch (const RowRefusal& r) {
      if (!settings_.skip_bad_rows || skipped_ == nullptr) {
        throw BadRowError(r.reason,
                          name_ + ":" + std::to_string(csv_.line()) + ": " + describe(r.reason) + ": " + r.detail);
      }
      ++skipped_->by_reason[static_cast<std::size_t>(r.reason)];
    }
  }
}

bool ImuLogReader::finish(Row& row, ImuRecord* record) {
  std::array<double, 3> omega = row.gyro, force = row.accel;
  const double dt = row.record.interval;
  for (int i = 0; i < 3; ++i) {
    if (setup_.gyro.quantity == Quantity::kIncrement) omega[i] /= dt;
    if (setup_.accelerometer && setup_.accel.quantity == Quantity::kIncrement) force[i] /= dt;
  }
  *record = row.record;
  for (int r = 0; r < 3; ++r) {
    const auto& m = setup_.axes[r];
    record->angular_velocity[r] = m[0] * omega[0] + m[1] * omega[1] + m[2] * omega[2];
    record->specific_force[r] = setup_.accelerometer ? m[0] * force[0] + m[1] * force[1] + m[2] * force[2] : 0.0;
  }
  for (int r = 0; r < 3; ++r) {
    if (!std::isfinite(record->angular_velocity[r]) || !std::isfinite(record->specific_force[r])) {
      const std::string detail = "an increment divided by its interval (" + shortestText(dt) + " s) overflows";
      if (!settings_.skip_bad_rows || skipped_ == nullptr) {
        throw BadRowError(BadRowReason::kNotANumber, name_ + ":" + std::to_string(row.record.line) + ": " +
                                                         describe(BadRowReason::kNotANumber) + ": " + detail);
      }
      ++skipped_->by_reason[static_cast<std::size_t>(BadRowReason::kNotANumber)];
      return false;
    }
  }
  return true;
}

bool ImuLogReader::next(ImuRecord* record) {
  for (;;) {
    Row row;
    if (have_pending_) {
      row = pending_;
      have_pending_ = false;
    } else if (!readRow(&row)) {
      return false;
    }
    if (!setup_.time_column) {
      row.record.interval = *setup_.interval;  // the fixed spacing, also across a skipped row
    } else if (first_) {
      if (setup_.interval) {
        row.record.interval = *setup_.interval;
      } else if (increments_) {
        // The first row's increments cover an interval no stamp before it bounds: take the next row's.
        if (!readRow(&pending_)) {
          throw std::runtime_error(name_ + ":" + std::to_string(row.record.line) +
                                   ": one row of increments: its interval is unknown (give --interval S)");
        }
        have_pending_ = true;
        row.record.interval = pending_.record.interval;
      }
    }
    first_ = false;
    if (finish(row, record)) return true;
  }
}

void ImuSummary::add(const ImuRecord& record) {
  if (rows_ == 0) first_ = record.stamp;
  last_ = record.stamp;
  ++rows_;
  for (int i = 0; i < 3; ++i) {
    omega_sum_[i] += record.angular_velocity[i];
    force_sum_[i] += record.specific_force[i];
  }
}

std::string ImuSummary::line(bool accelerometer, const BadRowCounts& skipped) const {
  std::string s = std::to_string(rows_) + " rows";
  if (rows_ > 0) {
    const double span = static_cast<double>(last_ - first_) / 1e9;
    s += ", stamps " + secondsText(first_) + " .. " + secondsText(last_) + " s (" + fixed(span, 3) + " s";
    if (rows_ > 1) s += ", " + fixed(static_cast<double>(rows_ - 1) / span, 3) + " Hz";
    s += ")";
    const double n = static_cast<double>(rows_);
    const double omega = std::hypot(omega_sum_[0] / n, omega_sum_[1] / n, omega_sum_[2] / n);
    char text[96];
    std::snprintf(text, sizeof text, ", |mean omega| %.4e rad/s = %.4f Earth rates", omega,
                  omega / core::kEarthRotationRate);
    s += text;
    if (accelerometer) {
      std::snprintf(text, sizeof text, ", |mean f| %.4f m/s^2",
                    std::hypot(force_sum_[0] / n, force_sum_[1] / n, force_sum_[2] / n));
      s += text;
    } else {
      s += ", no accelerometer";
    }
  }
  return s + ", skipped " + skipped.summary();
}

}  // namespace csv
}  // namespace hrg_gyro

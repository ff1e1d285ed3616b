// A navigation-grade IMU's text log (fibre-optic or ring-laser gyros with their accelerometers) read
// record by record into body-frame rates, for `hrg_bag import --imu`. Such logs differ from a test
// bench's CSV in everything but being text: rates or increments, often integer counts with a scale,
// often no time column (a fixed interval instead), comment lines of another prefix, header lines of
// numbers (the site, the scales), axes other than REP-103's. ImuLogReader takes each of those as a
// setting, or from the header of the PSINS toolbox's "SIMU" format, and gives per row the stamp, the
// angular velocity (rad/s) and the specific force (m/s^2) in the body frame FLU (x forward, y left,
// z up). Every row is checked as the bench logs' are (gyro_logs.h: field count, numbers, stamps
// strictly increasing, the output's stamp range), refused with file:line and the column, or skipped
// and counted. One line is held at a time, so memory stays flat for a log of any size. No ROS.
#pragma once

#include <array>
#include <cstdint>
#include <istream>
#include <limits>
#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "csv_reader.h"
#include "gyro_logs.h"

namespace hrg_gyro {
namespace csv {

/// What a sensor column holds per row: a rate (rad/s, m/s^2 once in SI), or an increment over the
/// interval the row closes (rad, m/s), which the reader divides by that interval.
enum class Quantity { kRate, kIncrement };

/// A column's unit: the quantity it implies and its value in SI (rad/s, rad, m/s^2 or m/s).
struct SensorUnit {
  Quantity quantity = Quantity::kRate;
  double to_si = 1.0;
};
/// The gyro units: rad/s, deg/s, deg/h (rates); rad, deg, arcsec (increments). An arcsecond is
/// (pi / 180) / 3600 rad, as PSINS's glv.sec. std::invalid_argument listing them otherwise.
SensorUnit gyroUnit(const std::string& name);
/// The accelerometer units: m/s^2, g, mg, ug (rates); m/s, g*s, mg*s, ug*s (velocity increments),
/// g being `gravity` (m/s^2). std::invalid_argument listing them otherwise.
SensorUnit accelUnit(const std::string& name, double gravity);
/// The standard gravity, the default of `gravity` (m/s^2).
constexpr double kStandardGravity = 9.80665;

/// From the log's axes to the body frame FLU (REP-103: x forward, y left, z up): v_flu = m v_log.
/// Its columns are the log's x, y, z axes written in FLU.
using AxisMatrix = std::array<std::array<double, 3>, 3>;
/// The log's axes by where each points, x then y then z, one letter each of F(orward) B(ack) L(eft)
/// R(ight) U(p) D(own), in any case: "FLU" (the identity), "RFU" (PSINS), "FRD", "RFD", ...; "NED"
/// is FRD and "ENU" is RFU (a body frame named after the navigation frame it is aligned with). A
/// left-handed set (RFD) is taken too: each axis's reading is a projection on the direction its letter
/// names (a rate right-hand positive about it), whatever the set's handedness. Two letters on one line
/// (FBU, FFU) are std::invalid_argument.
AxisMatrix frameAxes(const std::string& axes);
/// R = Rz(yaw) Ry(pitch) Rx(roll), angles in rad: yaw = pi/2 is a log whose x axis points left.
AxisMatrix eulerAxes(double roll, double pitch, double yaw);

/// Where the log was taken: geodetic latitude and longitude (deg), height (m; NaN when unknown).
struct Site {
  double latitude_deg = 0.0, longitude_deg = 0.0, height_m = 0.0;
};
/// Refuses (std::invalid_argument naming the field) a latitude outside [-90, 90] deg, a longitude
/// outside [-180, 180] deg or an infinite height.
void checkSite(const Site& site);

/// The three numeric header lines of a PSINS "SIMU" text log (base/io/imufile.m of the PSINS toolbox).
struct PsinsHeader {
  double pitch_deg = 0.0, roll_deg = 0.0;
  double yaw_deg = 0.0;                 ///< PSINS's yaw: counter-clockwise positive from north
  double ve = 0.0, vn = 0.0, vu = 0.0;  ///< initial velocity, m/s, east north up
  Site site;
  double t0 = 0.0;                      ///< s; the first row closes t0 + interval
  double interval_ms = 0.0;             ///< sampling interval, ms
  double gravity = 0.0;                 ///< m/s^2: the "g" of the accelerometer's ug*s scale
  std::array<double, 3> gyro_scale{};   ///< arcsec per count
  std::array<double, 3> accel_scale{};  ///< ug*s per count
  /// The header's yaw as a true heading of the forward axis (clockwise from north), in [0, 360) deg.
  double trueHeadingDeg() const;
};
/// The rows of a PSINS log have this many fields: gx gy gz ax ay az, angle and velocity increments in
/// counts, axes x right, y forward, z up.
constexpr std::size_t kPsinsFields = 6;
/// `lines` (the layout's preamble: three lines of six numbers, apart by blanks) as a PSINS header.
/// std::runtime_error "NAME:LINE: PSINS header line K field J (what, unit): why" for a line of
/// another field count, an unreadable or non-finite number, a value out of its range (interval and
/// gravity positive, scales non-zero, the site as checkSite).
PsinsHeader parsePsinsHeader(const std::vector<NumberedLine>& lines, const std::string& name);

enum class ImuLogFormat {
  kColumns,  ///< the layout, columns and quantities the settings give
  kPsins,    ///< the PSINS SIMU text format: '%' comments, three header lines, six columns of counts
};

/// What the caller asks for. A setting left unset comes from the format (PSINS's header) or its
/// default; one given always wins over the header.
struct ImuLogSettings {
  ImuLogFormat format = ImuLogFormat::kColumns;
  /// Columns format only (PSINS fixes its own: '%' comments, three header lines, blanks, no header row).
  TextLayout layout;
  /// Column of each key (time, gx, gy, gz, ax, ay, az): a header name or "#N"; a key not given is
  /// looked up by its own name (any case). PSINS: gx..az are #1..#6 and cannot be remapped.
  std::map<std::string, std::string> columns;
  std::optional<std::string> gyro_unit;   ///< default rad/s (PSINS: arcsec)
  std::optional<std::string> accel_unit;  ///< default m/s^2 (PSINS: ug*s)
  /// Per count of the log, per axis x y z of the log, in the unit (default 1; PSINS: its header's).
  std::optional<std::array<double, 3>> gyro_scale, accel_scale;
  std::optional<double> gravity;  ///< m/s^2 of the g units (default kStandardGravity; PSINS: its header's)
  /// The rows' spacing, s: required without a time column (row n, from 1, closes start + n interval);
  /// with one, the interval of the first row's increments (else the next row's stamp difference).
  std::optional<double> interval;
  std::optional<double> start;  ///< s, the log's time the first row's interval opens at (default 0; PSINS: t0)
  core::Nanoseconds epoch = 0;  ///< added to the log's time of every row (Unix time of the log's t = 0)
  /// The log's axes (frameAxes) or its rotation to FLU (roll, pitch, yaw, rad; eulerAxes); at most
  /// one. Neither: FLU (PSINS: RFU).
  std::optional<std::string> frame;
  std::optional<std::array<double, 3>> rotation;
  /// The site, deg and m, each given one winning over the header's (PSINS). Latitude and longitude go
  /// together (std::invalid_argument for one without the other and no header); the height alone
  /// needs them; without one it is unknown (NaN).
  std::optional<double> latitude, longitude, height;
  bool skip_bad_rows = false;
  /// The stamps the output can hold (a bag: ros::TIME_MIN to ros::TIME_MAX); a row stamped outside is
  /// a bad record, `stamp_range_holder` saying whose range it is.
  core::Nanoseconds earliest_stamp = 0;
  core::Nanoseconds latest_stamp = std::numeric_limits<core::Nanoseconds>::max();
  std::string stamp_range_holder = "the output";
};

/// The settings in force once the log's header is read: what the reader applies, for the caller to
/// print.
struct ImuLogSetup {
  bool time_column = false;
  bool accelerometer = false;
  std::string gyro_unit, accel_unit;
  SensorUnit gyro, accel;
  std::array<double, 3> gyro_scale{}, accel_scale{};
  /// Per axis of the log: scale x unit, the one factor a count is multiplied by (to rad/s, rad, m/s^2
  /// or m/s); an increment's is then divided by its interval.
  std::array<double, 3> gyro_factor{}, accel_factor{};
  double gravity = kStandardGravity;
  std::optional<double> interval;  ///< s
  double start = 0.0;              ///< s
  core::Nanoseconds epoch = 0;
  std::string frame;  ///< "FLU", "RFU", ..., or "rotation roll,pitch,yaw"
  AxisMatrix axes{};
  std::optional<Site> site;
  std::optional<PsinsHeader> psins;
};

struct ImuRecord {
  core::Nanoseconds stamp = 0;  ///< epoch + the log's time; for increments the end of their interval
  std::uint64_t line = 0;       ///< the row's line in the file
  std::uint64_t row = 0;        ///< the row's number among the log's rows, from 0, skipped ones counted
  /// s: the interval the row closes, by which its increments were divided: the stamp difference to the
  /// previous row whose stamp was good (the first row: the interval setting, else the next row's); the
  /// fixed interval without a time column. 0 for a first row of rates without an interval setting.
  double interval = 0.0;
  std::array<double, 3> angular_velocity{};  ///< rad/s, FLU
  std::array<double, 3> specific_force{};    ///< m/s^2, FLU (+g up at rest); 0 without an accelerometer
};

class ImuLogReader {
 public:
  /// Reads the log's layout, preamble (the PSINS header) and header row, and resolves the settings.
  /// std::invalid_argument for settings that cannot stand together (no time column and no interval,
  /// both a frame and a rotation, an unknown unit or frame, a scale that is zero or not finite);
  /// std::runtime_error naming the file for a log that is not as they say (a missing column, an
  /// accelerometer with one or two axes, an unreadable header).
  ImuLogReader(std::istream& in, const std::string& name, const ImuLogSettings& settings, BadRowCounts* skipped);
  /// The next good row; false at the end. BadRowError for a bad row (unless skipped and counted),
  /// std::runtime_error for a log of one row of increments whose interval nothing gives.
  bool next(ImuRecord* record);
  const ImuLogSetup& setup() const { return setup_; }
  const CsvReader& csv() const { return csv_; }

 private:
  /// A row read and converted to SI, not yet divided by its interval nor turned to FLU.
  struct Row {
    ImuRecord record;
    std::array<double, 3> gyro{}, accel{};
    bool have_previous = false;  ///< a previous row's stamp is known: record.interval holds the difference
  };
  bool readRow(Row* row);
  /// Row `n`'s time in the log (its time column, or start + n interval); refuses the row when bad.
  core::Nanoseconds logTime(const std::vector<std::string_view>& fields, std::uint64_t n) const;
  /// The number in `fields[column]` (the log's `key`) times `factor`; refuses the row when it is not
  /// a finite number or the product overflows.
  double columnValue(const std::vector<std::string_view>& fields, int column, const char* key, double factor) const;
  // The constructor's sections, in order: each setting given wins over the PSINS header's (`header`,
  // nullptr without one), which wins over the default; each throws what the constructor documents.
  void setupUnits(const PsinsHeader* header);
  void setupTime(const PsinsHeader* header, const std::map<std::string, std::string>& columns);
  void setupColumns(const std::map<std::string, std::string>& columns);
  void setupAxes(const PsinsHeader* header);
  void setupSite(const PsinsHeader* header);
  /// Divides increments by the row's interval and turns the vectors to FLU; BadRowError (or counted,
  /// false) when that overflows.
  bool finish(Row& row, ImuRecord* record);
  [[noreturn]] void bad(BadRowReason reason, const std::string& detail) const;

  std::string name_;
  ImuLogSettings settings_;
  CsvReader csv_;
  ImuLogSetup setup_;
  BadRowCounts* skipped_;
  bool has_header_ = false;
  bool increments_ = false;  ///< the gyro's or the accelerometer's columns hold increments
  int time_ = -1;
  std::array<int, 3> gyro_columns_{}, accel_columns_{};
  std::uint64_t rows_ = 0;  ///< data lines read, bad ones counted
  bool have_last_ = false;  ///< a row's stamp was good (readable, in range, after the one before)
  core::Nanoseconds last_ = 0;
  bool first_ = true;
  bool have_pending_ = false;  ///< the row read ahead to give the first row its interval
  Row pending_;
};

/// The figures of an import's summary line: rows, stamps, rate, and the mean vectors a still IMU's
/// log is checked by (|mean omega| is the Earth's rate, 7.292115e-5 rad/s, |mean f| the gravity).
class ImuSummary {
 public:
  void add(const ImuRecord& record);
  std::uint64_t rows() const { return rows_; }
  core::Nanoseconds firstStamp() const { return first_; }
  /// "184718 rows, stamps 1395394311.010000000 .. 1395396158.180000000 s (1847.170 s, 100.000 Hz),
  /// |mean omega| 7.197e-05 rad/s = 0.9870 Earth rates, |mean f| 9.7955 m/s^2, skipped 0"; without an
  /// accelerometer "no accelerometer" stands for |mean f|.
  std::string line(bool accelerometer, const BadRowCounts& skipped) const;

 private:
  std::uint64_t rows_ = 0;
  core::Nanoseconds first_ = 0, last_ = 0;
  std::array<double, 3> omega_sum_{}, force_sum_{};
};

}  // namespace csv
}  // namespace hrg_gyro

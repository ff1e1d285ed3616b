// hrg_bag import --imu: an IMU's text log, streamed row by row through csv::ImuLogReader, into
// sensor_msgs/Imu messages (and one NavSatFix of the site) written as they are read, so memory stays
// flat for a log of any size. What the reader resolved (units, interval, axes, the PSINS header) is
// printed before the import, the summary after it.
#include "imu_import.h"

#include <sensor_msgs/Imu.h>
#include <sensor_msgs/NavSatFix.h>

#include <charconv>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <optional>

#include "../cli_checks.h"
#include "bag_tools.h"
#include "hrg_gyro/ros/conversions.h"
#include "imu_log.h"

namespace hrg_gyro {
namespace bag_tools {

namespace {

const std::string kGroup = "IMU log (--imu; defaults for --format columns, --format psins from its header)";

/// "1,2,3" (or one number for all three when `one_for_all`), each a finite number read whole.
std::array<double, 3> numbers(const std::string& text, const char* option, bool one_for_all) {
  std::vector<double> values;
  std::size_t begin = 0;
  for (;;) {
    const std::size_t cut = text.find(',', begin);
    const std::string field = text.substr(begin, cut == std::string::npos ? std::string::npos : cut - begin);
    double v = 0.0;
    const auto r = std::from_chars(field.data(), field.data() + field.size(), v);
    if (field.empty() || r.ec != std::errc() || r.ptr != field.data() + field.size() || !std::isfinite(v)) {
      throw UsageError(std::string(option) + ": '" + field + "' is not a finite number");
    }
    values.push_back(v);
    if (cut == std::string::npos) break;
    begin = cut + 1;
  }
  if (values.size() == 1 && one_for_all) return {values[0], values[0], values[0]};
  if (values.size() != 3) {
    throw UsageError(std::string(option) + " expects " + (one_for_all ? "one number or " : "") +
                     "three apart by commas (x,y,z), got '" + text + "'");
  }
  return {values[0], values[1], values[2]};
}

std::string fixed(double value, int decimals) {
  char text[64];
  std::snprintf(text, sizeof text, "%.*f", decimals, value);
  return text;
}

std::string quantity(csv::Quantity q) { return q == csv::Quantity::kRate ? "rates" : "increments"; }

std::string scales(const std::array<double, 3>& s) {
  if (s[0] == s[1] && s[1] == s[2]) return tools::shortest(s[0]);
  return tools::shortest(s[0]) + "," + tools::shortest(s[1]) + "," + tools::shortest(s[2]);
}

/// The reader's settings from the options; a given option always wins over the PSINS header.
csv::ImuLogSettings imuSettings(const ImuImportOptions& o) {
  const CLI::App& cmd = *o.command;
  auto given = [&](const char* name) { return cmd.count(name) > 0; };
  csv::ImuLogSettings s;
  s.format = o.format == "psins" ? csv::ImuLogFormat::kPsins : csv::ImuLogFormat::kColumns;
  if (s.format == csv::ImuLogFormat::kPsins) {
    for (const char* fixed_by_format : {"--delimiter", "--comment", "--skip-lines", "--no-header", "--column"}) {
      if (given(fixed_by_format)) {
        throw UsageError(std::string(fixed_by_format) +
                         ": --format psins fixes the layout ('%' comments, three header lines, blanks, "
                         "columns gx gy gz ax ay az)");
      }
    }
  }
  s.layout.delimiter = o.delimiter == "comma"        ? ','
                       : o.delimiter == "semicolon"  ? ';'
                       : o.delimiter == "tab"        ? '\t'
                       : o.delimiter == "whitespace" ? csv::kWhitespace
                                                     : 0;
  s.layout.blanks_when_no_delimiter = true;  // auto: a log of numbers apart by blanks is the common case
  s.layout.comment = o.comment;
  s.layout.preamble_lines = static_cast<std::size_t>(o.skip_lines);
  s.layout.has_header = !o.no_header;
  const std::vector<std::string> keys = {"time", "gx", "gy", "gz", "ax", "ay", "az"};
  for (const std::string& entry : o.columns) {
    const std::size_t eq = entry.find('=');
    if (eq == std::string::npos || eq == 0 || eq + 1 == entry.size()) {
      throw UsageError("--column expects KEY=COLUMN (e.g. gx=wx or gx=#2), got '" + entry + "'");
    }
    const std::string key = entry.substr(0, eq);
    if (std::find(keys.begin(), keys.end(), key) == keys.end()) {
      throw UsageError("--column: unknown key '" + key + "' for --imu (keys: time, gx, gy, gz, ax, ay, az)");
    }
    s.columns[key] = entry.substr(eq + 1);
  }
  if (given("--gyro-unit")) s.gyro_unit = o.gyro_unit;
  if (given("--accel-unit")) s.accel_unit = o.accel_unit;
  if (given("--gyro-scale")) s.gyro_scale = numbers(o.gyro_scale, "--gyro-scale", true);
  if (given("--accel-scale")) s.accel_scale = numbers(o.accel_scale, "--accel-scale", true);
  if (given("--gravity")) s.gravity = o.gravity;
  if (given("--interval")) s.interval = o.interval;
  if (given("--epoch")) {
    try {
      s.epoch = csv::parseStamp(o.epoch, csv::StampFormat::kSeconds);
    } catch (const csv::FieldError& e) {
      throw UsageError("--epoch: " + std::string(e.what()) + " (Unix seconds, a plain decimal: 1395394311.5)");
    }
  }
  if (given("--frame") && given("--rotation")) {
    throw UsageError("--frame and --rotation both give the log's axes: give one");
  }
  if (given("--frame")) s.frame = o.frame;
  if (given("--rotation")) s.rotation = numbers(o.rotation, "--rotation", false);
  if (given("--latitude")) s.latitude = o.latitude;
  if (given("--longitude")) s.longitude = o.longitude;
  if (given("--height")) s.height = o.height;
  s.skip_bad_rows = o.skip_bad_rows;
  s.earliest_stamp = static_cast<core::Nanoseconds>(ros::TIME_MIN.toNSec());
  s.latest_stamp = static_cast<core::Nanoseconds>(ros::TIME_MAX.toNSec());
  s.stamp_range_holder = "a bag";
  return s;
}

/// What the reader resolved, on stderr before the import: what the numbers will mean.
void printSetup(const ImuImportOptions& o, const csv::ImuLogSetup& s) {
  std::cerr << "import: " << o.log << ": gyro " << quantity(s.gyro.quantity) << " in " << s.gyro_unit << " x "
            << scales(s.gyro_scale);
  if (s.accelerometer) {
    std::cerr << ", accelerometer " << quantity(s.accel.quantity) << " in " << s.accel_unit << " x "
              << scales(s.accel_scale);
    if (s.accel_unit.find('g') != std::string::npos) std::cerr << " (g = " << tools::shortest(s.gravity) << " m/s^2)";
  } else {
    std::cerr << ", no accelerometer";
  }
  std::cerr << "; "
            << (s.time_column ? "time column"
                              : "no time column, row n at " + tools::shortest(s.start) + " + n x " +
                                    tools::shortest(*s.interval) + " s (" + fixed(1.0 / *s.interval, 3) + " Hz)");
  std::cerr << ", epoch " << csv::secondsText(s.epoch) << " s; axes " << s.frame << " -> FLU\n";
  if (s.psins) {
    const csv::PsinsHeader& h = *s.psins;
    std::cerr << "import: the PSINS header's initial attitude (unverified: the format calls it 'maybe "
              << "inaccurate'): pitch " << tools::shortest(h.pitch_deg) << " deg, roll " << tools::shortest(h.roll_deg)
              << " deg, yaw " << tools::shortest(h.yaw_deg) << " deg counter-clockwise from north, i.e. true heading "
              << fixed(h.trueHeadingDeg(), 4) << " deg (clockwise from north) of the forward axis; velocity E N U "
              << tools::shortest(h.ve) << " " << tools::shortest(h.vn) << " " << tools::shortest(h.vu) << " m/s\n";
  }
  if (s.site) {
    const double latitude_rad = s.site->latitude_deg * core::kPi / 180.0;
    std::cerr << "import: site latitude " << tools::shortest(s.site->latitude_deg)
              << " deg = " << tools::shortest(latitude_rad)
              << " rad (put it in your gyrocompass settings' latitude), longitude "
              << tools::shortest(s.site->longitude_deg) << " deg, height "
              << (std::isnan(s.site->height_m) ? std::string("unknown") : tools::shortest(s.site->height_m) + " m")
              << ": one NavSatFix on " << o.fix_topic << " at the first stamp\n";
  }
}

sensor_msgs::Imu toImuMessage(const csv::ImuRecord& r, bool accelerometer, const std::string& frame_id) {
  sensor_msgs::Imu m;
  m.header.stamp = toRosTime(r.stamp);
  m.header.seq = static_cast<std::uint32_t>(r.row);  // a skipped row leaves a gap
  m.header.frame_id = frame_id;
  // REP-145: no orientation; the angular velocity's covariance unknown (all 0, as the message says).
  m.orientation_covariance[0] = -1.0;
  m.angular_velocity.x = r.angular_velocity[0];
  m.angular_velocity.y = r.angular_velocity[1];
  m.angular_velocity.z = r.angular_velocity[2];
  if (accelerometer) {
    m.linear_acceleration.x = r.specific_force[0];
    m.linear_acceleration.y = r.specific_force[1];
    m.linear_acceleration.z = r.specific_force[2];
  } else {
    m.linear_acceleration_covariance[0] = -1.0;
  }
  return m;
}

sensor_msgs::NavSatFix toFixMessage(const csv::Site& site, core::Nanoseconds stamp, const std::string& frame_id) {
  sensor_msgs::NavSatFix m;
  m.header.stamp = toRosTime(stamp);
  m.header.frame_id = frame_id;
  // A site declared by the log or the options, not a receiver's solution: no service, no covariance.
  m.status.status = sensor_msgs::NavSatStatus::STATUS_FIX;
  m.status.service = 0;
  m.latitude = site.latitude_deg;
  m.longitude = site.longitude_deg;
  m.altitude = site.height_m;  // NaN when unknown, as the message allows
  m.position_covariance_type = sensor_msgs::NavSatFix::COVARIANCE_TYPE_UNKNOWN;
  return m;
}

}  // namespace

const std::vector<std::string>& imuOnlyOptions() {
  static const std::vector<std::string> names = {
      "--imu",        "--format",      "--comment",   "--skip-lines", "--gyro-unit", "--gyro-scale",
      "--accel-unit", "--accel-scale", "--gravity",   "--interval",   "--epoch",     "--frame",
      "--rotation",   "--latitude",    "--longitude", "--height",     "--imu-topic", "--fix-topic"};
  return names;
}

void addImuImportOptions(CLI::App& cmd, ImuImportOptions* o) {
  cmd.add_option("--imu", o->log,
                 "an IMU's text log (rates or increments, counts with a scale, with or without a time column) into "
                 "sensor_msgs/Imu; not with --channels")
      ->check(tools::notEmpty())
      ->group(kGroup);
  cmd.add_option("--format", o->format,
                 "columns (the layout, columns and units the options give) or psins (the PSINS toolbox's SIMU text: "
                 "'%' comments, 3 header lines of attitude, site, interval, g and scales, then gx gy gz ax ay az "
                 "increments in counts on x right, y forward, z up)")
      ->check(CLI::IsMember({"columns", "psins"}))
      ->capture_default_str()
      ->group(kGroup);
  cmd.add_option("--comment", o->comment, "prefix of comment lines, anywhere in the log (e.g. '%')")
      ->check(tools::notEmpty())
      ->capture_default_str()
      ->group(kGroup);
  cmd.add_option("--skip-lines", o->skip_lines,
                 "header lines (not empty, not comments) passed over before the header row or the first row")
      ->transform(tools::wholeNumber(0, 1000000))
      ->capture_default_str()
      ->group(kGroup);
  cmd.add_option("--gyro-unit", o->gyro_unit,
                 "rates rad/s (default), deg/s, deg/h; increments over each row's interval rad, deg, arcsec "
                 "(divided by the interval)")
      ->check(CLI::IsMember({"rad/s", "deg/s", "deg/h", "rad", "deg", "arcsec"}))
      ->group(kGroup);
  cmd.add_option("--gyro-scale", o->gyro_scale,
                 "units per count, S or SX,SY,SZ (the log's axes; default 1): --gyro-unit arcsec --gyro-scale 0.1 is "
                 "0.1 arcsec a count")
      ->group(kGroup);
  cmd.add_option("--accel-unit", o->accel_unit,
                 "specific force m/s^2 (default), g, mg, ug; velocity increments m/s, g*s, mg*s, ug*s (g: --gravity)")
      ->check(CLI::IsMember({"m/s^2", "g", "mg", "ug", "m/s", "g*s", "mg*s", "ug*s"}))
      ->group(kGroup);
  cmd.add_option("--accel-scale", o->accel_scale,
                 "units per count, S or SX,SY,SZ (default 1): PSINS's --accel-unit ug*s --accel-scale 125 --gravity "
                 "9.780327")
      ->group(kGroup);
  cmd.add_option("--gravity", o->gravity, "m/s^2 of the accelerometer's g units (default 9.80665)")
      ->transform(tools::finiteNumber())
      ->check(tools::above(0.0))
      ->group(kGroup);
  cmd.add_option("--interval", o->interval,
                 "s between rows: required without a time column (row n, from 1, is stamped epoch + n x interval, "
                 "PSINS: + its t0; an increment's stamp is the end of its interval); with one, the first row's "
                 "increment interval (default: the next row's stamp difference)")
      ->transform(tools::finiteNumber())
      ->check(tools::above(0.0))
      ->group(kGroup);
  cmd.add_option("--epoch", o->epoch,
                 "s (Unix time, read exactly) added to every stamp: the time of the log's t = 0 (default 0; a stamp "
                 "a bag cannot hold, before 1 ns or from 2^32 s, is refused)")
      ->group(kGroup);
  cmd.add_option("--frame", o->frame,
                 "the log's axes x y z, a letter each of F B L R U D: FLU (default), RFU (PSINS), FRD, RFD, NED (= "
                 "FRD), ENU (= RFU), ...; turned to the body frame FLU (REP-103)")
      ->group(kGroup);
  cmd.add_option("--rotation", o->rotation,
                 "ROLL,PITCH,YAW (rad): v_flu = Rz(yaw) Ry(pitch) Rx(roll) v_log, instead of --frame")
      ->group(kGroup);
  cmd.add_option("--latitude", o->latitude, "deg, the site's (with --longitude): a NavSatFix on --fix-topic")
      ->transform(tools::finiteNumber())
      ->group(kGroup);
  cmd.add_option("--longitude", o->longitude, "deg, the site's (with --latitude)")
      ->transform(tools::finiteNumber())
      ->group(kGroup);
  cmd.add_option("--height", o->height, "m, the site's (default unknown: NaN altitude)")
      ->transform(tools::finiteNumber())
      ->group(kGroup);
  cmd.add_option("--imu-topic", o->imu_topic, "topic of the sensor_msgs/Imu messages")
      ->check(topicName())
      ->capture_default_str()
      ->group(kGroup);
  cmd.add_option("--fix-topic", o->fix_topic, "topic of the site's sensor_msgs/NavSatFix (not --imu-topic)")
      ->check(topicName())
      ->capture_default_str()
      ->group(kGroup);
}

int runImuImport(const ImuImportOptions& o, std::istream& log, double log_bytes) {
  if (o.imu_topic == o.fix_topic) {
    throw UsageError("--imu-topic and --fix-topic are both " + o.imu_topic + ": one topic cannot carry both types");
  }
  const csv::ImuLogSettings settings = imuSettings(o);
  csv::BadRowCounts skipped;
  std::optional<csv::ImuLogReader> reader;
  try {
    reader.emplace(log, o.log, settings, &skipped);
  } catch (const csv::ReadError&) {
    throw;
  } catch (const std::exception& e) {
    throw UsageError(e.what());  // settings that cannot stand together, a header or columns not as they say
  }
  const csv::ImuLogSetup& setup = reader->setup();
  printSetup(o, setup);

  OutputBag bag(o.out, o.compression);
  std::optional<Progress> progress;
  if (!o.quiet) progress.emplace("import", log_bytes);
  csv::ImuSummary summary;
  try {
    csv::ImuRecord r;
    while (reader->next(&r)) {
      if (summary.rows() == 0 && setup.site) {
        bag.write(o.fix_topic, toRosTime(r.stamp), toFixMessage(*setup.site, r.stamp, o.frame_id));
      }
      bag.write(o.imu_topic, toRosTime(r.stamp), toImuMessage(r, setup.accelerometer, o.frame_id));
      summary.add(r);
      if (progress) progress->update(static_cast<double>(reader->csv().bytesRead()), summary.rows());
    }
  } catch (const OutputError&) {
    throw;  // exit 3, not a bad input
  } catch (const csv::BadRowError& e) {
    std::cerr << "hrg_bag import: " << e.what() << "\nhrg_bag import: " << o.out
              << " not written (--skip-bad-rows skips and counts such rows)\n";
    return 1;  // `bag` is destroyed uncommitted: nothing is left at --out
  } catch (const csv::ReadError& e) {
    std::cerr << "hrg_bag import: " << e.what() << "\nhrg_bag import: " << o.out << " not written\n";
    return 2;
  } catch (const std::runtime_error& e) {
    std::cerr << "hrg_bag import: " << e.what() << "\nhrg_bag import: " << o.out << " not written\n";
    return 1;
  }
  if (summary.rows() == 0) {
    std::cerr << "hrg_bag import: " << o.log << " holds no usable IMU row; " << o.out << " not written\n";
    return 1;
  }
  bag.commit();
  if (progress) progress->finish(summary.rows());
  std::cerr << "import: wrote " << o.out << ": " << summary.line(setup.accelerometer, skipped) << "; Imu on "
            << o.imu_topic << (setup.site ? ", one NavSatFix on " + o.fix_topic : std::string()) << ", frame "
            << o.frame_id << "\n";
  // A log's own times from 0 fit in a bag, but as 1970: say so (not for a log of Unix times).
  constexpr core::Nanoseconds kYear2001 = 1000000000LL * 1000000000LL;
  if (o.command->count("--epoch") == 0 && summary.firstStamp() < kYear2001) {
    std::cerr << "import: no --epoch: the stamps are the log's own times, from "
              << csv::secondsText(summary.firstStamp())
              << " s after 1970-01-01; pass --epoch S, the Unix time of the log's t = 0, for its real time\n";
  }
  return 0;
}

}  // namespace bag_tools
}  // namespace hrg_gyro

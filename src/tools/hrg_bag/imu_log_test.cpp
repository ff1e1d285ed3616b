#include "imu_log.h"

#include <gtest/gtest.h>

#include <cmath>
#include <sstream>
#include <vector>

#include "hrg_gyro/core/common/units.h"

namespace hrg_gyro {
namespace csv {
namespace {

constexpr double kDegree = core::kPi / 180.0;
constexpr double kArcsecond = kDegree / 3600.0;

std::vector<ImuRecord> readImu(const std::string& text, const ImuLogSettings& settings, BadRowCounts* skipped = nullptr,
                               ImuLogSetup* setup = nullptr) {
  std::istringstream in(text);
  ImuLogReader reader(in, "imu.txt", settings, skipped);
  if (setup != nullptr) *setup = reader.setup();
  std::vector<ImuRecord> records;
  ImuRecord r;
  while (reader.next(&r)) records.push_back(r);
  return records;
}

/// What reading `text` refused (a bad row's message, a setting's or a layout's), "" when accepted.
std::string refusal(const std::string& text, const ImuLogSettings& settings) {
  try {
    readImu(text, settings);
  } catch (const std::exception& e) {
    return e.what();
  }
  return "";
}

bool has(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

/// A log with a header row "time,gx,gy,gz" read as rates in rad/s.
ImuLogSettings rates() { return ImuLogSettings{}; }

ImuLogSettings withoutHeader(std::map<std::string, std::string> columns) {
  ImuLogSettings s;
  s.layout.has_header = false;
  s.layout.blanks_when_no_delimiter = true;  // as the import's --delimiter auto
  s.columns = std::move(columns);
  return s;
}

// The PSINS "SIMU" text format, as base/io/imufile.m writes it (the header of data/lasergyro.imu,
// its blank line and the trailing blank of the scale line included).
const char* kPsins =
    "% PSINS-format SIMU log file. (DO NOT EDIT!)\n"
    "%   Conventionally, SIMU is mounted on vehicle with \"X-Right,Y-Foward,Z-Up\" orientation.\n"
    "\n"
    "0.000000 0.000000 -90.600000 0.000000 0.000000 0.000000\n"
    "34.24604800 108.90966400 380.000 0.00000000 10.00000000 9.780327\n"
    "0.100000 0.100000 0.100000 125.000 125.000 125.000 \n"
    "0 0 2 0 0 80\n"
    "-4 7 0 1 -2 80\n";

ImuLogSettings psins() {
  ImuLogSettings s;
  s.format = ImuLogFormat::kPsins;
  return s;
}

TEST(ImuLogTest, GyroAndAccelerometerUnitsWithTheQuantityTheyImply) {
  EXPECT_EQ(gyroUnit("rad/s").quantity, Quantity::kRate);
  EXPECT_EQ(gyroUnit("rad/s").to_si, 1.0);
  EXPECT_EQ(gyroUnit("deg/s").to_si, kDegree);
  EXPECT_EQ(gyroUnit("deg/h").to_si, kDegree / 3600.0);
  EXPECT_EQ(gyroUnit("deg/h").quantity, Quantity::kRate);
  EXPECT_EQ(gyroUnit("rad").quantity, Quantity::kIncrement);
  EXPECT_EQ(gyroUnit("deg").to_si, kDegree);
  EXPECT_EQ(gyroUnit("deg").quantity, Quantity::kIncrement);
  EXPECT_EQ(gyroUnit("arcsec").to_si, kArcsecond);
  EXPECT_EQ(gyroUnit("arcsec").quantity, Quantity::kIncrement);
  EXPECT_NEAR(gyroUnit("arcsec").to_si, 4.84813681109536e-6, 1e-20);
  EXPECT_THROW(gyroUnit("rpm"), std::invalid_argument);
  EXPECT_THROW(gyroUnit("deg/h "), std::invalid_argument);
  const double g = 9.780327;
  EXPECT_EQ(accelUnit("m/s^2", g).to_si, 1.0);
  EXPECT_EQ(accelUnit("m/s^2", g).quantity, Quantity::kRate);
  EXPECT_EQ(accelUnit("g", g).to_si, g);
  EXPECT_EQ(accelUnit("mg", g).to_si, 1e-3 * g);
  EXPECT_EQ(accelUnit("ug", g).to_si, 1e-6 * g);
  EXPECT_EQ(accelUnit("ug", g).quantity, Quantity::kRate);
  EXPECT_EQ(accelUnit("m/s", g).quantity, Quantity::kIncrement);
  EXPECT_EQ(accelUnit("g*s", g).to_si, g);
  EXPECT_EQ(accelUnit("mg*s", g).to_si, 1e-3 * g);
  EXPECT_EQ(accelUnit("ug*s", g).to_si, 1e-6 * g);
  EXPECT_EQ(accelUnit("ug*s", g).quantity, Quantity::kIncrement);
  try {
    accelUnit("ft/s^2", g);
    FAIL() << "ft/s^2 was taken";
  } catch (const std::invalid_argument& e) {
    EXPECT_TRUE(has(e.what(), "m/s^2, g, mg, ug (rates), m/s, g*s, mg*s, ug*s (increments)")) << e.what();
  }
}

TEST(ImuLogTest, EachFrameMapsTheLogsAxesOnFlu) {
  // Columns are the log's axes in FLU (x forward, y left, z up).
  const AxisMatrix flu{{{1, 0, 0}, {0, 1, 0}, {0, 0, 1}}};
  const AxisMatrix rfu{{{0, 1, 0}, {-1, 0, 0}, {0, 0, 1}}};   // x right, y forward, z up (PSINS)
  const AxisMatrix frd{{{1, 0, 0}, {0, -1, 0}, {0, 0, -1}}};  // x forward, y right, z down
  const AxisMatrix rfd{{{0, 1, 0}, {-1, 0, 0}, {0, 0, -1}}};  // left-handed: projections all the same
  EXPECT_EQ(frameAxes("FLU"), flu);
  EXPECT_EQ(frameAxes("RFU"), rfu);
  EXPECT_EQ(frameAxes("rfu"), rfu);
  EXPECT_EQ(frameAxes("ENU"), rfu);
  EXPECT_EQ(frameAxes("FRD"), frd);
  EXPECT_EQ(frameAxes("NED"), frd);
  EXPECT_EQ(frameAxes("RFD"), rfd);
  EXPECT_EQ(frameAxes("BRU"), (AxisMatrix{{{-1, 0, 0}, {0, -1, 0}, {0, 0, 1}}}));
  EXPECT_EQ(frameAxes("ULF"), (AxisMatrix{{{0, 0, 1}, {0, 1, 0}, {1, 0, 0}}}));
  for (const char* bad : {"FBU", "FFU", "FL", "FLUX", "FLX", ""}) {
    EXPECT_THROW(frameAxes(bad), std::invalid_argument) << bad;
  }
  try {
    frameAxes("LRU");
  } catch (const std::invalid_argument& e) {
    EXPECT_TRUE(has(e.what(), "names the left-right line twice")) << e.what();
  }
  // Read through the reader: an RFU row (right 1, forward 2, up 3) is forward 2, left -1, up 3; FRD's
  // (forward 1, right 2, down 3) forward 1, left -2, up -3.
  const std::string log = "time,gx,gy,gz,ax,ay,az\n1.0,1,2,3,0.5,0.25,9.75\n";
  ImuLogSettings s;
  s.frame = "RFU";
  auto r = readImu(log, s);
  ASSERT_EQ(r.size(), 1u);
  EXPECT_EQ(r[0].angular_velocity, (std::array<double, 3>{2, -1, 3}));
  EXPECT_EQ(r[0].specific_force, (std::array<double, 3>{0.25, -0.5, 9.75}));
  s.frame = "NED";
  r = readImu(log, s);
  EXPECT_EQ(r[0].angular_velocity, (std::array<double, 3>{1, -2, -3}));
  EXPECT_EQ(r[0].specific_force, (std::array<double, 3>{0.5, -0.25, -9.75}));
  s.frame = "RFD";
  r = readImu(log, s);
  EXPECT_EQ(r[0].angular_velocity, (std::array<double, 3>{2, -1, -3}));
  s.frame.reset();  // FLU: as logged
  r = readImu(log, s);
  EXPECT_EQ(r[0].angular_velocity, (std::array<double, 3>{1, 2, 3}));
  s.frame = "FXU";
  EXPECT_TRUE(has(refusal(log, s), "'X' is none of F B L R U D"));
}

TEST(ImuLogTest, RotationIsRzRyRxFromTheLogToFlu) {
  const double r = 0.3, p = -0.2, y = 1.1;
  const AxisMatrix m = eulerAxes(r, p, y);
  // Rz(y) Ry(p) Rx(r) multiplied out by hand.
  const AxisMatrix rx{{{1, 0, 0}, {0, std::cos(r), -std::sin(r)}, {0, std::sin(r), std::cos(r)}}};
  const AxisMatrix ry{{{std::cos(p), 0, std::sin(p)}, {0, 1, 0}, {-std::sin(p), 0, std::cos(p)}}};
  const AxisMatrix rz{{{std::cos(y), -std::sin(y), 0}, {std::sin(y), std::cos(y), 0}, {0, 0, 1}}};
  auto product = [](const AxisMatrix& a, const AxisMatrix& b) {
    AxisMatrix c{};
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j)
        for (int k = 0; k < 3; ++k) c[i][j] += a[i][k] * b[k][j];
    return c;
  };
  const AxisMatrix expected = product(rz, product(ry, rx));
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) EXPECT_NEAR(m[i][j], expected[i][j], 1e-15) << i << j;
  // A yaw of -90 deg is RFU's mapping, roll 180 deg FRD's (to rounding).
  const AxisMatrix rfu = eulerAxes(0, 0, -core::kPi / 2), frd = eulerAxes(core::kPi, 0, 0);
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) {
      EXPECT_NEAR(rfu[i][j], frameAxes("RFU")[i][j], 1e-16);
      EXPECT_NEAR(frd[i][j], frameAxes("FRD")[i][j], 2e-16);
    }
  }
  // Through the reader, to gyro and accelerometer alike; a frame and a rotation together are refused.
  ImuLogSettings s;
  s.rotation = std::array<double, 3>{0, 0, core::kPi / 2};  // the log's x points left
  ImuLogSetup setup;
  const auto records = readImu("time,gx,gy,gz,ax,ay,az\n1.0,1,0,0,2,0,0\n", s, nullptr, &setup);
  EXPECT_NEAR(records[0].angular_velocity[0], 0.0, 1e-16);
  EXPECT_NEAR(records[0].angular_velocity[1], 1.0, 1e-16);
  EXPECT_NEAR(records[0].specific_force[1], 2.0, 1e-15);
  EXPECT_TRUE(has(setup.frame, "rotation 0,0,1.5707963267948966 rad")) << setup.frame;
  s.frame = "FLU";
  EXPECT_TRUE(has(refusal("time,gx,gy,gz\n1.0,1,0,0\n", s), "a frame (FLU) and a rotation; give one"));
  s.frame.reset();
  s.rotation = std::array<double, 3>{0, NAN, 0};
  EXPECT_TRUE(has(refusal("time,gx,gy,gz\n1.0,1,0,0\n", s), "rotation angle nan is not finite"));
}

TEST(ImuLogTest, ColumnsByNameInAnyCaseOrByIndex) {
  // Default names time gx gy gz ax ay az, in any case; other columns are passed over.
  auto r = readImu("Time,temp,GX,gy,gz\n1.5,20,0.1,0.2,0.3\n", rates());
  ASSERT_EQ(r.size(), 1u);
  EXPECT_EQ(r[0].stamp, 1500000000);
  EXPECT_EQ(r[0].angular_velocity, (std::array<double, 3>{0.1, 0.2, 0.3}));
  EXPECT_EQ(r[0].specific_force, (std::array<double, 3>{0, 0, 0}));
  ImuLogSettings s;
  s.columns = {{"time", "t_s"}, {"gx", "wx"}, {"gy", "#3"}, {"gz", "wz"}, {"ax", "fx"}, {"ay", "fy"}, {"az", "#7"}};
  ImuLogSetup setup;
  r = readImu("t_s,wx,wy,wz,fx,fy,fz\n2,1,2,3,4,5,6\n", s, nullptr, &setup);
  EXPECT_TRUE(setup.time_column);
  EXPECT_TRUE(setup.accelerometer);
  EXPECT_EQ(r[0].angular_velocity, (std::array<double, 3>{1, 2, 3}));
  EXPECT_EQ(r[0].specific_force, (std::array<double, 3>{4, 5, 6}));
  // Without a header row, by index only.
  r = readImu("2 1 2 3\n", withoutHeader({{"time", "#1"}, {"gx", "#2"}, {"gy", "#3"}, {"gz", "#4"}}));
  EXPECT_EQ(r[0].angular_velocity, (std::array<double, 3>{1, 2, 3}));
}

TEST(ImuLogTest, MissingColumnsAndPartialAccelerometerAreRefused) {
  EXPECT_TRUE(has(refusal("time,gx,gy\n1,2,3\n", rates()),
                  "imu.txt:1: no column 'gz' for gz in the header ('time', "
                  "'gx', 'gy')"));
  ImuLogSettings s;
  s.columns = {{"ax", "fx"}};
  EXPECT_TRUE(has(refusal("time,gx,gy,gz\n1,2,3,4\n", s), "no column 'fx' for ax"));
  EXPECT_TRUE(has(refusal("time,gx,gy,gz,ax,az\n1,2,3,4,5,6\n", rates()),
                  "the accelerometer needs ax, ay and az or none of them, found ax, az"));
  EXPECT_TRUE(has(refusal("1 2 3\n", withoutHeader({{"gx", "#1"}, {"gy", "#2"}})),
                  "no header row, so gz needs its column by index: --column gz=#N (N from 1 to 3)"));
  EXPECT_TRUE(has(refusal("1 2 3\n", withoutHeader({{"gx", "#1"}, {"gy", "#2"}, {"gz", "#4"}})),
                  "column '#4' is not one of #1..#3"));
  // No time column and no interval: nothing says when a row was taken.
  EXPECT_TRUE(has(refusal("gx,gy,gz\n1,2,3\n", rates()),
                  "imu.txt: no time column ('time' or --column time=...): give the rows' spacing with --interval S"));
}

TEST(ImuLogTest, DelimitersCommentsAndSkippedHeaderLines) {
  const std::vector<std::pair<char, std::string>> layouts = {
      {',', "0.5,1,2,3\n1.0,4,5,6\n"},        {';', "0.5;1;2;3\n1.0;4;5;6\n"},
      {'\t', "0.5\t1\t2\t3\n1.0\t4\t5\t6\n"}, {kWhitespace, "  0.5  1 2\t3 \n1.0 4   5 6\n"},
      {0, "0.5 1 2 3\n1.0 4 5 6\n"},          {0, "0.5, 1, 2, 3\n1.0, 4, 5, 6\n"}};
  for (const auto& [delimiter, rows] : layouts) {
    ImuLogSettings s = withoutHeader({{"time", "#1"}, {"gx", "#2"}, {"gy", "#3"}, {"gz", "#4"}});
    s.layout.delimiter = delimiter;
    s.layout.blanks_when_no_delimiter = true;  // what the import's --delimiter auto asks
    s.layout.comment = "%";
    s.layout.preamble_lines = 2;
    const std::string text = "% site 7\n% scale 1\nIMU-3 serial 42\n\n% between\n0.1 0.1 0.1\n" + rows;
    const auto r = readImu(text, s);
    ASSERT_EQ(r.size(), 2u) << rows;
    EXPECT_EQ(r[0].line, 7u);
    EXPECT_EQ(r[1].stamp, 1000000000);
    EXPECT_EQ(r[1].angular_velocity, (std::array<double, 3>{4, 5, 6})) << rows;
  }
  // '#' is the default comment prefix; a header row may follow the skipped lines.
  ImuLogSettings s;
  s.layout.preamble_lines = 1;
  const auto r = readImu("# exported\nunit: rad/s\ntime,gx,gy,gz\n# late comment\n1,2,3,4\n", s);
  ASSERT_EQ(r.size(), 1u);
  EXPECT_EQ(r[0].line, 5u);
  // A log without the lines it should skip is refused.
  EXPECT_TRUE(has(refusal("# only a comment\n", s), "imu.txt: 0 of its 1 header lines"));
}

TEST(ImuLogTest, BadRowsNameTheLineAndTheColumnOrAreSkippedAndCounted) {
  const std::string head = "time,gx,gy,gz\n1.0,1,2,3\n";
  EXPECT_EQ(refusal(head + "2.0,1,2,3\n", rates()), "");
  EXPECT_EQ(refusal(head + "2.0,1,1.5abc,3\n", rates()),
            "imu.txt:3: unreadable number: gy (#3): '1.5abc' is not a number");
  EXPECT_EQ(refusal(head + "2.0,1,,3\n", rates()),
            "imu.txt:3: unreadable number: gy (#3): empty field where a number belongs");
  EXPECT_EQ(refusal(head + "2.0,1,2\n", rates()), "imu.txt:3: wrong field count: 3 fields, the header has 4");
  EXPECT_TRUE(has(refusal(head + "1.0,1,2,3\n", rates()),
                  "imu.txt:3: stamp not increasing: time 1.000000000 s is not after the previous row's 1.000000000 s"));
  EXPECT_TRUE(has(refusal(head + "0.5,1,2,3\n", rates()), "imu.txt:3: stamp not increasing"));
  EXPECT_TRUE(has(refusal(head + "2.0e0,1,2,3\n", rates()), "imu.txt:3: unreadable stamp: time (#1): stamp"));
  EXPECT_TRUE(has(refusal(head + "--2.0,1,2,3\n", rates()), "imu.txt:3: unreadable stamp: time (#1)"));
  EXPECT_EQ(refusal(head + "2.0,nan,2,3\n", rates()),
            "imu.txt:3: NaN or infinity not allowed: gx (#2) is nan (a number is required here)");
  EXPECT_TRUE(has(refusal(head + "2.0,1,2,-inf\n", rates()), "imu.txt:3: NaN or infinity not allowed: gz (#4)"));
  ImuLogSettings big;
  big.gyro_scale = std::array<double, 3>{1e300, 1, 1};
  EXPECT_TRUE(has(refusal(head + "2.0,1e10,2,3\n", big),
                  "imu.txt:3: NaN or infinity not allowed: gx (#2) 1e10 times its scale and unit overflows"));
  // Without a header row the first row sets the field count.
  EXPECT_TRUE(
      has(refusal("1 2 3 4\n2 1 2\n", withoutHeader({{"time", "#1"}, {"gx", "#2"}, {"gy", "#3"}, {"gz", "#4"}})),
          "imu.txt:2: wrong field count: 3 fields, the first row has 4"));
  // Skipped and counted; a skipped row's good stamp still orders the next.
  ImuLogSettings s;
  s.skip_bad_rows = true;
  BadRowCounts skipped;
  const auto r = readImu(
      head + "2.0,1,2\n3.0,x,2,3\n2.5,1,2,3\n4.0,1,2,3\n" + std::string(2 << 20, '9') + "\n5,1,2,3\n", s, &skipped);
  ASSERT_EQ(r.size(), 3u);
  EXPECT_EQ(r[1].stamp, 4000000000);
  EXPECT_EQ(r[1].row, 4u);  // rows counted from 0 with the skipped ones: a gap in the sequence
  EXPECT_EQ(r[1].interval, 1.0);
  EXPECT_EQ(r[2].line, 8u);
  EXPECT_EQ(skipped.summary(), "4 (line too long 1, wrong field count 1, stamp not increasing 1, unreadable number 1)");
}

TEST(ImuLogTest, CountsTimesScalesAreExactToTheBit) {
  // Rates in counts: 0.01 deg/h a count on x, 0.02 on y and z; accelerometer 1 mg a count, g given.
  ImuLogSettings s;
  s.gyro_unit = "deg/h";
  s.gyro_scale = std::array<double, 3>{0.01, 0.02, 0.02};
  s.accel_unit = "mg";
  s.accel_scale = std::array<double, 3>{1, 1, 1};
  s.gravity = 9.7803253359;
  auto r = readImu("time,gx,gy,gz,ax,ay,az\n1.0,1503,-77,30011,-12,3,1000\n", s);
  ASSERT_EQ(r.size(), 1u);
  EXPECT_EQ(r[0].angular_velocity[0], 1503.0 * (0.01 * (kDegree / 3600.0)));
  EXPECT_EQ(r[0].angular_velocity[1], -77.0 * (0.02 * (kDegree / 3600.0)));
  EXPECT_EQ(r[0].angular_velocity[2], 30011.0 * (0.02 * (kDegree / 3600.0)));
  EXPECT_EQ(r[0].specific_force[0], -12.0 * (1.0 * (1e-3 * 9.7803253359)));
  EXPECT_EQ(r[0].specific_force[2], 1000.0 * (1.0 * (1e-3 * 9.7803253359)));
  // Increments in counts: 0.1 arcsec and 125 ug*s a count (PSINS's), 100 Hz, no time column.
  ImuLogSettings inc =
      withoutHeader({{"gx", "#1"}, {"gy", "#2"}, {"gz", "#3"}, {"ax", "#4"}, {"ay", "#5"}, {"az", "#6"}});
  inc.gyro_unit = "arcsec";
  inc.gyro_scale = std::array<double, 3>{0.1, 0.1, 0.1};
  inc.accel_unit = "ug*s";
  inc.accel_scale = std::array<double, 3>{125, 125, 125};
  inc.gravity = 9.780327;
  inc.interval = 0.01;
  r = readImu("7 -9 2 0 1 80\n", inc);
  EXPECT_EQ(r[0].stamp, 10000000);
  EXPECT_EQ(r[0].interval, 0.01);
  EXPECT_EQ(r[0].angular_velocity[0], 7.0 * (0.1 * kArcsecond) / 0.01);
  EXPECT_EQ(r[0].angular_velocity[1], -9.0 * (0.1 * kArcsecond) / 0.01);
  EXPECT_EQ(r[0].specific_force[1], 1.0 * (125.0 * (1e-6 * 9.780327)) / 0.01);
  EXPECT_EQ(r[0].specific_force[2], 80.0 * (125.0 * (1e-6 * 9.780327)) / 0.01);
  EXPECT_NEAR(r[0].specific_force[2], 9.780327, 1e-12);
  // A scale of zero or not finite is refused, naming the axis.
  inc.gyro_scale = std::array<double, 3>{0.1, 0.0, 0.1};
  EXPECT_TRUE(has(refusal("7 -9 2 0 1 80\n", inc), "gyro scale 0 of the log's y axis is not a finite non-zero"));
  inc.gyro_scale.reset();
  inc.accel_scale = std::array<double, 3>{125, 125, INFINITY};
  EXPECT_TRUE(has(refusal("7 -9 2 0 1 80\n", inc), "accelerometer scale inf of the log's z axis"));
  inc.accel_scale.reset();
  inc.gravity = 0.0;
  EXPECT_TRUE(has(refusal("7 -9 2 0 1 80\n", inc), "gravity 0 m/s^2 is not a positive number"));
}

TEST(ImuLogTest, IncrementsAndRatesGiveTheSameRates) {
  // Uneven spacing of 0.5, 0.75 and 1 s: increment = rate x interval is exact here, so the rates read
  // back from the increments are the rates, bit for bit.
  const std::vector<double> times = {10.0, 10.5, 11.25, 12.25};
  const std::vector<std::array<double, 3>> w = {{1, -2, 4}, {2, -4, 8}, {3, -6, 12}, {4, -8, 16}};
  std::string rate_log = "time,gx,gy,gz,ax,ay,az\n", increment_log = rate_log;
  for (std::size_t i = 0; i < times.size(); ++i) {
    const double dt = i == 0 ? 0.5 : times[i] - times[i - 1];  // the first row: the next row's interval
    char line[256];
    std::snprintf(line, sizeof line, "%.17g,%.17g,%.17g,%.17g,0.5,0.25,9.75\n", times[i], w[i][0], w[i][1], w[i][2]);
    rate_log += line;
    std::snprintf(line, sizeof line, "%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g\n", times[i], w[i][0] * dt,
                  w[i][1] * dt, w[i][2] * dt, 0.5 * dt, 0.25 * dt, 9.75 * dt);
    increment_log += line;
  }
  const auto from_rates = readImu(rate_log, rates());
  ImuLogSettings s;
  s.gyro_unit = "rad";
  s.accel_unit = "m/s";
  const auto from_increments = readImu(increment_log, s);
  ASSERT_EQ(from_rates.size(), 4u);
  ASSERT_EQ(from_increments.size(), 4u);
  for (std::size_t i = 0; i < 4; ++i) {
    EXPECT_EQ(from_increments[i].stamp, from_rates[i].stamp);
    EXPECT_EQ(from_increments[i].angular_velocity, w[i]) << i;
    EXPECT_EQ(from_increments[i].specific_force, (std::array<double, 3>{0.5, 0.25, 9.75})) << i;
    EXPECT_EQ(from_rates[i].angular_velocity, w[i]) << i;
  }
  EXPECT_EQ(from_increments[0].interval, 0.5);
  EXPECT_EQ(from_increments[2].interval, 0.75);
  // The first row's interval given: its increments are divided by it instead.
  s.interval = 0.25;
  EXPECT_EQ(readImu(increment_log, s)[0].angular_velocity, (std::array<double, 3>{2, -4, 8}));
  // deg increments against deg/s rates alike.
  ImuLogSettings deg_rates, deg_increments;
  deg_rates.gyro_unit = "deg/s";
  deg_increments.gyro_unit = "deg";
  const auto a = readImu("time,gx,gy,gz\n1,10,20,30\n1.5,10,20,30\n", deg_rates);
  const auto b = readImu("time,gx,gy,gz\n1,5,10,15\n1.5,5,10,15\n", deg_increments);
  EXPECT_EQ(a[1].angular_velocity, b[1].angular_velocity);
  EXPECT_EQ(a[0].angular_velocity, b[0].angular_velocity);
  // One row of increments with nothing to give its interval is refused.
  ImuLogSettings one;
  one.gyro_unit = "rad";
  EXPECT_TRUE(has(refusal("time,gx,gy,gz\n1,5,10,15\n", one),
                  "imu.txt:2: one row of increments: its interval is unknown (give --interval S)"));
}

TEST(ImuLogTest, WithoutTimeColumnRowNClosesNIntervals) {
  ImuLogSettings s = withoutHeader({{"gx", "#1"}, {"gy", "#2"}, {"gz", "#3"}});
  s.interval = 0.005;
  s.skip_bad_rows = true;
  BadRowCounts skipped;
  const auto r = readImu("1 2 3\n1 x 3\n1 2 3\n", s, &skipped);
  ASSERT_EQ(r.size(), 2u);
  EXPECT_EQ(r[0].stamp, 5000000);
  EXPECT_EQ(r[1].stamp, 15000000);  // the skipped row keeps its place in time
  EXPECT_EQ(r[1].interval, 0.005);  // and an increment's interval stays the spacing
  EXPECT_EQ(r[1].row, 2u);
  // 1/3 ms: each stamp rounded to its nanosecond from n, no error accumulated.
  s.interval = 1.0 / 3000.0;
  std::string rows;
  for (int i = 0; i < 3000; ++i) rows += "0 0 0\n";
  const auto third = readImu(rows, s);
  EXPECT_EQ(third[0].stamp, 333333);
  EXPECT_EQ(third[1].stamp, 666667);
  EXPECT_EQ(third.back().stamp, 1000000000);
  s.interval = 0.0;
  EXPECT_TRUE(has(refusal("1 2 3\n", s), "interval 0 s is outside [1e-9, 1e6] s"));
}

TEST(ImuLogTest, EpochShiftsEveryStampAndAStampABagCannotHoldIsRefused) {
  ImuLogSettings s = rates();
  s.earliest_stamp = 1;  // a bag's ros::TIME_MIN
  s.latest_stamp = 4294967295999999999LL;
  s.stamp_range_holder = "a bag";
  const std::string log = "time,gx,gy,gz\n0.0,1,2,3\n0.01,1,2,3\n";
  EXPECT_TRUE(has(refusal(log, s),
                  "imu.txt:2: stamp out of range: time 0.000000000 s + epoch 0.000000000 s is "
                  "outside [0.000000001 s, 4294967295.999999999 s], the stamps a bag can hold: pass "
                  "--epoch S, the Unix time of the log's t = 0"));
  s.epoch = 1395394311000000000LL;
  auto r = readImu(log, s);
  ASSERT_EQ(r.size(), 2u);
  EXPECT_EQ(r[0].stamp, 1395394311000000000LL);
  EXPECT_EQ(r[1].stamp, 1395394311010000000LL);
  // A log's times may be negative (before its t = 0): the epoch brings them in range.
  r = readImu("time,gx,gy,gz\n-0.5,1,2,3\n+0.25,1,2,3\n", s);
  EXPECT_EQ(r[0].stamp, 1395394310500000000LL);
  EXPECT_EQ(r[1].stamp, 1395394311250000000LL);
  s.epoch = 4294967295995000000LL;  // 0.01 s after it is 2^32 s
  EXPECT_TRUE(has(refusal(log, s), "imu.txt:3: stamp out of range"));
  EXPECT_TRUE(has(refusal(log, s), "check --epoch"));
  // Without a time column row 1 closes the first interval: a log from t = 0 fits without an epoch.
  ImuLogSettings spaced = withoutHeader({{"gx", "#1"}, {"gy", "#2"}, {"gz", "#3"}});
  spaced.earliest_stamp = 1;
  spaced.interval = 0.01;
  EXPECT_EQ(readImu("1 2 3\n", spaced)[0].stamp, 10000000);
  spaced.epoch = 1395394311000000000LL;
  EXPECT_EQ(readImu("1 2 3\n", spaced)[0].stamp, 1395394311010000000LL);
}

TEST(ImuLogTest, PsinsHeaderFromInlineText) {
  std::istringstream in(kPsins);
  ImuLogReader reader(in, "simu.imu", psins(), nullptr);
  ASSERT_TRUE(reader.setup().psins);
  const PsinsHeader& h = *reader.setup().psins;
  EXPECT_EQ(h.pitch_deg, 0.0);
  EXPECT_EQ(h.yaw_deg, -90.6);
  EXPECT_DOUBLE_EQ(h.trueHeadingDeg(), 90.6);  // counter-clockwise -90.6 from north: 90.6 east of it
  EXPECT_EQ(h.site.latitude_deg, 34.246048);
  EXPECT_EQ(h.site.longitude_deg, 108.909664);
  EXPECT_EQ(h.site.height_m, 380.0);
  EXPECT_EQ(h.t0, 0.0);
  EXPECT_EQ(h.interval_ms, 10.0);
  EXPECT_EQ(h.gravity, 9.780327);
  EXPECT_EQ(h.gyro_scale, (std::array<double, 3>{0.1, 0.1, 0.1}));
  EXPECT_EQ(h.accel_scale, (std::array<double, 3>{125, 125, 125}));
  PsinsHeader turned;
  turned.yaw_deg = 45.0;  // 45 deg west of north
  EXPECT_DOUBLE_EQ(turned.trueHeadingDeg(), 315.0);
  EXPECT_EQ(PsinsHeader{}.trueHeadingDeg(), 0.0);
  // The preset: what the reader does with it.
  const ImuLogSetup& setup = reader.setup();
  EXPECT_EQ(setup.gyro_unit, "arcsec");
  EXPECT_EQ(setup.accel_unit, "ug*s");
  EXPECT_EQ(setup.gravity, 9.780327);
  EXPECT_EQ(*setup.interval, 0.01);
  EXPECT_EQ(setup.frame, "RFU");
  EXPECT_FALSE(setup.time_column);
  EXPECT_TRUE(setup.accelerometer);
  ASSERT_TRUE(setup.site);
  EXPECT_EQ(setup.site->latitude_deg, 34.246048);
}

TEST(ImuLogTest, PsinsHeaderRefusalsNameTheLineAndTheField) {
  auto with = [](int line, const std::string& text) {
    std::string log = kPsins;
    std::size_t at = 0;
    for (int i = 1; i < line; ++i) at = log.find('\n', at) + 1;
    return log.replace(at, log.find('\n', at) - at, text);
  };
  EXPECT_EQ(refusal(with(5, "34.24 108.9 380 0 abc 9.78"), psins()),
            "imu.txt:5: PSINS header line 2 field 5 (sampling interval, ms): 'abc' is not a number");
  EXPECT_EQ(refusal(with(5, "34.24 108.9 380 0 0 9.78"), psins()),
            "imu.txt:5: PSINS header line 2 field 5 (sampling interval, ms): 0 is no interval (1 ns to 1e6 s)");
  EXPECT_EQ(refusal(with(5, "94.24 108.9 380 0 10 9.78"), psins()),
            "imu.txt:5: PSINS header line 2 field 1 (latitude0, deg): 94.24 is outside [-90, 90]");
  EXPECT_EQ(refusal(with(5, "34.24 108.9 380 0 10 -9.78"), psins()),
            "imu.txt:5: PSINS header line 2 field 6 (g, m/s^2): -9.78 is no gravity (positive)");
  EXPECT_EQ(refusal(with(6, "0.1 0.1 0 125 125 125"), psins()),
            "imu.txt:6: PSINS header line 3 field 3 (gf_z, arcsec/count): 0 would make every count 0");
  EXPECT_EQ(refusal(with(4, "0 0 -90.6 0 0"), psins()),
            "imu.txt:4: PSINS header line 1: 5 fields, 6 expected (pitch0, deg ... VU0, m/s)");
  EXPECT_TRUE(has(refusal(with(4, "0 0 -90.6 0 0 0 0"), psins()), "7 fields, 6 expected"));
  EXPECT_TRUE(has(refusal(with(4, "0 0 -90.6 0 0 0 0"), psins()), "sampling-time dither column is not read"));
  EXPECT_EQ(refusal(with(4, "0 0 inf 0 0 0"), psins()),
            "imu.txt:4: PSINS header line 1 field 3 (yaw0, deg): 'inf' is not finite");
  EXPECT_EQ(refusal(with(7, "0 0 2 0 0 80 3"), psins()),
            "imu.txt:7: 7 fields, a PSINS row has 6 (gx gy gz ax ay az); the variant with a sampling-time dither "
            "column is not read");
  EXPECT_EQ(refusal(with(8, "-4 7 0 1 -2"), psins()), "imu.txt:8: wrong field count: 5 fields, the first row has 6");
  EXPECT_TRUE(has(refusal("% PSINS\n0 0 0 0 0 0\n1 2 3 4 5 6\n", psins()), "imu.txt: 2 of its 3 header lines"));
}

TEST(ImuLogTest, PsinsRowsAreIncrementsInCountsOnRightForwardUp) {
  ImuLogSettings s = psins();
  s.epoch = 1395394311000000000LL;
  const auto r = readImu(kPsins, s);
  ASSERT_EQ(r.size(), 2u);
  // Row n closes t0 + n x 10 ms (imufile.m: "t0+ts = sampling time of the first IMU record").
  EXPECT_EQ(r[0].stamp, 1395394311010000000LL);
  EXPECT_EQ(r[1].stamp, 1395394311020000000LL);
  EXPECT_EQ(r[0].line, 7u);
  const double gyro = 0.1 * kArcsecond, accel = 125.0 * (1e-6 * 9.780327);
  // RFU to FLU: forward = y, left = -x, up = z.
  EXPECT_EQ(r[0].angular_velocity, (std::array<double, 3>{0.0, 0.0, 2.0 * gyro / 0.01}));
  EXPECT_EQ(r[0].specific_force, (std::array<double, 3>{0.0, 0.0, 80.0 * accel / 0.01}));
  EXPECT_EQ(r[1].angular_velocity[0], 7.0 * gyro / 0.01);
  EXPECT_EQ(r[1].angular_velocity[1], -(-4.0 * gyro / 0.01));
  EXPECT_EQ(r[1].specific_force[0], -2.0 * accel / 0.01);
  EXPECT_EQ(r[1].specific_force[1], -(1.0 * accel / 0.01));
  // Options given win over the header: interval, scale, gravity, frame, site.
  s.interval = 0.005;
  s.gyro_scale = std::array<double, 3>{0.2, 0.2, 0.2};
  s.gravity = 9.8;
  s.frame = "FLU";
  s.latitude = 45.0;
  s.height = 12.0;
  ImuLogSetup setup;
  const auto o = readImu(kPsins, s, nullptr, &setup);
  EXPECT_EQ(o[1].stamp, 1395394311010000000LL);
  EXPECT_EQ(o[1].angular_velocity[0], -4.0 * (0.2 * kArcsecond) / 0.005);
  EXPECT_EQ(o[1].specific_force[1], -2.0 * (125.0 * (1e-6 * 9.8)) / 0.005);
  EXPECT_EQ(setup.site->latitude_deg, 45.0);
  EXPECT_EQ(setup.site->longitude_deg, 108.909664);  // the header's: not given
  EXPECT_EQ(setup.site->height_m, 12.0);
  s.latitude = 91.0;
  EXPECT_TRUE(has(refusal(kPsins, s), "latitude 91 deg is outside [-90, 90]"));
  s.latitude.reset();
  s.longitude = 181.0;
  EXPECT_TRUE(has(refusal(kPsins, s), "longitude 181 deg is outside [-180, 180]"));
}

TEST(ImuLogTest, SiteFromTheSettingsLatitudeAndLongitudeTogether) {
  const std::string log = "time,gx,gy,gz\n1,0,0,0\n";
  ImuLogSetup setup;
  readImu(log, rates(), nullptr, &setup);
  EXPECT_FALSE(setup.site);
  ImuLogSettings s;
  s.latitude = -33.9;
  s.longitude = 18.4;
  readImu(log, s, nullptr, &setup);
  ASSERT_TRUE(setup.site);
  EXPECT_EQ(setup.site->latitude_deg, -33.9);
  EXPECT_TRUE(std::isnan(setup.site->height_m));  // not given: unknown
  s.height = 10.0;
  readImu(log, s, nullptr, &setup);
  EXPECT_EQ(setup.site->height_m, 10.0);
  s.longitude.reset();
  EXPECT_TRUE(has(refusal(log, s), "a latitude without a longitude or the reverse: give both (no longitude)"));
  s.latitude.reset();
  EXPECT_TRUE(has(refusal(log, s), "a height without a latitude and longitude"));
  s.height = INFINITY;
  s.latitude = 1.0;
  s.longitude = 2.0;
  EXPECT_TRUE(has(refusal(log, s), "height inf m is not finite"));
}

TEST(ImuLogTest, SummaryLineGivesRowsStampsRateAndTheMeanVectors) {
  ImuSummary summary;
  BadRowCounts skipped;
  EXPECT_EQ(summary.line(true, skipped), "0 rows, skipped 0");
  for (int i = 0; i < 101; ++i) {
    ImuRecord r;
    r.stamp = 1000000000LL + i * 10000000LL;
    r.angular_velocity = {0.0, 6e-5, 4e-5 + (i % 2 == 0 ? 1e-3 : -1e-3)};
    r.specific_force = {0.0, 3.0, 4.0};
    summary.add(r);
  }
  skipped.by_reason[static_cast<std::size_t>(BadRowReason::kNumber)] = 2;
  const std::string line = summary.line(true, skipped);
  EXPECT_TRUE(has(line, "101 rows, stamps 1.000000000 .. 2.000000000 s (1.000 s, 100.000 Hz)")) << line;
  // |(0, 6e-5, 4e-5 + 1e-3 / 101)| = 7.8039e-05 rad/s: the mean vector's length, not the mean length.
  EXPECT_TRUE(has(line, "|mean omega| 7.8039e-05 rad/s = 1.0702 Earth rates")) << line;
  EXPECT_TRUE(has(line, "|mean f| 5.0000 m/s^2, skipped 2 (unreadable number 2)")) << line;
  EXPECT_TRUE(has(summary.line(false, skipped), "no accelerometer")) << line;
}

}  // namespace
}  // namespace csv
}  // namespace hrg_gyro

#include "gyro_logs.h"

#include <gtest/gtest.h>

#include <cmath>
#include <sstream>
#include <vector>

namespace hrg_gyro {
namespace csv {
namespace {

std::vector<ChannelRecord> readChannels(const std::string& text, const LogSettings& settings = {},
                                        BadRowCounts* skipped = nullptr) {
  std::istringstream in(text);
  ChannelLogReader reader(in, "ch.csv", settings, skipped);
  std::vector<ChannelRecord> records;
  ChannelRecord r;
  while (reader.next(&r)) records.push_back(r);
  return records;
}

std::vector<TurntableRecord> readTurntable(const std::string& text, const LogSettings& settings = {},
                                           BadRowCounts* skipped = nullptr) {
  std::istringstream in(text);
  TurntableLogReader reader(in, "tt.csv", settings, skipped);
  std::vector<TurntableRecord> records;
  TurntableRecord r;
  while (reader.next(&r)) records.push_back(r);
  return records;
}

/// The message of the refusal of `text`, "" when it was accepted.
std::string refusal(const std::string& text) {
  try {
    readChannels(text);
  } catch (const BadRowError& e) {
    return e.what();
  }
  return "";
}

const char* kHeader = "stamp,ac,bc,as,bs\n";

TEST(GyroLogsTest, ChannelRecordsWithDefaultNamesAndOptionalColumns) {
  const auto records = readChannels(
      "stamp,Ac,Bc,As,Bs,frequency,temperature,periods\n"
      "1.5,0.9,0.1,-0.2,0.01,5000.25,nan,25\n"
      "1700000000123456789,1,2,3,4,5001,21.5,0\n");
  ASSERT_EQ(records.size(), 2u);
  EXPECT_EQ(records[0].stamp, 1500000000LL);
  EXPECT_EQ(records[0].ac, 0.9);
  EXPECT_EQ(records[0].bs, 0.01);
  EXPECT_EQ(records[0].frequency, 5000.25);
  EXPECT_TRUE(std::isnan(records[0].temperature));
  EXPECT_EQ(records[0].periods, 25u);
  EXPECT_EQ(records[1].stamp, 1700000000123456789LL);
  EXPECT_EQ(records[1].temperature, 21.5);
  const auto minimal = readChannels(std::string(kHeader) + "1,1,2,3,4\n");
  ASSERT_EQ(minimal.size(), 1u);
  EXPECT_TRUE(std::isnan(minimal[0].frequency));
  EXPECT_TRUE(std::isnan(minimal[0].temperature));
  EXPECT_EQ(minimal[0].periods, 0u);
}

TEST(GyroLogsTest, ColumnsMappedByNameOrIndex) {
  LogSettings settings;
  settings.columns = {{"stamp", "t_ns"}, {"ac", "Ac_V"}, {"bc", "#3"}, {"as", "As_V"}, {"bs", "Bs_V"}};
  const auto records = readChannels("t_ns;Ac_V;quad;As_V;Bs_V\n1000;1;2;3;4\n", settings);
  ASSERT_EQ(records.size(), 1u);
  EXPECT_EQ(records[0].stamp, 1000);
  EXPECT_EQ(records[0].bc, 2.0);
  // A column that is neither in the header nor mapped: named with the file and the key.
  try {
    readChannels("stamp,ac,bc,as\n1,1,2,3\n");
    FAIL() << "a log without bs was accepted";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("no column 'bs' for bs"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("ch.csv:1"), std::string::npos) << e.what();
  }
  // An optional column named by an option must exist.
  settings.columns = {{"temperature", "T_degC"}};
  EXPECT_THROW(readChannels(std::string(kHeader) + "1,1,2,3,4\n", settings), std::runtime_error);
}

TEST(GyroLogsTest, WithoutHeaderEveryColumnByIndex) {
  LogSettings settings;
  settings.has_header = false;
  settings.columns = {{"stamp", "#1"}, {"ac", "#2"}, {"bc", "#3"}, {"as", "#4"}, {"bs", "#5"}};
  const auto records = readChannels("1000,1,2,3,4\n2000,5,6,7,8\n", settings);
  ASSERT_EQ(records.size(), 2u);
  EXPECT_EQ(records[0].stamp, 1000);
  EXPECT_EQ(records[1].bs, 8.0);
  settings.columns.erase("bs");
  try {
    readChannels("1000,1,2,3,4\n", settings);
    FAIL() << "bs without a column was accepted";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("--column bs=#N (N from 1 to 5)"), std::string::npos) << e.what();
  }
}

TEST(GyroLogsTest, EveryBadRowReasonWithItsLineNumber) {
  const std::string ok = std::string(kHeader) + "1.0,1,2,3,4\n";
  EXPECT_NE(refusal(ok + "2.0,1,2,3\n").find("ch.csv:3: wrong field count: 4 fields, the header has 5"),
            std::string::npos);
  EXPECT_NE(refusal(ok + "# c\n2.0,1,2,3,4,5\n").find("ch.csv:4: wrong field count"), std::string::npos);
  EXPECT_NE(refusal(ok + "abc,1,2,3,4\n").find("ch.csv:3: unreadable stamp"), std::string::npos);
  EXPECT_NE(refusal(ok + "0.5,1,2,3,4\n").find("ch.csv:3: stamp not increasing"), std::string::npos);
  EXPECT_NE(refusal(ok + "1.0,1,2,3,4\n").find("ch.csv:3: stamp not increasing"), std::string::npos);
  EXPECT_NE(refusal(ok + "2.0,1.5abc,2,3,4\n").find("ch.csv:3: unreadable number: ac: '1.5abc' is not a number"),
            std::string::npos);
  EXPECT_NE(refusal(ok + "2.0,1,2,nan,4\n").find("ch.csv:3: NaN or infinity not allowed: as is nan"),
            std::string::npos);
  EXPECT_NE(refusal(ok + "2.0,1,2,3,inf\n").find("ch.csv:3: NaN or infinity not allowed: bs"), std::string::npos);
  EXPECT_EQ(refusal(ok + "2.0,1,2,3,4\n"), "");
  // "1,5" under a ';' delimiter is a number refused, never 1.
  EXPECT_NE(refusal("stamp;ac;bc;as;bs\n1.0;1,5;2;3;4\n").find("ch.csv:2: unreadable number: ac: '1,5'"),
            std::string::npos);
  const std::string periods = "stamp,ac,bc,as,bs,periods\n";
  EXPECT_NE(refusal(periods + "1,1,2,3,4,-1\n").find("periods"), std::string::npos);
  EXPECT_NE(refusal(periods + "1,1,2,3,4,2.5\n").find("periods"), std::string::npos);
}

TEST(GyroLogsTest, ALineTooLongIsABadRecord) {
  const std::string ok = std::string(kHeader) + "1.0,1,2,3,4\n";
  const std::string long_line = "2.0,1,2,3," + std::string(kMaxLineBytes, '4') + "\n";
  EXPECT_NE(refusal(ok + long_line)
                .find("ch.csv:3: line too long: more than 1048576 bytes (1 MiB), the limit of a "
                      "line"),
            std::string::npos);
  LogSettings settings;
  settings.skip_bad_rows = true;
  BadRowCounts skipped;
  const auto records = readChannels(ok + long_line + "3.0,5,6,7,8\n", settings, &skipped);
  ASSERT_EQ(records.size(), 2u);
  EXPECT_EQ(records[1].stamp, 3000000000LL);
  EXPECT_EQ(records[1].bs, 8.0);
  EXPECT_EQ(skipped.summary(), "1 (line too long 1)");
}

TEST(GyroLogsTest, AStampOutsideWhatTheOutputHoldsIsABadRecord) {
  // The range import gives: what a bag's ros::Time holds, [TIME_MIN, TIME_MAX].
  LogSettings bag;
  bag.earliest_stamp = 1;
  bag.latest_stamp = 4294967295999999999LL;
  bag.stamp_range_holder = "a bag";
  auto why = [&](const std::string& stamp) -> std::string {
    try {
      readChannels(std::string(kHeader) + stamp + ",1,2,3,4\n", bag);
    } catch (const BadRowError& e) {
      EXPECT_EQ(e.reason, BadRowReason::kStampRange) << e.what();
      return e.what();
    }
    return "";
  };
  EXPECT_EQ(why("0"),
            "ch.csv:2: stamp out of range: stamp 0.000000000 s is outside [0.000000001 s, 4294967295.999999999 s], "
            "the stamps a bag can hold");
  EXPECT_NE(why("4294967296.0").find("ch.csv:2: stamp out of range: stamp 4294967296.000000000 s is outside"),
            std::string::npos);
  EXPECT_NE(why("2106-02-07T06:28:16Z").find("stamp 4294967296.000000000 s is outside"), std::string::npos);
  EXPECT_NE(why("99999999999999999999")
                .find("ch.csv:2: stamp out of range: stamp '99999999999999999999' is out of "
                      "range"),
            std::string::npos);
  EXPECT_NE(why("-1.5").find("is negative"), std::string::npos);
  EXPECT_NE(why("1969-12-31T23:59:59Z").find("before 1970"), std::string::npos);
  // The two ends themselves are stamps a bag holds.
  EXPECT_EQ(why("0.000000001"), "");
  EXPECT_EQ(why("4294967295.999999999"), "");
  // Skipped and counted like any other bad record; a later good record is read.
  bag.skip_bad_rows = true;
  BadRowCounts skipped;
  const auto records =
      readChannels(std::string(kHeader) + "0,1,2,3,4\n5000000000000000000,1,2,3,4\n2.5,1,2,3,4\n", bag, &skipped);
  ASSERT_EQ(records.size(), 1u);
  EXPECT_EQ(records[0].stamp, 2500000000LL);
  EXPECT_EQ(skipped.summary(), "2 (stamp out of range 2)");
}

TEST(GyroLogsTest, LongFieldsAndHeadersAreQuotedAsExcerpts) {
  const std::string field(500000, '7');
  const std::string ok = std::string(kHeader) + "1.0,1,2,3,4\n";
  for (const std::string& record :
       {"2.0," + field + "x,2,3,4\n", "2.0,1,2,3," + field + "nan\n", field + "x,1,2,3,4\n"}) {
    const std::string why = refusal(ok + record);
    EXPECT_NE(why.find("ch.csv:3: "), std::string::npos) << why.substr(0, 300);
    EXPECT_NE(why.find("... (5000"), std::string::npos) << why.substr(0, 300);
    EXPECT_LT(why.size(), 300u) << why.substr(0, 300);
  }
  const std::string periods = refusal("stamp,ac,bc,as,bs,periods\n1,1,2,3,4," + field + "\n");
  EXPECT_NE(periods.find("periods: '" + std::string(kQuotedBytes, '7') + "... (500000 bytes)'"), std::string::npos)
      << periods.substr(0, 300);
  // A header of 5000 long names: the message names a few of them, each cut.
  std::string header = "stamp";
  for (int i = 0; i < 5000; ++i) header += "," + std::string(100, 'h') + std::to_string(i);
  try {
    readChannels(header + "\n");
    FAIL() << "a header without ac was accepted";
  } catch (const std::runtime_error& e) {
    const std::string why = e.what();
    EXPECT_NE(why.find("no column 'ac' for ac in the header ('stamp', '" + std::string(kQuotedBytes, 'h') +
                       "... (101 bytes)'"),
              std::string::npos)
        << why.substr(0, 300);
    EXPECT_NE(why.find(", ... (5001 columns))"), std::string::npos) << why.substr(0, 300);
    EXPECT_LT(why.size(), 2000u);
  }
}

TEST(GyroLogsTest, SkippedRowsAreCountedByReason) {
  LogSettings settings;
  settings.skip_bad_rows = true;
  BadRowCounts skipped;
  const auto records = readChannels(std::string(kHeader) +
                                        "1.0,1,2,3,4\n"
                                        "2.0,1,2,3\n"    // field count
                                        "0.5,1,2,3,4\n"  // stamp going back
                                        "1.0,1,2,3,4\n"  // stamp repeated
                                        "x,1,2,3,4\n"    // stamp
                                        "3.0,1,y,3,4\n"  // number
                                        "4.0,1,2,nan,4\n"
                                        "5.0,5,6,7,8\n",
                                    settings, &skipped);
  ASSERT_EQ(records.size(), 2u);
  EXPECT_EQ(records[1].stamp, 5000000000LL);
  EXPECT_EQ(records[1].ac, 5.0);
  EXPECT_EQ(skipped.total(), 6u);
  EXPECT_EQ(skipped.by_reason[static_cast<std::size_t>(BadRowReason::kFieldCount)], 1u);
  EXPECT_EQ(skipped.by_reason[static_cast<std::size_t>(BadRowReason::kStampOrder)], 2u);
  EXPECT_EQ(skipped.by_reason[static_cast<std::size_t>(BadRowReason::kStamp)], 1u);
  EXPECT_EQ(skipped.by_reason[static_cast<std::size_t>(BadRowReason::kNumber)], 1u);
  EXPECT_EQ(skipped.by_reason[static_cast<std::size_t>(BadRowReason::kNotANumber)], 1u);
  EXPECT_EQ(skipped.summary(),
            "6 (wrong field count 1, unreadable stamp 1, stamp not increasing 2, unreadable number 1, NaN or "
            "infinity not allowed 1)");
}

TEST(GyroLogsTest, TurntableUnitsAreConverted) {
  LogSettings settings;
  settings.angle_scale = M_PI / 180.0;
  settings.rate_scale = M_PI / 180.0;
  const auto records = readTurntable("stamp\tangle_deg\trate_dps\n1\t180\t-90\n", [&] {
    settings.columns = {{"angle", "angle_deg"}, {"rate", "rate_dps"}};
    return settings;
  }());
  ASSERT_EQ(records.size(), 1u);
  EXPECT_EQ(records[0].stamp, 1);
  EXPECT_DOUBLE_EQ(records[0].angle, M_PI);
  EXPECT_DOUBLE_EQ(records[0].rate, -M_PI / 2);
}

TEST(GyroLogsTest, RateFromAngleIsTheCentralDifference) {
  // Angle t^2 (rad, t in s) at uneven spacing: the central difference of a parabola is exact at
  // the midpoint of its neighbours, the ends are one-sided.
  const auto records = readTurntable("stamp,angle\n0.0,0\n1.0,1\n3.0,9\n4.0,16\n");
  ASSERT_EQ(records.size(), 4u);
  EXPECT_DOUBLE_EQ(records[0].rate, 1.0);  // (1 - 0) / 1
  EXPECT_DOUBLE_EQ(records[1].rate, 3.0);  // (9 - 0) / 3
  EXPECT_DOUBLE_EQ(records[2].rate, 5.0);  // (16 - 1) / 3
  EXPECT_DOUBLE_EQ(records[3].rate, 7.0);  // (16 - 9) / 1
  EXPECT_EQ(records[2].angle, 9.0);
  // A derived rate needs a neighbour; an angle-only log also needs every angle.
  EXPECT_THROW(readTurntable("stamp,angle\n0.0,0\n"), std::runtime_error);
  EXPECT_THROW(readTurntable("stamp,angle\n0.0,0\n1.0,nan\n"), BadRowError);
}

TEST(GyroLogsTest, ADerivedRateThatOverflowsIsABadRecordOfItsOwnLine) {
  // Finite angles 1e308 and -1e308 two records apart: their difference is no double. The rate is
  // that of the record between them (line 4), which is named although the reader is a line ahead.
  const std::string log = "stamp,angle\n0,0\n1.0,1e308\n2.0,2\n3.0,-1e308\n4.0,4\n";
  try {
    readTurntable(log);
    FAIL() << "an infinite derived rate was accepted";
  } catch (const BadRowError& e) {
    EXPECT_EQ(e.reason, BadRowReason::kNotANumber);
    EXPECT_EQ(std::string(e.what()),
              "tt.csv:4: NaN or infinity not allowed: rate derived from the angle is -inf: the central difference "
              "of lines 3 and 5 overflows (angles 1e+308 and -1e+308 rad, 2 s apart)");
  }
  // Skipped and counted: the record whose rate overflowed is not written, but its angle, good in
  // itself, stays the neighbour of the next record, so no kept record's rate changes by the skip.
  // An unreadable record (line 7) is no neighbour: the rate of line 6 spans lines 5 to 8.
  LogSettings settings;
  settings.skip_bad_rows = true;
  BadRowCounts skipped;
  const auto records = readTurntable(log + "5.0,x\n6.0,10\n", settings, &skipped);
  ASSERT_EQ(records.size(), 5u);
  EXPECT_EQ(skipped.summary(), "2 (unreadable number 1, NaN or infinity not allowed 1)");
  EXPECT_EQ(records[0].stamp, 0);
  EXPECT_DOUBLE_EQ(records[0].rate, 1e308);              // (1e308 - 0) / 1, one-sided
  EXPECT_DOUBLE_EQ(records[1].rate, 1.0);                // (2 - 0) / 2
  EXPECT_EQ(records[2].stamp, 3000000000LL);             // 2.0 s is the one skipped
  EXPECT_DOUBLE_EQ(records[2].rate, (4.0 - 2.0) / 2.0);  // from the skipped record's angle: not (4 - 1e308) / 3
  EXPECT_DOUBLE_EQ(records[3].rate, (10.0 + 1e308) / 3.0);
  EXPECT_EQ(records[4].stamp, 6000000000LL);
  EXPECT_DOUBLE_EQ(records[4].rate, (10.0 - 4.0) / 2.0);
}

TEST(GyroLogsTest, RateOnlyLeavesTheAngleNaN) {
  const auto records = readTurntable("stamp,rate\n1.0,0.05\n2.0,0.05\n");
  ASSERT_EQ(records.size(), 2u);
  EXPECT_TRUE(std::isnan(records[0].angle));
  EXPECT_EQ(records[1].rate, 0.05);
  EXPECT_THROW(readTurntable("stamp,rate\n1.0,nan\n"), BadRowError);
  EXPECT_THROW(readTurntable("stamp,speed\n1.0,0\n"), std::runtime_error);
}

}  // namespace
}  // namespace csv
}  // namespace hrg_gyro

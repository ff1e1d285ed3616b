#include "csv_reader.h"

#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <sstream>
#include <vector>

namespace hrg_gyro {
namespace csv {
namespace {

TEST(CsvReaderTest, StampsInTheThreeFormatsAreExactNanoseconds) {
  // 1700000000.123456789 s is not representable as a double: the reader never goes through one.
  EXPECT_EQ(parseStamp("1700000000.123456789", StampFormat::kAuto), 1700000000123456789LL);
  EXPECT_EQ(parseStamp("1700000000.123456789", StampFormat::kSeconds), 1700000000123456789LL);
  EXPECT_EQ(parseStamp("1700000000123456789", StampFormat::kAuto), 1700000000123456789LL);
  EXPECT_EQ(parseStamp("1700000000123456789", StampFormat::kNanoseconds), 1700000000123456789LL);
  EXPECT_EQ(parseStamp("12", StampFormat::kSeconds), 12000000000LL);
  EXPECT_EQ(parseStamp("12.", StampFormat::kSeconds), 12000000000LL);
  EXPECT_EQ(parseStamp("0.5", StampFormat::kAuto), 500000000LL);
  // Beyond the 9th decimal: rounded to the nearest nanosecond, carrying into the seconds.
  EXPECT_EQ(parseStamp("1.0000000004", StampFormat::kSeconds), 1000000000LL);
  EXPECT_EQ(parseStamp("1.0000000005", StampFormat::kSeconds), 1000000001LL);
  EXPECT_EQ(parseStamp("1.9999999999", StampFormat::kSeconds), 2000000000LL);
  // 2026-11-23T10:00:00Z is 1795428000 s after the epoch.
  EXPECT_EQ(parseStamp("2026-11-23T10:00:00.123456789Z", StampFormat::kAuto), 1795428000123456789LL);
  EXPECT_EQ(parseStamp("2026-11-23T11:00:00.123456789+01:00", StampFormat::kIso8601), 1795428000123456789LL);
  EXPECT_EQ(parseStamp("2026-11-23T04:30:00.5-0530", StampFormat::kIso8601), 1795428000500000000LL);
  EXPECT_EQ(parseStamp("1970-01-01T00:00:00Z", StampFormat::kIso8601), 0);
  EXPECT_EQ(parseStamp("2024-02-29T00:00:00Z", StampFormat::kIso8601), 1709164800000000000LL);
}

TEST(CsvReaderTest, BadStampsAreRefusedWithTheReason) {
  auto why = [](const char* text, StampFormat format) -> std::string {
    try {
      parseStamp(text, format);
    } catch (const FieldError& e) {
      return e.what();
    }
    return "accepted";
  };
  EXPECT_NE(why("2026-11-23T10:00:00", StampFormat::kAuto).find("no zone"), std::string::npos);
  EXPECT_NE(why("2026-02-29T10:00:00Z", StampFormat::kAuto).find("day out of range"), std::string::npos);
  EXPECT_NE(why("2026-11-23T10:00:00Zx", StampFormat::kAuto).find("trailing"), std::string::npos);
  EXPECT_NE(why("-1.5", StampFormat::kAuto).find("negative"), std::string::npos);
  EXPECT_NE(why("1.5e3", StampFormat::kAuto).find("plain decimal"), std::string::npos);
  EXPECT_NE(why("12.5", StampFormat::kNanoseconds).find("whole number"), std::string::npos);
  EXPECT_NE(why("99999999999999999999", StampFormat::kNanoseconds).find("out of range"), std::string::npos);
  EXPECT_NE(why("9999999999999.0", StampFormat::kSeconds).find("out of range"), std::string::npos);
  EXPECT_NE(why("", StampFormat::kAuto).find("empty"), std::string::npos);
  // Readable numbers outside what a stamp can be are told apart from unreadable ones.
  for (const char* out_of_range :
       {"-1.5", "99999999999999999999", "9999999999999.0", "1969-12-31T23:59:59Z", "9999-12-31T23:59:59Z"}) {
    EXPECT_THROW(parseStamp(out_of_range, StampFormat::kAuto), OutOfRangeError) << out_of_range;
  }
  for (const char* unreadable : {"abc", "1.5e3", "2026-11-23T10:00:00"}) {
    try {
      parseStamp(unreadable, StampFormat::kAuto);
      ADD_FAILURE() << unreadable << " was read";
    } catch (const OutOfRangeError&) {
      ADD_FAILURE() << unreadable << " is unreadable, not out of range";
    } catch (const FieldError&) {
    }
  }
}

TEST(CsvReaderTest, NumbersAreReadWholeOrRefused) {
  EXPECT_EQ(parseNumber("1.5"), 1.5);
  EXPECT_EQ(parseNumber(" -2.5e-3 "), -2.5e-3);
  EXPECT_EQ(parseNumber("+3"), 3.0);
  EXPECT_EQ(parseNumber("0.1"), 0.1);  // the same double as the compiler's, bit for bit
  EXPECT_TRUE(std::isnan(parseNumber("nan")));
  for (const char* bad : {"1.5abc", "1,5", "", "  ", "0x10", "abc", "1e999"}) {
    EXPECT_THROW(parseNumber(bad), FieldError) << bad;
  }
}

TEST(CsvReaderTest, DelimiterCommentsQuotesAndLineNumbers) {
  std::istringstream in(
      "# bench log\n"
      "\n"
      "\"Stamp\";Ac_V;Bc\r\n"
      "# a comment between records\n"
      "1.0; 0.5 ;\"0.25\"\r\n"
      "2.0;;x\n");
  CsvReader reader(in, "bench.csv");
  EXPECT_EQ(reader.delimiter(), ';');
  ASSERT_EQ(reader.header().size(), 3u);
  EXPECT_EQ(reader.header()[0], "Stamp");
  EXPECT_EQ(reader.line(), 3u);
  ASSERT_TRUE(reader.next());
  EXPECT_EQ(reader.line(), 5u);
  ASSERT_EQ(reader.fields().size(), 3u);
  EXPECT_EQ(reader.fields()[1], "0.5");
  EXPECT_EQ(reader.fields()[2], "0.25");
  ASSERT_TRUE(reader.next());
  EXPECT_EQ(reader.line(), 6u);
  EXPECT_EQ(reader.fields()[1], "");
  EXPECT_FALSE(reader.next());
}

TEST(CsvReaderTest, DelimiterFromTheHeaderOrGiven) {
  std::istringstream tabs("stamp\tac\n1\t2\n");
  EXPECT_EQ(CsvReader(tabs, "t").delimiter(), '\t');
  std::istringstream mixed("stamp;a,c\n");
  EXPECT_THROW(CsvReader(mixed, "m"), std::runtime_error);
  std::istringstream one("stamp\n");
  EXPECT_THROW(CsvReader(one, "o"), std::runtime_error);
  std::istringstream given("stamp;a,c\n1;2,5\n");
  CsvReader reader(given, "g", ';');
  ASSERT_TRUE(reader.next());
  EXPECT_EQ(reader.fields()[1], "2,5");  // and parseNumber refuses it: never read as 2
  EXPECT_THROW(parseNumber(reader.fields()[1]), FieldError);
  std::istringstream empty("# only a comment\n");
  EXPECT_THROW(CsvReader(empty, "e"), std::runtime_error);
}

TEST(CsvReaderTest, ColumnsByNameInAnyCaseOrByIndex) {
  std::istringstream in("Stamp,AC_V,bc,ac_v2\n");
  CsvReader reader(in, "c");
  EXPECT_EQ(reader.column("stamp"), 0);
  EXPECT_EQ(reader.column("ac_v"), 1);
  EXPECT_EQ(reader.column("#3"), 2);
  EXPECT_EQ(reader.column("missing"), -1);
  EXPECT_THROW(reader.column("#0"), std::runtime_error);
  EXPECT_THROW(reader.column("#5"), std::runtime_error);
  EXPECT_THROW(reader.column("#x"), std::runtime_error);
  std::istringstream twice("stamp,a,A\n");
  EXPECT_THROW(CsvReader(twice, "t").column("a"), std::runtime_error);
}

TEST(CsvReaderTest, ByteOrderMarkIsIgnored) {
  std::istringstream in("\xEF\xBB\xBFstamp,ac\n1,2\n");
  CsvReader reader(in, "bom");
  EXPECT_EQ(reader.header()[0], "stamp");
  EXPECT_EQ(reader.column("stamp"), 0);
}

TEST(CsvReaderTest, WithoutHeaderTheFirstLineIsARecordAndColumnsGoByIndex) {
  std::istringstream in("# no header\n1.0;2;3\n2.0;4;5\n");
  CsvReader reader(in, "raw", 0, false);
  EXPECT_EQ(reader.delimiter(), ';');
  EXPECT_EQ(reader.header().size(), 3u);
  EXPECT_EQ(reader.column("stamp"), -1);
  EXPECT_EQ(reader.column("#2"), 1);
  ASSERT_TRUE(reader.next());
  EXPECT_EQ(reader.line(), 2u);
  EXPECT_EQ(reader.fields()[0], "1.0");
  ASSERT_TRUE(reader.next());
  EXPECT_EQ(reader.fields()[2], "5");
  EXPECT_FALSE(reader.next());
}

TEST(CsvReaderTest, LayoutOfAnImuLogCommentsBlanksAndPreamble) {
  // A PSINS-like log: '%' comments, a blank line, two header lines of numbers, rows apart by blanks.
  std::istringstream in(
      "% SIMU log\n"
      "\n"
      "34.2 108.9  380\n"
      "% a comment among the header lines\n"
      "0.1 0.1 0.1 \n"
      " 1  -2\t3 \r\n"
      "# not a comment here\n");
  TextLayout layout;
  layout.delimiter = kWhitespace;
  layout.comment = "%";
  layout.preamble_lines = 2;
  layout.has_header = false;
  CsvReader reader(in, "simu.imu", layout);
  ASSERT_EQ(reader.preamble().size(), 2u);
  EXPECT_EQ(reader.preamble()[0].number, 3u);
  EXPECT_EQ(reader.preamble()[0].text, "34.2 108.9  380");
  EXPECT_EQ(reader.preamble()[1].number, 5u);
  EXPECT_EQ(reader.header().size(), 3u);
  ASSERT_TRUE(reader.next());
  EXPECT_EQ(reader.line(), 6u);
  EXPECT_EQ(reader.fields(), (std::vector<std::string_view>{"1", "-2", "3"}));
  ASSERT_TRUE(reader.next());  // '#' is no comment prefix in this layout
  EXPECT_EQ(reader.fields(), (std::vector<std::string_view>{"#", "not", "a", "comment", "here"}));
  EXPECT_FALSE(reader.next());
  // A file that ends within its preamble says how many header lines it had.
  std::istringstream short_file("% c\n1 2\n");
  try {
    CsvReader(short_file, "short.imu", layout);
    FAIL() << "a file of one header line was accepted";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("short.imu: 1 of its 2 header lines"), std::string::npos) << e.what();
  }
  // Auto: the one of , ; tab the first line holds, blanks when it holds none (if the layout says so).
  TextLayout automatic;
  automatic.has_header = false;
  automatic.blanks_when_no_delimiter = true;
  std::istringstream blanks("1 2  3\n");
  EXPECT_EQ(CsvReader(blanks, "b", automatic).delimiter(), kWhitespace);
  std::istringstream commas("1, 2, 3\n");
  EXPECT_EQ(CsvReader(commas, "c", automatic).delimiter(), ',');
  std::istringstream several("1,2;3\n");
  EXPECT_THROW(CsvReader(several, "s", automatic), std::runtime_error);
  automatic.blanks_when_no_delimiter = false;  // the bench logs' rule: refused
  std::istringstream refused("1 2 3\n");
  EXPECT_THROW(CsvReader(refused, "r", automatic), std::runtime_error);
  EXPECT_EQ(secondsText(-1500000000), "-1.500000000");
}

TEST(CsvReaderTest, MessagesQuoteAnExcerptOfAField) {
  EXPECT_EQ(excerpt("1.5abc"), "1.5abc");
  EXPECT_EQ(excerpt(std::string(kQuotedBytes, 'x')), std::string(kQuotedBytes, 'x'));
  EXPECT_EQ(excerpt(std::string(10000000, 'x')), std::string(kQuotedBytes, 'x') + "... (10000000 bytes)");
  // Never half a UTF-8 character ("\xC3\xA9" is one), control characters escaped.
  EXPECT_EQ(excerpt(std::string(kQuotedBytes - 1, 'x') + "\xC3\xA9" + std::string(100, 'y')),
            std::string(kQuotedBytes - 1, 'x') + "... (165 bytes)");
  EXPECT_EQ(excerpt("a\x1B[2Jb\n"), "a\\x1B[2Jb\\x0A");
  // Through the parsers: a 10 MB field is refused in a message of a few dozen bytes.
  const std::string huge = "1" + std::string(10000000, '5') + "x";
  for (const auto& refuse :
       std::vector<std::function<void()>>{[&] { parseNumber(huge); }, [&] { parseStamp(huge, StampFormat::kSeconds); },
                                          [&] { parseStamp(huge, StampFormat::kIso8601); }}) {
    try {
      refuse();
      ADD_FAILURE() << "accepted";
    } catch (const FieldError& e) {
      EXPECT_LT(std::string(e.what()).size(), 200u) << std::string(e.what()).substr(0, 200);
      EXPECT_NE(std::string(e.what()).find("... (10000002 bytes)"), std::string::npos)
          << std::string(e.what()).substr(0, 200);
    }
  }
}

TEST(CsvReaderTest, ALineLongerThanTheLimitIsRefusedAndReadPast) {
  const std::string at_limit(kMaxLineBytes - 2, '1');  // "1.<digits>": a field of exactly the limit
  const std::string over(kMaxLineBytes + 1, '2'), far_over(kMaxLineBytes + 1000, '2');
  std::istringstream in("stamp\n1." + at_limit + "\n" + "1." + at_limit + "\r\n" + far_over + "\n3\n" + over);
  CsvReader reader(in, "long.csv", ',');
  ASSERT_TRUE(reader.next());
  EXPECT_EQ(reader.fields()[0].size(), kMaxLineBytes);
  ASSERT_TRUE(reader.next());  // the limit does not count the "\r" of a "\r\n" line end
  EXPECT_EQ(reader.line(), 3u);
  EXPECT_EQ(reader.fields()[0].size(), kMaxLineBytes);
  try {
    reader.next();
    FAIL() << "a line of the limit and one byte more was read";
  } catch (const LineTooLongError& e) {
    EXPECT_EQ(reader.line(), 4u);
    EXPECT_EQ(std::string(e.what()), "more than 1048576 bytes (1 MiB), the limit of a line");
  }
  ASSERT_TRUE(reader.next());  // the rest of the long line was read past
  EXPECT_EQ(reader.line(), 5u);
  EXPECT_EQ(reader.fields()[0], "3");
  EXPECT_THROW(reader.next(), LineTooLongError);  // the last line, without a line end
  EXPECT_EQ(reader.line(), 6u);
  EXPECT_FALSE(reader.next());
  EXPECT_EQ(reader.bytesRead(), in.str().size());
}

TEST(CsvReaderTest, AFileWithoutLineEndsIsRefusedAtItsHeader) {
  std::istringstream in(std::string(3 * kMaxLineBytes, 'x'));
  try {
    CsvReader reader(in, "binary.dat");
    FAIL() << "a header longer than the limit was accepted";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("binary.dat:1: line too long: more than 1048576 bytes"), std::string::npos)
        << e.what();
  }
  // Never more of it read than the limit and the one byte that tells it is longer.
  EXPECT_EQ(in.tellg(), static_cast<std::streamoff>(kMaxLineBytes + 1));
}

}  // namespace
}  // namespace csv
}  // namespace hrg_gyro

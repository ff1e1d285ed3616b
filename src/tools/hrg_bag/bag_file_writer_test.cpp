#include "bag_file_writer.h"

#include <gtest/gtest.h>
#include <rosbag/bag.h>
#include <rosbag/view.h>
#include <std_msgs/Float64.h>
#include <std_msgs/String.h>
#include <unistd.h>

#include <cstdio>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

namespace hrg_gyro {
namespace bag_tools {
namespace {

typedef BagFileWriter::Compression Compression;

std::string temporaryPath(const std::string& name) {
  return "/tmp/hrg_gyro_bag_writer_test_" + std::to_string(::getpid()) + "_" + name + ".bag";
}

std::string contents(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

// A session written in chunks of about 2 KiB, so that it takes a hundred chunks and the writer
// recycles them: /value on every message, /note only at the start and the end, so most chunks
// carry one connection and reuse a chunk whose index also lists the other.
void writeSession(const std::string& path, Compression compression) {
  BagFileWriter writer(path, compression, 2048);
  for (int i = 0; i < 8000; ++i) {
    const ros::Time t(100, 0);
    const ros::Time stamp = t + ros::Duration(1e-3 * i);
    std_msgs::Float64 value;
    value.data = 0.5 * i;
    writer.write("/value", stamp, value);
    if (i < 50 || i >= 7950) {
      std_msgs::String note;
      note.data = "note " + std::to_string(i);
      writer.write("/note", stamp, note);
    }
  }
  writer.close();
}

class BagFileWriterTest : public ::testing::TestWithParam<Compression> {};

TEST_P(BagFileWriterTest, RosbagReadsBackEveryMessageOfAManyChunkSession) {
  const std::string path = temporaryPath("read_back");
  writeSession(path, GetParam());
  rosbag::Bag bag(path, rosbag::bagmode::Read);
  int values = 0, notes = 0;
  for (const rosbag::MessageInstance& m : rosbag::View(bag)) {
    if (m.getTopic() == "/value") {
      const auto value = m.instantiate<std_msgs::Float64>();
      ASSERT_TRUE(value != nullptr);
      EXPECT_EQ(value->data, 0.5 * values);
      EXPECT_EQ(m.getTime(), ros::Time(100, 0) + ros::Duration(1e-3 * values));
      ++values;
    } else {
      ASSERT_EQ(m.getTopic(), "/note");
      const auto note = m.instantiate<std_msgs::String>();
      ASSERT_TRUE(note != nullptr);
      const int i = notes < 50 ? notes : 7900 + notes;
      EXPECT_EQ(note->data, "note " + std::to_string(i));
      ++notes;
    }
  }
  EXPECT_EQ(values, 8000);
  EXPECT_EQ(notes, 100);
  // The per-topic index (what rosbag play and rosbag filter use) finds each topic's messages.
  EXPECT_EQ(rosbag::View(bag, rosbag::TopicQuery("/note")).size(), 100u);
  EXPECT_EQ(rosbag::View(bag, rosbag::TopicQuery("/value")).size(), 8000u);
  bag.close();
  std::remove(path.c_str());
}

TEST_P(BagFileWriterTest, TheSameSessionGivesTheSameBytes) {
  // Recycled chunks keep their index lists from an earlier chunk, and which spare a chunk reuses
  // depends on the background thread's timing: the file must not.
  const std::string first = temporaryPath("first"), second = temporaryPath("second");
  writeSession(first, GetParam());
  writeSession(second, GetParam());
  const std::string a = contents(first);
  EXPECT_GT(a.size(), 100000u);
  EXPECT_TRUE(a == contents(second));
  std::remove(first.c_str());
  std::remove(second.c_str());
}

TEST(BagFileWriterMemoryTest, NoMoreChunksThanTheBoundHoweverFarTheWriterThreadFallsBehind) {
  // bzip2 on 32 KiB chunks: compressing one takes some milliseconds, tens of times longer than
  // filling it, so the filling thread is ahead of the writing one, as on a loaded machine. It must
  // then wait rather than make more chunks.
  const std::string path = temporaryPath("bounded");
  BagFileWriter writer(path, Compression::kBz2, 32 << 10);
  for (int i = 0; i < 40000; ++i) {
    std_msgs::Float64 value;
    value.data = i;
    writer.write("/value", ros::Time(100, 0) + ros::Duration(1e-3 * i), value);
    ASSERT_LE(writer.chunksAllocated(), BagFileWriter::kMaxChunksAlive) << "after message " << i;
  }
  writer.close();
  RecordProperty("chunks_allocated", static_cast<int>(writer.chunksAllocated()));
  rosbag::Bag bag(path, rosbag::bagmode::Read);
  EXPECT_EQ(rosbag::View(bag).size(), 40000u);
  bag.close();
  std::remove(path.c_str());
}

INSTANTIATE_TEST_SUITE_P(Compressions, BagFileWriterTest,
                         ::testing::Values(Compression::kNone, Compression::kLz4, Compression::kBz2));

}  // namespace
}  // namespace bag_tools
}  // namespace hrg_gyro

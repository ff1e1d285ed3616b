#include "hrg_gyro/core/alignment/gyrocompass_records.h"

#include <gtest/gtest.h>

namespace hrg_gyro {
namespace core {
namespace {

GyrocompassRecords windowWithRecords() {
  GyrocompassRecords w;
  w.stream_count = 2;
  w.started = true;
  w.start = 1000000000;
  w.end = 3000000000;
  for (std::size_t i = 0; i < 2; ++i) {
    w.streams[i].channels = 1;
    w.streams[i].stamp = {w.start + 10000000};
    w.streams[i].dt = {0.01};
    w.streams[i].increment = {1e-7};
    w.streams[i].broken = {1};
  }
  w.streams[0].last = 1500000000;
  w.streams[1].last = 1700000000;
  w.streams[2].last = 2900000000;  // beyond stream_count: not one of this window's streams
  w.indexer.push_back(IndexerRecord{w.start, 0.5, 0.0});
  w.accelerometer.push_back(AccelerometerRecord{w.start, Eigen::Vector3d(0.0, 0.0, 9.8)});
  w.precession[1].push_back(PrecessionStateRecord{w.start, 1.0, 0.0});
  return w;
}

TEST(GyrocompassRecords, SecondsAndLastSampleOfTheWindowsStreams) {
  const GyrocompassRecords w = windowWithRecords();
  EXPECT_DOUBLE_EQ(w.seconds(w.start + 2500000000), 2.5);
  EXPECT_EQ(w.lastSample(), 1700000000);
}

TEST(GyrocompassRecords, ClearWindowDropsEveryRecordAndKeepsTheLayout) {
  GyrocompassRecords w = windowWithRecords();
  w.triad.bias = Eigen::Vector3d(1e-6, 0.0, 0.0);
  w.clearWindow();
  EXPECT_FALSE(w.started);
  EXPECT_EQ(w.lastSample(), 0);
  for (const GyroStreamRecords& s : w.streams) {
    EXPECT_TRUE(s.stamp.empty() && s.dt.empty() && s.increment.empty() && s.broken.empty());
    EXPECT_EQ(s.last, 0);
  }
  EXPECT_EQ(w.streams[0].channels, 1u);  // the mode's layout stays
  EXPECT_EQ(w.stream_count, 2u);
  EXPECT_TRUE(w.indexer.empty() && w.accelerometer.empty() && w.precession[1].empty());
  EXPECT_EQ(w.triad.bias.x(), 1e-6);
}

}  // namespace
}  // namespace core
}  // namespace hrg_gyro

#include "hrg_gyro/core/alignment/gyrocompass_records.h"

#include <algorithm>

namespace hrg_gyro {
namespace core {

void GyroStreamRecords::clear() {
  stamp.clear();
  dt.clear();
  increment.clear();
  broken.clear();
  last = 0;
}

Nanoseconds GyrocompassRecords::lastSample() const {
  Nanoseconds newest = 0;
  for (std::size_t i = 0; i < stream_count; ++i) newest = std::max(newest, streams[i].last);
  return newest;
}

void GyrocompassRecords::clearWindow() {
  for (GyroStreamRecords& s : streams) s.clear();
  indexer.clear();
  accelerometer.clear();
  for (auto& track : precession) track.clear();
  started = false;
}

}  // namespace core
}  // namespace hrg_gyro

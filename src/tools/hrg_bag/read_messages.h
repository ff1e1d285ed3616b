// The hrg_bag subcommands' loop over a bag's messages: each message of a view in record order, the
// progress on stderr as it goes, and a read error of the bag (a truncated or corrupt chunk) as the
// UsageError every subcommand reports for it.
#pragma once

#include <rosbag/view.h>

#include <cstdint>
#include <string>

#include "bag_tools.h"

namespace hrg_gyro {
namespace bag_tools {

/// Calls `each(message)` (a rosbag::MessageInstance) for every message of `view`, updating
/// `progress` by the messages read; returns how many were read. The caller finishes the progress.
template <class Each>
std::uint64_t readMessages(rosbag::View& view, Progress& progress, Each&& each) {
  std::uint64_t n = 0;
  try {
    for (const rosbag::MessageInstance& m : view) {
      ++n;
      progress.update(n, n);
      each(m);
    }
  } catch (const rosbag::BagException& e) {
    throw UsageError(std::string("bag read error (truncated?): ") + e.what());
  }
  return n;
}

}  // namespace bag_tools
}  // namespace hrg_gyro

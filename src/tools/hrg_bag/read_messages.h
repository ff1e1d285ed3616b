// The hrg_bag subcommands' one loop over a bag's messages: each message of a view in record order,
// the progress on stderr as it goes, and a read error of the bag (a truncated or corrupt chunk, a
// record shorter than its type) as the UsageError every subcommand reports for it
// (rethrowBagReadError). Every subcommand reads its bag through it, so they all stop, count and fail
// alike.
#pragma once

#include <rosbag/view.h>

#include <cstdint>
#include <type_traits>

#include "bag_tools.h"

namespace hrg_gyro {
namespace bag_tools {

/// Calls `each(message)` (a rosbag::MessageInstance) for every message of `view`, until an `each`
/// that returns bool returns false (one returning void reads them all); updates `progress` (may be
/// null) every 4096 messages. Returns how many messages were read. The caller finishes the progress.
template <class Each>
std::uint64_t readMessages(rosbag::View& view, Progress* progress, Each&& each) {
  std::uint64_t n = 0;
  try {
    for (const rosbag::MessageInstance& m : view) {
      ++n;
      bool go_on = true;
      if constexpr (std::is_void<decltype(each(m))>::value) {
        each(m);
      } else {
        go_on = each(m);
      }
      if (progress && n % 4096 == 0) progress->update(static_cast<double>(n), n);
      if (!go_on) break;
    }
  } catch (...) {
    rethrowBagReadError(n);
  }
  return n;
}

template <class Each>
std::uint64_t readMessages(rosbag::View& view, Progress& progress, Each&& each) {
  return readMessages(view, &progress, std::forward<Each>(each));
}

}  // namespace bag_tools
}  // namespace hrg_gyro

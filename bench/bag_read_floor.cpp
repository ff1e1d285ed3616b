// The floor of the offline path: a minimal program that only reads every ChannelAmplitudes message
// of a bag with the rosbag C++ API and reports messages/s. `hrg_bag process` cannot be faster than
// reading its input, so bench/run_benchmarks.py times it beside this floor on the same bag.
//   hrg_gyro_bag_read_floor BAG [MODE] [TOPIC]
// MODE (default reused):
//   view         iterate the rosbag::View only (index walk, no message data read): the cost of the
//                View's per-message path alone;
//   instantiate  MessageInstance::instantiate, a new message per sample (the rosbag idiom);
//   reused       the serialised bytes deserialised into one reused message (what hrg_bag does).
// Prints one line: "floor MODE: N messages in T s (R messages/s)", T the read loop alone, opening
// the bag included (the whole process is timed by the caller).
#include <rosbag/bag.h>
#include <rosbag/view.h>

#include <chrono>
#include <cstdio>
#include <cstring>
#include <exception>
#include <string>

#include "../src/tools/hrg_bag/reused_message_reader.h"
#include "hrg_gyro/ChannelAmplitudes.h"

namespace {

double seconds() { return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count(); }

int usage() {
  std::fprintf(stderr, "usage: hrg_gyro_bag_read_floor BAG [view|instantiate|reused] [TOPIC (default /channels)]\n");
  return 2;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 2 || argc > 4) return usage();
  const std::string path = argv[1], mode = argc > 2 ? argv[2] : "reused", topic = argc > 3 ? argv[3] : "/channels";
  if (mode != "view" && mode != "instantiate" && mode != "reused") return usage();
  try {
    const double start = seconds();
    rosbag::Bag bag(path, rosbag::bagmode::Read);
    rosbag::View view(bag, rosbag::TopicQuery(topic));
    std::uint64_t n = 0;
    double checksum = 0.0;  // read back so that nothing is optimised away
    if (mode == "view") {
      for (const rosbag::MessageInstance& m : view) {
        checksum += m.getTime().nsec;
        ++n;
      }
    } else if (mode == "instantiate") {
      for (const rosbag::MessageInstance& m : view) {
        const hrg_gyro::ChannelAmplitudes::ConstPtr msg = m.instantiate<hrg_gyro::ChannelAmplitudes>();
        if (!msg) continue;
        checksum += msg->c_in;
        ++n;
      }
    } else {
      hrg_gyro::bag_tools::ReusedMessageReader<hrg_gyro::ChannelAmplitudes> reader;
      hrg_gyro::ChannelAmplitudes msg;
      for (const rosbag::MessageInstance& m : view) {
        if (!reader.read(m, &msg)) continue;
        checksum += msg.c_in;
        ++n;
      }
    }
    const double elapsed = seconds() - start;
    if (n == 0) {
      std::fprintf(stderr, "bag_read_floor: no %s message on %s in %s\n", "hrg_gyro/ChannelAmplitudes", topic.c_str(),
                   path.c_str());
      return 1;
    }
    std::printf("floor %s: %lu messages in %.3f s (%.0f messages/s) checksum %.6g\n", mode.c_str(),
                static_cast<unsigned long>(n), elapsed, n / elapsed, checksum);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "bag_read_floor: %s: %s\n", path.c_str(), e.what());
    return 2;
  }
  return 0;
}

// hrg_bag simulate: the simulator without a master, straight into a bag, as fast as it runs.
#include <iostream>

#include "bag_tools.h"
#include "hrg_gyro/core/gyro_simulator.h"
#include "hrg_gyro/ros/conversions.h"

namespace hrg_gyro {

int simulateCommand(int argc, char** argv) {
  using namespace bag_tools;
  const Args args(argc, argv, {"scenario", "out", "seed", "frame-id", "compression"}, {"no-truth"});
  if (args.help()) {
    std::cout << "usage: hrg_bag simulate --scenario FILE.yaml --out OUT.bag [--seed N] [--frame-id ID] [--no-truth]\n"
                 "       [--compression lz4|bz2|none]\n"
                 "Runs the simulated gyro of a scenario (the driver_sim parameters) and writes /channels,\n"
                 "/turntable/state and /truth (unless --no-truth), stamped and recorded at simulated time. Chunks are LZ4-compressed\n"
                 "by default (several times faster to read back; every rosbag reader handles it).\n";
    return 0;
  }
  core::SimulationConfig config =
      core::SimulationConfig::load(args.require("scenario"), core::nodeOnlyScenarioKeys());
  if (args.has("seed")) {
    const double seed = args.getDouble("seed", 0.0);
    if (seed < 0 || seed != std::floor(seed)) throw UsageError("--seed must be a non-negative integer");
    config.seed = static_cast<std::uint64_t>(seed);
  }
  const std::string frame = args.get("frame-id", "gyro_link");
  const bool truth = !args.flag("no-truth");
  const std::unique_ptr<rosbag::Bag> out = createBag(args.require("out"), args);
  rosbag::Bag& bag = *out;
  core::GyroSimulator sim(config);
  Progress progress("simulate", sim.duration());
  core::SimulationSample s;
  std::uint32_t seq = 0;
  while (sim.next(&s)) {
    const ros::Time stamp = toRosTime(s.stamp);
    const ChannelAmplitudes ch = toChannelsMessage(s, stamp, seq++, frame);
    bag.write("/channels", stamp, ch);
    bag.write("/turntable/state", stamp, toTurntableMessage(s, ch.header));
    if (truth) bag.write("/truth", stamp, toTruthMessage(s, ch.header));
    progress.update(sim.elapsed(), seq);
  }
  bag.close();
  progress.finish(seq);
  std::cerr << "simulate: " << sim.elapsed() << " s of session written to " << args.get("out") << "\n";
  return 0;
}

}  // namespace hrg_gyro

// hrg_bag process: the processor offline. The same core::GyroProcessor and the same message
// conversions as the node, so the output is bit for bit the node's on the same input.
#include <cstdio>
#include <fstream>
#include <iostream>
#include <memory>

#include "bag_tools.h"
#include "hrg_gyro/core/parameter_file.h"
#include "hrg_gyro/ros/conversions.h"

namespace hrg_gyro {
namespace {

const char* verdictName(const core::ProcessorResult& r) {
  switch (r.verdict) {
    case core::SampleVerdict::kAccepted: return "accepted";
    case core::SampleVerdict::kFirst: return "first";
    case core::SampleVerdict::kRejectedValue: return "rejected_value";
    case core::SampleVerdict::kRejectedStamp: return "rejected_stamp";
    case core::SampleVerdict::kDuplicate: return "duplicate";
    case core::SampleVerdict::kOutOfOrder: return "out_of_order";
    case core::SampleVerdict::kRejectedJump: return "rejected_jump";
  }
  return "unknown";
}

}  // namespace

int processCommand(int argc, char** argv) {
  using namespace bag_tools;
  std::vector<std::string> valued{"params", "out", "csv", "channels-topic", "frame-id"};
  valued.insert(valued.end(), kProcessorOptions.begin(), kProcessorOptions.end());
  const Args args(argc, argv, valued, {});
  if (args.help() || args.positional().size() != 1) {
    std::cout << "usage: hrg_bag process BAG --params P.yaml [--out OUT.bag] [--csv OUT.csv] [--channels-topic T]\n"
                 "       [--frame-id ID] [--max-gap S] [--backward-reset S] [--max-rate R] [--min-anisotropy X]\n"
                 "       [--min-amplitude A] [--max-amplitude A]\n"
                 "Runs the processor on the bag's channels: OUT.bag gets /wave and /output (recorded at the\n"
                 "input's record time), OUT.csv one row per input sample with its verdict (%.17g numbers).\n";
    return args.help() ? 0 : 2;
  }
  if (!args.has("out") && !args.has("csv")) throw UsageError("give --out and/or --csv");
  const auto params = std::make_shared<const core::GyroParameters>(core::loadParameterFile(args.require("params")));
  const std::unique_ptr<rosbag::Bag> in = openBag(args.positional()[0]);
  const GyroTopics topics = findTopics(*in, args, true, false);
  std::unique_ptr<rosbag::Bag> out;
  if (args.has("out")) {
    out = std::make_unique<rosbag::Bag>();
    try {
      out->open(args.get("out"), rosbag::bagmode::Write);
    } catch (const rosbag::BagException& e) {
      throw UsageError(std::string("cannot write ") + args.get("out") + ": " + e.what());
    }
  }
  std::ofstream csv;
  if (args.has("csv")) {
    csv.open(args.get("csv"));
    if (!csv) throw UsageError("cannot write " + args.get("csv"));
    csv << "stamp,seq,status,dt,dtheta,dalpha,dalpha_earth_fixed,alpha,rate,theta_mid,frequency,scale_factor,drift,"
           "rejected_before,flags,theta,amplitude,quadrature,phase\n";
  }
  const std::string frame = args.get("frame-id", "gyro_link");
  core::GyroProcessor processor(processorConfig(args), params);
  std::uint64_t outputs = 0;
  char line[1024];
  replayChannels(*in, topics.channels, processor, [&](const ChannelAmplitudes& msg, const core::ProcessorResult& r) {
    const WaveState wave = toWaveMessage(msg, r.wave, frame);
    const GyroOutput output = toOutputMessage(wave.header, r);
    if (out && r.has_wave) out->write("/wave", msg.header.stamp, wave);
    if (out && r.has_output) out->write("/output", msg.header.stamp, output);
    outputs += r.has_output ? 1 : 0;
    if (csv.is_open()) {
      if (r.has_output) {
        std::snprintf(line, sizeof line,
                      "%u.%09u,%u,%s,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%u,%u,%.17g,%.17g,"
                      "%.17g,%.17g\n",
                      msg.header.stamp.sec, msg.header.stamp.nsec, msg.header.seq, verdictName(r), output.dt,
                      output.dtheta, output.dalpha, output.dalpha_earth_fixed, output.alpha, output.rate,
                      output.theta_mid, output.frequency, output.scale_factor, output.drift, output.rejected_before,
                      output.flags, wave.theta, wave.amplitude, wave.quadrature, wave.phase);
      } else if (r.has_wave) {
        std::snprintf(line, sizeof line, "%u.%09u,%u,%s,,,,,%.17g,,,,,,,,%.17g,%.17g,%.17g,%.17g\n",
                      msg.header.stamp.sec, msg.header.stamp.nsec, msg.header.seq, verdictName(r), r.alpha,
                      wave.theta, wave.amplitude, wave.quadrature, wave.phase);
      } else {
        std::snprintf(line, sizeof line, "%u.%09u,%u,%s,,,,,,,,,,,,,,,,\n", msg.header.stamp.sec,
                      msg.header.stamp.nsec, msg.header.seq, verdictName(r));
      }
      csv << line;
    }
  }, "process");
  if (out) out->close();
  const core::ProcessorCounters& c = processor.counters();
  std::cerr << "process: " << c.received << " samples, " << outputs << " outputs, " << c.rejected()
            << " rejected, " << c.gaps << " gaps, " << c.resets << " resets\n";
  return 0;
}

}  // namespace hrg_gyro

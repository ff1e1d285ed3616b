// hrg_bag allan: overlapping Allan deviation of the compensated rate (IEEE 952 readings).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <memory>
#include <vector>

#include "bag_tools.h"
#include "hrg_gyro/core/allan_deviation.h"
#include "hrg_gyro/core/parameter_file.h"

namespace hrg_gyro {

int allanCommand(int argc, char** argv) {
  using namespace bag_tools;
  std::vector<std::string> valued{"params", "csv", "plot", "channels-topic"};
  valued.insert(valued.end(), kProcessorOptions.begin(), kProcessorOptions.end());
  const Args args(argc, argv, valued, {});
  if (args.help() || args.positional().size() != 1) {
    std::cout << "usage: hrg_bag allan BAG [--params P.yaml] [--csv OUT.csv] [--plot OUT.png]\n"
                 "Processes the bag's channels (with P.yaml, default the nominal model) and computes the\n"
                 "overlapping Allan deviation of the compensated rate from the integrated angle over its\n"
                 "longest continuous stretch (no gap or reset). Prints the readings: angle white noise Q\n"
                 "(slope -1), angle random walk N (slope -1/2, at tau = 1 s), bias instability B (flat\n"
                 "bottom / 0.664), each with the tau range it was read from, or 'not identified'.\n";
    return args.help() ? 0 : 2;
  }
  const auto params = std::make_shared<const core::GyroParameters>(
      args.has("params") ? core::loadParameterFile(args.get("params")) : core::GyroParameters());
  const std::unique_ptr<rosbag::Bag> bag = openBag(args.positional()[0]);
  const GyroTopics topics = findTopics(*bag, args, true, false);
  core::GyroProcessor processor(processorConfig(args), params);
  // Continuous stretches of the integrated angle; the longest one is analysed.
  std::vector<double> current, best, dts;
  replayChannels(*bag, topics.channels, processor, [&](const ChannelAmplitudes&, const core::ProcessorResult& r) {
    if (!r.has_output) return;
    if (r.flags & (core::kFlagGap | core::kFlagReset)) {
      if (current.size() > best.size()) best.swap(current);
      current.clear();
    }
    current.push_back(r.alpha);
    dts.push_back(r.increment.dt);
  }, "allan");
  if (current.size() > best.size()) best.swap(current);
  if (best.size() < 100) throw UsageError("fewer than 100 continuous samples: nothing to analyse");
  std::nth_element(dts.begin(), dts.begin() + dts.size() / 2, dts.end());
  const double tau0 = dts[dts.size() / 2];
  const core::AllanResult a = core::allanDeviation(best, tau0);
  constexpr double kDegPerHour = 180.0 / M_PI * 3600.0;
  std::printf("allan: %zu samples, tau0 %.6f s, %zu points from %.3g s to %.3g s\n", best.size(), tau0,
              a.curve.size(), a.curve.front().tau, a.curve.back().tau);
  auto reading = [](const char* name, const core::NoiseReading& r, double scale, const char* unit, double si_scale,
                    const char* si_unit) {
    if (!r.identified) {
      std::printf("  %-22s not identified (no range with that slope)\n", name);
    } else {
      std::printf("  %-22s %.4g %s (%.4g %s), from tau %.3g..%.3g s\n", name, r.value * si_scale, si_unit,
                  r.value * scale, unit, r.tau_min, r.tau_max);
    }
  };
  reading("angle white noise Q", a.angle_white_noise, 180.0 / M_PI * 3600.0, "arcsec", 1.0, "rad");
  reading("angle random walk N", a.angle_random_walk, 180.0 / M_PI * 60.0, "deg/sqrt(h)", 1.0, "rad/sqrt(s)");
  reading("bias instability B", a.bias_instability, kDegPerHour, "deg/h", 1.0, "rad/s");
  if (args.has("csv")) {
    std::ofstream csv(args.get("csv"));
    if (!csv) throw UsageError("cannot write " + args.get("csv"));
    csv << "tau,deviation,error,clusters\n";
    char line[128];
    for (const core::AllanPoint& p : a.curve) {
      std::snprintf(line, sizeof line, "%.9g,%.9g,%.9g,%lu\n", p.tau, p.deviation, p.error,
                    static_cast<unsigned long>(p.clusters));
      csv << line;
    }
  }
  if (args.has("plot")) {
    if (!args.has("csv")) throw UsageError("--plot needs --csv (the plot is drawn from the CSV)");
    if (runPlotter({"allan", args.get("csv"), args.get("plot")}) != 0) {
      std::cerr << "allan: plotting failed (is python3-matplotlib installed?)\n";
    }
  }
  return 0;
}

}  // namespace hrg_gyro

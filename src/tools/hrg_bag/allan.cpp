// hrg_bag allan: overlapping Allan deviation of the compensated rate (IEEE 952 readings).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <memory>
#include <vector>

#include "../cli_checks.h"
#include "bag_tools.h"
#include "hrg_gyro/core/estimation/allan_deviation.h"
#include "hrg_gyro/core/estimation/allan_readings_file.h"
#include "hrg_gyro/core/model/parameter_file.h"

namespace hrg_gyro {

namespace {

struct AllanOptions {
  std::string bag, params, csv, plot, yaml;
  double from = -INFINITY, to = INFINITY;  ///< s, channel stamps analysed (the processor sees them all)
  bag_tools::GyroTopics topics;
  core::ProcessorConfig processor;
};

int runAllan(const AllanOptions& o) {
  using namespace bag_tools;
  checkProcessorConfig(o.processor);
  checkOutputPaths({o.bag, o.params}, {o.csv, o.plot, o.yaml});
  if (!(o.from < o.to)) throw UsageError("--from must be before --to");
  const auto params = std::make_shared<const core::GyroParameters>(
      o.params.empty() ? core::GyroParameters() : core::loadParameterFile(o.params));
  const std::unique_ptr<rosbag::Bag> bag = openBag(o.bag);
  const GyroTopics topics = findTopics(*bag, o.topics, true, false);
  core::GyroProcessor processor(o.processor, params);
  // Continuous stretches of the integrated angle; the longest one is analysed.
  std::vector<double> current, best, dts;
  replayChannels(
      *bag, topics.channels, processor,
      [&](const ChannelAmplitudes& c, const core::ProcessorResult& r) {
        if (!r.has_output) return;
        const double stamp = c.header.stamp.toSec();
        if (stamp < o.from || stamp > o.to) {
          // Outside the window: ends the stretch being collected, as a gap would.
          if (current.size() > best.size()) best.swap(current);
          current.clear();
          return;
        }
        if (r.flags & (core::kFlagGap | core::kFlagReset)) {
          if (current.size() > best.size()) best.swap(current);
          current.clear();
        }
        current.push_back(r.alpha);
        dts.push_back(r.increment.dt);
      },
      "allan");
  if (current.size() > best.size()) best.swap(current);
  if (best.size() < 100) throw UsageError("fewer than 100 continuous samples: nothing to analyse");
  std::nth_element(dts.begin(), dts.begin() + dts.size() / 2, dts.end());
  const double tau0 = dts[dts.size() / 2];
  const core::AllanResult a = core::allanDeviation(best, tau0);
  constexpr double kDegPerHour = 180.0 / M_PI * 3600.0;
  std::printf("allan: %zu samples, tau0 %.6f s, %zu points from %.3g s to %.3g s\n", best.size(), tau0, a.curve.size(),
              a.curve.front().tau, a.curve.back().tau);
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
  reading("rate random walk K", a.rate_random_walk, kDegPerHour * 60.0, "deg/h/sqrt(h)", 1.0, "rad/s/sqrt(s)");
  if (!o.yaml.empty()) {
    // The readings in SI for reports and for settings that read them (the alignment's noise/allan_file).
    OutputText yaml_file(o.yaml);
    yaml_file.stream() << core::allanReadingsYaml({best.size(), tau0, a});
    yaml_file.commit();
  }
  if (!o.csv.empty()) {
    OutputText csv_file(o.csv);
    std::ostream& csv = csv_file.stream();
    csv << "tau,deviation,error,clusters\n";
    char line[128];
    for (const core::AllanPoint& p : a.curve) {
      std::snprintf(line, sizeof line, "%.9g,%.9g,%.9g,%lu\n", p.tau, p.deviation, p.error,
                    static_cast<unsigned long>(p.clusters));
      csv << line;
    }
    csv_file.commit();
  }
  if (!o.plot.empty()) plot("allan", o.csv, o.plot);
  return 0;
}

}  // namespace

namespace bag_tools {

Command addAllanCommand(CLI::App& root) {
  auto o = std::make_shared<AllanOptions>();
  CLI::App* cmd = root.add_subcommand("allan", "overlapping Allan deviation of the compensated rate");
  cmd->add_option("BAG", o->bag, "input bag with the gyro's channels (a static session)")->required();
  cmd->add_option("--params", o->params, "parameter file (default: the nominal model)")->check(tools::notEmpty());
  CLI::Option* csv = cmd->add_option("--csv", o->csv, "output CSV: tau (s), deviation and its error (rad/s), clusters")
                         ->check(tools::notEmpty());
  cmd->add_option("--plot", o->plot, "PNG drawn from the CSV")->needs(csv)->check(tools::notEmpty());
  cmd->add_option("--yaml", o->yaml, "output YAML: the readings in SI with their tau ranges")->check(tools::notEmpty());
  cmd->add_option("--from", o->from, "first channel stamp analysed (s; default: the first)")
      ->check(tools::finiteNumber());
  cmd->add_option("--to", o->to, "last channel stamp analysed (s; default: the last)")->check(tools::finiteNumber());
  addTopicOptions(*cmd, &o->topics, false);
  addProcessorOptions(*cmd, &o->processor);
  cmd->footer(
      "Computes the overlapping Allan deviation of the compensated rate from the integrated angle over its\n"
      "longest continuous stretch (no gap or reset) within --from..--to (every sample still goes through\n"
      "the processor). Prints the readings: angle white noise Q (slope -1), angle random walk N (slope\n"
      "-1/2, at tau = 1 s), bias instability B (flat bottom / 0.664), rate random walk K (slope +1/2, at\n"
      "tau = 3 s), each with the tau range it was read from, or 'not identified'.\n"
      "The CSV, the YAML and the plot replace their paths only when complete.\n"
      "Exit 0 success, 2 bad usage, unreadable input or fewer than 100 continuous samples, 3 an output\n"
      "could not be written (nothing left at its path, an existing file unchanged).");
  return [o] { return runAllan(*o); };
}

}  // namespace bag_tools
}  // namespace hrg_gyro

// hrg_bag allan: overlapping Allan deviation of the compensated rate (IEEE 952 readings): of one HRG
// from its channels through the processor, or per axis of a triad's TriadOutput or of any IMU's
// sensor_msgs/Imu (its rates turned back into increments as the gyrocompass's IMU input does), the
// readings file then each axis's and, at its top level, the worst axis's per term.
#include <rosbag/view.h>
#include <sensor_msgs/Imu.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <memory>
#include <vector>

#include "../cli_checks.h"
#include "bag_tools.h"
#include "hrg_gyro/TriadOutput.h"
#include "hrg_gyro/core/estimation/allan_deviation.h"
#include "hrg_gyro/core/estimation/allan_readings_file.h"
#include "hrg_gyro/core/model/parameter_file.h"
#include "hrg_gyro/core/processing/imu_increment_converter.h"
#include "hrg_gyro/ros/conversions.h"
#include "read_messages.h"
#include "reused_message_reader.h"

namespace hrg_gyro {

namespace {

struct AllanOptions {
  std::string bag, params, csv, plot, yaml;
  std::string imu_topic, triad_topic;      ///< per axis of this stream instead of one HRG's channels
  double from = -INFINITY, to = INFINITY;  ///< s, channel stamps analysed (the processor sees them all)
  bag_tools::GyroTopics topics;
  core::ProcessorConfig processor;
};

constexpr double kDegPerHour = 180.0 / M_PI * 3600.0;

void printReading(const char* name, const core::NoiseReading& r, const char* si_unit, double scale, const char* unit) {
  if (!r.identified) {
    std::printf("  %-22s not identified (no range with that slope)\n", name);
  } else {
    std::printf("  %-22s %.4g %s (%.4g %s), from tau %.3g..%.3g s\n", name, r.value, si_unit, r.value * scale, unit,
                r.tau_min, r.tau_max);
  }
}

void printReadings(const core::AllanResult& a) {
  printReading("angle white noise Q", a.angle_white_noise, "rad", 180.0 / M_PI * 3600.0, "arcsec");
  printReading("angle random walk N", a.angle_random_walk, "rad/sqrt(s)", 180.0 / M_PI * 60.0, "deg/sqrt(h)");
  printReading("bias instability B", a.bias_instability, "rad/s", kDegPerHour, "deg/h");
  printReading("rate random walk K", a.rate_random_walk, "rad/s/sqrt(s)", kDegPerHour * 60.0, "deg/h/sqrt(h)");
}

/// The three axes' integrated angles over the longest continuous stretch of a triad's or an IMU's
/// stream within --from..--to, and the stretch's median interval. A gap, a reset, and a sample over
/// another interval than the stretch's first (one that spans a lost sample) end the stretch: the
/// deviation needs the angle every tau0.
struct AxisAngles {
  std::array<std::vector<double>, 3> angle, best;
  std::vector<double> dts;
  std::array<double, 3> sum{{0.0, 0.0, 0.0}};
  double spacing = 0.0;  // s, the stretch's first interval

  void add(const core::TriadBodySample& s, double from, double to) {
    const double t = core::toSeconds(s.stamp);
    const bool uneven = spacing > 0.0 && std::abs(s.dt / spacing - 1.0) > 0.5;
    if (t < from || t > to || !s.integrated() || uneven) {
      cut();
      return;
    }
    if (spacing == 0.0) spacing = s.dt;
    for (int a = 0; a < 3; ++a) {
      sum[a] += s.delta_angle[a];
      angle[a].push_back(sum[a]);
    }
    dts.push_back(s.dt);
  }
  void cut() {
    if (angle[0].size() > best[0].size()) best.swap(angle);
    for (auto& v : angle) v.clear();
    spacing = 0.0;
  }
};

int runAxesAllan(const AllanOptions& o) {
  using namespace bag_tools;
  checkOutputPaths({o.bag}, {o.csv, o.plot, o.yaml});
  if (!o.csv.empty() || !o.plot.empty())
    throw UsageError("--csv and --plot: one gyro's channels only (per axis: --yaml)");
  if (!(o.from < o.to)) throw UsageError("--from must be before --to");
  const std::unique_ptr<rosbag::Bag> bag = openBag(o.bag);
  const bool imu = !o.imu_topic.empty();
  const std::string topic =
      imu ? findTopic(*bag, o.imu_topic, ros::message_traits::datatype<sensor_msgs::Imu>(), "imu-topic", true)
          : findTopic(*bag, o.triad_topic, ros::message_traits::datatype<TriadOutput>(), "triad-topic", true);
  core::ImuIncrementConverter converter{core::ImuInputSettings()};
  ReusedMessageReader<sensor_msgs::Imu> imu_reader;
  ReusedMessageReader<TriadOutput> triad_reader;
  sensor_msgs::Imu imu_message;
  TriadOutput triad_message;
  AxisAngles angles;
  rosbag::View view(*bag, rosbag::TopicQuery(topic));
  readMessages(view, nullptr, [&](const rosbag::MessageInstance& m) {
    if (imu && imu_reader.read(m, &imu_message)) {
      const auto sample = converter.convert(fromImuMessage(imu_message));
      if (sample) angles.add(*sample, o.from, o.to);
    } else if (!imu && triad_reader.read(m, &triad_message)) {
      angles.add(fromMessage(triad_message), o.from, o.to);
    }
  });
  angles.cut();
  const std::size_t n = angles.best[0].size();
  if (n < 100) throw UsageError("fewer than 100 continuous samples on " + topic + ": nothing to analyse");
  std::nth_element(angles.dts.begin(), angles.dts.begin() + angles.dts.size() / 2, angles.dts.end());
  const double tau0 = angles.dts[angles.dts.size() / 2];
  core::AllanReadings readings;
  readings.samples = n;
  readings.tau0 = tau0;
  std::printf("allan: %s, %zu continuous samples of 3 axes, tau0 %.6f s\n", topic.c_str(), n, tau0);
  const char* names[3] = {"x", "y", "z"};
  for (int a = 0; a < 3; ++a) {
    readings.axes.push_back({names[a], core::allanDeviation(angles.best[a], tau0)});
    std::printf(" axis %s (the stream's own frame):\n", names[a]);
    printReadings(readings.axes.back().result);
    // Whatever else the record holds (a base that rocks, a count's rounding), the angle random walk is
    // at most the smallest deviation times sqrt(tau): the bound to give where no slope reads N.
    double bound = INFINITY, at = 0.0;
    for (const core::AllanPoint& p : readings.axes.back().result.curve) {
      if (p.clusters >= 8 && p.deviation * std::sqrt(p.tau) < bound) {
        bound = p.deviation * std::sqrt(p.tau);
        at = p.tau;
      }
    }
    if (std::isfinite(bound)) {
      std::printf("  %-22s %.4g rad/sqrt(s) (%.4g deg/sqrt(h)): the smallest deviation x sqrt(tau), at tau %.3g s\n",
                  "N at most", bound, bound * 180.0 / M_PI * 60.0, at);
    }
  }
  readings.result = core::worstOfAxes(readings.axes);
  std::printf(" the worst axis per term (the readings file's top level, what noise/allan_file takes):\n");
  printReadings(readings.result);
  if (!o.yaml.empty()) {
    OutputText yaml_file(o.yaml);
    yaml_file.stream() << core::allanReadingsYaml(readings);
    yaml_file.commit();
  }
  return 0;
}

int runAllan(const AllanOptions& o) {
  using namespace bag_tools;
  if (!o.imu_topic.empty() || !o.triad_topic.empty()) return runAxesAllan(o);
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
  std::printf("allan: %zu samples, tau0 %.6f s, %zu points from %.3g s to %.3g s\n", best.size(), tau0, a.curve.size(),
              a.curve.front().tau, a.curve.back().tau);
  printReadings(a);
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
  CLI::Option* imu = cmd->add_option("--imu-topic", o->imu_topic,
                                     "per axis of any IMU's sensor_msgs/Imu (its rates back into increments)")
                         ->check(tools::notEmpty());
  cmd->add_option("--triad-topic", o->triad_topic, "per axis of a triad's hrg_gyro/TriadOutput")
      ->check(tools::notEmpty())
      ->excludes(imu);
  addTopicOptions(*cmd, &o->topics, false);
  addProcessorOptions(*cmd, &o->processor);
  cmd->footer(
      "Computes the overlapping Allan deviation of the compensated rate from the integrated angle over its\n"
      "longest continuous stretch (no gap or reset) within --from..--to (every sample still goes through\n"
      "the processor). Prints the readings: angle white noise Q (slope -1), angle random walk N (slope\n"
      "-1/2, at tau = 1 s), bias instability B (flat bottom / 0.664), rate random walk K (slope +1/2, at\n"
      "tau = 3 s), each with the tau range it was read from, or 'not identified'.\n"
      "--imu-topic (any IMU's sensor_msgs/Imu) or --triad-topic (TriadOutput): the same per axis of that\n"
      "stream, over its longest stretch without a gap or a lost sample; --yaml then holds each axis's\n"
      "readings and, at its top level, the worst axis's per term, with tau0 the stream's median interval\n"
      "(the alignment refuses a window sampled otherwise: its Q is per sample).\n"
      "The CSV, the YAML and the plot replace their paths only when complete.\n"
      "Exit 0 success, 2 bad usage, unreadable input or fewer than 100 continuous samples, 3 an output\n"
      "could not be written (nothing left at its path, an existing file unchanged).");
  return [o] { return runAllan(*o); };
}

}  // namespace bag_tools
}  // namespace hrg_gyro

// hrg_bag simulate: the simulator without a master, straight into a bag, as fast as it runs.
#include <iostream>

#include "../cli_checks.h"
#include "bag_tools.h"
#include "hrg_gyro/core/simulation/gyro_simulator.h"
#include "hrg_gyro/core/simulation/triad_simulator.h"
#include "hrg_gyro/ros/conversions.h"

namespace hrg_gyro {

namespace {

struct SimulateOptions {
  std::string scenario, out, frame_id = "gyro_link", compression = "lz4";
  std::uint64_t seed = 0;
  CLI::Option* seed_option = nullptr;
  CLI::Option* frame_id_option = nullptr;
  bool no_truth = false;
};

/// A triad scenario: each axis's channels and truth under its own namespace, one table, the fixture's
/// log and the body's truth (docs/simulation.md, "A triad on a rate table").
int runSimulateTriad(const SimulateOptions& o, const YAML::Node& document) {
  using namespace bag_tools;
  core::TriadSimulationConfig config =
      core::TriadSimulationConfig::parse(core::YamlField(document, ""), core::nodeOnlyScenarioKeys());
  if (*o.seed_option) config.setSeed(o.seed);  // the fixture errors it draws included
  if (*o.frame_id_option) config.frame_id = o.frame_id;
  const bool truth = !o.no_truth;
  OutputBag bag(o.out, o.compression);
  core::TriadSimulator sim(config);
  std::array<std::string, 3> channels_topic, truth_topic, precession_topic;
  for (int i = 0; i < 3; ++i) {
    channels_topic[i] = "/" + triadAxisTopic(config.axes[i].name, "channels");
    truth_topic[i] = "/" + triadAxisTopic(config.axes[i].name, "truth");
    precession_topic[i] = "/" + triadAxisTopic(config.axes[i].name, "precession/state");
  }
  Progress progress("simulate", sim.duration());
  core::TriadSample s;
  std::uint32_t seq = 0;
  while (sim.next(&s)) {
    const ros::Time stamp = toRosTime(s.stamp);
    for (int i = 0; i < 3; ++i) {
      const core::SimulationSample& axis = s.axes[i];
      const ChannelAmplitudes ch =
          toChannelsMessage(axis, stamp, static_cast<std::uint32_t>(axis.index), config.axes[i].name);
      if (axis.channels_delivered) bag.write(channels_topic[i], stamp, ch);
      if (truth) bag.write(truth_topic[i], stamp, toTruthMessage(axis, trueHeader(ch.header, stamp)));
      if (config.axes[i].dynamics.averaged()) {
        bag.write(precession_topic[i], stamp,
                  toPrecessionStateMessage(axis, trueHeader(ch.header, stamp), kScheduledPrecessionSource));
      }
    }
    for (const core::TurntableLogRecord& r : s.turntable) {
      bag.write("/turntable/state", toRosTime(core::toNanoseconds(config.start_time + r.time)),
                toTurntableMessage(r, 0, config.frame_id));
    }
    if (s.fixture_logged) bag.write("/fixture/position", stamp, toFixtureMessage(s, stamp, config.frame_id));
    if (truth) bag.write("/truth", stamp, toBodyTruthMessage(s, stamp, config.frame_id));
    if (s.accelerometer.present)
      bag.write("/accel/data_raw", stamp, toAccelerometerMessage(s, stamp, config.accelerometer));
    progress.update(sim.elapsed(), ++seq);
  }
  bag.commit();
  progress.finish(seq);
  std::cerr << "simulate: " << sim.elapsed() << " s of triad session written to " << o.out << "\n";
  return 0;
}

int runSimulate(const SimulateOptions& o) {
  using namespace bag_tools;
  checkOutputPaths({o.scenario}, {o.out});
  const YAML::Node document = core::loadScenarioDocument(o.scenario);
  if (core::isTriadScenario(document)) return runSimulateTriad(o, document);
  core::SimulationConfig config =
      core::SimulationConfig::parse(core::YamlField(document, ""), core::nodeOnlyScenarioKeys());
  if (*o.seed_option) config.seed = o.seed;
  const bool truth = !o.no_truth;
  OutputBag bag(o.out, o.compression);
  core::GyroSimulator sim(config);
  Progress progress("simulate", sim.duration());
  core::SimulationSample s;
  std::uint32_t seq = 0;
  std::string precession_source;  // every command here is the schedule's
  while (sim.next(&s)) {
    const ros::Time stamp = toRosTime(s.stamp);
    // The channel sequence number is the sample's index, so a lost sample leaves a gap in it.
    const ChannelAmplitudes ch = toChannelsMessage(s, stamp, static_cast<std::uint32_t>(s.index), o.frame_id);
    if (s.channels_delivered) bag.write("/channels", stamp, ch);
    // The table's records, recorded when they were made (neither a glitched stamp nor the
    // controller's clock moves them), their sequence number the controller's count: a lost record
    // leaves a gap in it.
    for (const core::TurntableLogRecord& r : s.turntable) {
      bag.write("/turntable/state", toRosTime(core::toNanoseconds(config.start_time + r.time)),
                toTurntableMessage(r, 0, o.frame_id));
    }
    if (truth) bag.write("/truth", stamp, toTruthMessage(s, trueHeader(ch.header, stamp)));
    // A gyro with a precession loop: the schedule's commands as the commanding node would have sent
    // them (at the carrier period that took each up), and what the loop executes, with every sample.
    for (const core::AppliedPrecession& a : s.precession_commands) {
      const ros::Time at = toRosTime(core::toNanoseconds(config.start_time + a.time));
      bag.write("/command/precession", at, toPrecessionCommandMessage(a, at, o.frame_id));
    }
    updatePrecessionSource(s, std::string(), &precession_source);
    if (sim.hasPrecessionLoop()) {
      bag.write("/precession/state", stamp,
                toPrecessionStateMessage(s, trueHeader(ch.header, stamp), precession_source));
    }
    progress.update(sim.elapsed(), ++seq);
  }
  bag.commit();
  progress.finish(seq);
  std::cerr << "simulate: " << sim.elapsed() << " s of session written to " << o.out << "\n";
  return 0;
}

}  // namespace

namespace bag_tools {

Command addSimulateCommand(CLI::App& root) {
  auto o = std::make_shared<SimulateOptions>();
  CLI::App* cmd = root.add_subcommand("simulate", "the simulator without a master, straight into a bag");
  cmd->add_option("--scenario", o->scenario, "scenario file (YAML, the driver_sim parameters)")->required();
  cmd->add_option("--out", o->out, "output bag")->required()->check(tools::notEmpty());
  o->seed_option = cmd->add_option("--seed", o->seed, "noise seed, a whole number >= 0 (default: the scenario's)")
                       ->transform(tools::unsignedWholeNumber());
  o->frame_id_option = cmd->add_option("--frame-id", o->frame_id,
                                       "frame_id of the written messages; of a triad's body frame (default: the "
                                       "scenario's triad.frame_id)")
                           ->check(tools::frameId())
                           ->capture_default_str();
  cmd->add_flag("--no-truth", o->no_truth, "do not write /truth");
  addCompressionOption(*cmd, &o->compression);
  cmd->footer(
      "Runs the simulated gyro of a scenario and writes /channels, /turntable/state and /truth (unless\n"
      "--no-truth), stamped and recorded at simulated time, as fast as it runs. A gyro with a precession\n"
      "loop (dynamics.model: averaged) adds /precession/state with every sample and its schedule's\n"
      "commands (dynamics.commands) on /command/precession, as sent to a live driver. A triad scenario (a\n"
      "`triad` section) writes /<axis>/channels and /<axis>/truth for each axis, /turntable/state,\n"
      "/fixture/position, the body's /truth (hrg_gyro/BodyTruth) and, with triad.accelerometer, its\n"
      "/accel/data_raw (sensor_msgs/Imu); an axis with a precession loop adds /<axis>/precession/state\n"
      "with every sample (its schedule's). Chunks are LZ4-compressed\n"
      "by default (several times faster to read back; every rosbag reader handles it).\n"
      "The bag is written to a temporary and renamed over --out when complete.\n"
      "Exit 0 success, 2 bad usage or unreadable scenario (or --out is the scenario file), 3 the bag\n"
      "could not be written (nothing left at --out, an existing file unchanged).");
  return [o] { return runSimulate(*o); };
}

}  // namespace bag_tools
}  // namespace hrg_gyro

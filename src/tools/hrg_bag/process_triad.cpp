#include "process_triad.h"

#include <rosbag/view.h>

#include <algorithm>
#include <array>
#include <iostream>
#include <map>
#include <memory>

#include "../cli_checks.h"
#include "bag_tools.h"
#include "csv_text.h"
#include "hrg_gyro/core/model/parameter_file.h"
#include "hrg_gyro/core/model/triad_parameters.h"
#include "hrg_gyro/ros/conversions.h"
#include "reused_message_reader.h"

namespace hrg_gyro {
namespace bag_tools {
namespace {

/// One axis of the triad: its processor, and the variance its processor node's Imu would carry.
struct Axis {
  std::string name, parameter_file, topic;
  std::unique_ptr<core::GyroProcessor> processor;
  std::unique_ptr<core::RateNoiseEstimator> noise;
  core::ProcessorResult result;
  std::string frame_id;  // of its outputs, as triad.launch names it
  std::uint64_t outputs = 0;
};

/// NAME=VALUE items of a per-axis option (--axis-params, --axis-channels): each name an axis of the
/// triad, given once. A UsageError names what is wrong.
std::map<std::string, std::string> perAxis(const std::vector<std::string>& items, const core::TriadParameters& triad,
                                           const std::string& option) {
  std::map<std::string, std::string> out;
  for (const std::string& item : items) {
    const std::size_t eq = item.find('=');
    if (eq == std::string::npos || eq == 0 || eq + 1 == item.size()) {
      throw UsageError("--" + option + " expects NAME=VALUE with NAME an axis of the triad (" + triad.axes[0] + ", " +
                       triad.axes[1] + ", " + triad.axes[2] + "), got '" + item + "'");
    }
    const std::string axis = item.substr(0, eq);
    if (std::find(triad.axes.begin(), triad.axes.end(), axis) == triad.axes.end()) {
      throw UsageError("--" + option + " " + item + ": '" + axis + "' is not an axis of the triad (its axes: " +
                       triad.axes[0] + ", " + triad.axes[1] + ", " + triad.axes[2] + ")");
    }
    if (!out.emplace(axis, item.substr(eq + 1)).second)
      throw UsageError("--" + option + " gives axis " + axis + " twice");
  }
  return out;
}

/// The axis's channels: `chosen` (--axis-channels), or /AXIS/channels, or the one ChannelAmplitudes
/// topic ending in /AXIS/channels (a triad recorded inside a namespace).
std::string axisTopic(const rosbag::Bag& bag, const std::string& axis, const std::string& chosen) {
  rosbag::View all(bag);
  const std::string type = ros::message_traits::datatype<ChannelAmplitudes>();
  if (!chosen.empty()) {
    for (const rosbag::ConnectionInfo* c : all.getConnections()) {
      if (c->topic != chosen) continue;
      if (c->datatype != type) throw UsageError("topic " + chosen + " has type " + c->datatype + ", expected " + type);
      return chosen;
    }
    throw UsageError("topic " + chosen + " (--axis-channels " + axis + "=...) is not in the bag");
  }
  const std::string suffix = "/" + axis + "/channels";
  std::vector<std::string> found;
  std::string listing;
  for (const rosbag::ConnectionInfo* c : all.getConnections()) {
    listing += "\n  " + c->topic + " [" + c->datatype + "]";
    if (c->datatype != type) continue;
    if (c->topic == suffix) return c->topic;
    const bool ends = c->topic.size() > suffix.size() &&
                      c->topic.compare(c->topic.size() - suffix.size(), suffix.size(), suffix) == 0;
    if (ends && std::find(found.begin(), found.end(), c->topic) == found.end()) found.push_back(c->topic);
  }
  if (found.size() == 1) return found.front();
  if (found.empty()) {
    throw UsageError("no " + type + " topic " + suffix + " for axis '" + axis +
                     "' in the bag; it holds:" + (listing.empty() ? " nothing" : listing));
  }
  throw UsageError("several " + type + " topics end in " + suffix + " in the bag: one triad per bag");
}

const char* kCsvHeader =
    "stamp,flags,dt,delta_angle_x,delta_angle_y,delta_angle_z,angular_velocity_x,angular_velocity_y,"
    "angular_velocity_z,cov_xx,cov_xy,cov_xz,cov_yx,cov_yy,cov_yz,cov_zx,cov_zy,cov_zz\n";

/// One CSV row from the message the triad node publishes (so the CSV holds its numbers).
void formatRow(const TriadOutput& m, CsvText* text) {
  text->beginRow();
  text->stamp(m.header.stamp.sec, m.header.stamp.nsec);
  text->integer(m.flags);
  text->number(m.dt);
  text->number(m.delta_angle.x);
  text->number(m.delta_angle.y);
  text->number(m.delta_angle.z);
  text->number(m.angular_velocity.x);
  text->number(m.angular_velocity.y);
  text->number(m.angular_velocity.z);
  for (double c : m.angular_velocity_covariance) text->number(c);
  text->endRow();
}

}  // namespace

CLI::Option* addTriadOptions(CLI::App& command, TriadOptions* o) {
  const std::string group = "Triad (the triad node's parameters; same rules)";
  CLI::Option* triad =
      command
          .add_option("--triad", o->triad_file,
                      "triad file (frame_id, axes, M, bias): process the three axes' /NAME/channels into the "
                      "triad's /triad/output and /imu/data_raw (with --axis-params)")
          ->check(tools::notEmpty())
          ->group(group);
  command.add_option("--axis-params", o->axis_params, "NAME=FILE, each axis's parameter file (all three)")
      ->expected(1)
      ->multi_option_policy(CLI::MultiOptionPolicy::TakeAll)
      ->group(group)
      ->needs(triad);
  command.add_option("--axis-channels", o->axis_channels, "NAME=TOPIC, an axis's channels (default /NAME/channels)")
      ->expected(1)
      ->multi_option_policy(CLI::MultiOptionPolicy::TakeAll)
      ->group(group)
      ->needs(triad);
  auto number = [&](const char* name, double* value, const char* meaning) {
    command.add_option(name, *value, meaning)
        ->transform(tools::finiteNumber())
        ->capture_default_str()
        ->group(group)
        ->needs(triad);
  };
  number("--stamp-tolerance", &o->combiner.stamp_tolerance,
         "s, >= 0: largest difference of the axes' stamps in one sample (0: a quarter of the sample period)");
  number("--max-wait", &o->combiner.max_wait, "s, > 0: of stamps a sample waits for an axis, then a gap");
  command.add_option("--max-pending", o->combiner.max_pending, "samples held per axis while waiting")
      ->transform(tools::wholeNumber(1, 100000000))
      ->capture_default_str()
      ->group(group)
      ->needs(triad);
  // The triad node's stamp rule and plausibility bound on the axes' outputs (its parameters of the
  // same names without the prefix; the processors' own are --max-gap, --backward-reset, ...).
  number("--triad-max-rate", &o->combiner.max_rate, "rad/s, > 0: an axis output with |dalpha| / dt above is dropped");
  number("--triad-backward-reset", &o->combiner.backward_reset,
         "s, > 0: an axis output stamped further back is a jump (a glitch unless it persists)");
  number("--triad-forward-jump", &o->combiner.forward_jump,
         "s, > 0: an axis output stamped further ahead is a jump (a glitch unless it persists)");
  command
      .add_option("--triad-jump-persist", o->combiner.jump_persist,
                  "axis outputs in a row past one jump that make it real")
      ->transform(tools::wholeNumber(1, 1000))
      ->capture_default_str()
      ->group(group)
      ->needs(triad);
  number("--angular-velocity-variance", &o->noise.configured_variance,
         "(rad/s)^2 of each axis's rate: positive, as given; negative, measured (the processor's own estimate)");
  number("--initial-angular-velocity-variance", &o->noise.initial_variance,
         "(rad/s)^2, > 0: each axis's variance until its measured one has settled");
  return triad;
}

int runTriadProcess(const std::string& bag_path, const std::string& out_path, const std::string& csv_path,
                    const std::string& compression, const core::ProcessorConfig& processor, const TriadOptions& o) {
  checkProcessorConfig(processor);
  core::TriadCombinerSettings combiner_settings = o.combiner;
  combiner_settings.initial_rate_variance = o.noise.initial_variance;  // the node's defaults agree
  try {
    o.noise.validate();
    combiner_settings.validate();
  } catch (const core::ConfigError& e) {
    std::string option = e.key();
    if (option == "max_rate" || option == "backward_reset" || option == "forward_jump" || option == "jump_persist") {
      option = "triad_" + option;  // the processors' options have these names
    }
    std::replace(option.begin(), option.end(), '_', '-');
    throw UsageError("--" + option + ": " + e.problem());
  }
  const auto triad = std::make_shared<const core::TriadParameters>(core::loadTriadFile(o.triad_file));
  const std::map<std::string, std::string> given = perAxis(o.axis_params, *triad, "axis-params");
  const std::map<std::string, std::string> channels = perAxis(o.axis_channels, *triad, "axis-channels");
  std::array<std::string, 3> files;
  for (std::size_t a = 0; a < 3; ++a) {
    const auto it = given.find(triad->axes[a]);
    if (it == given.end()) {
      throw UsageError("--axis-params " + triad->axes[a] + "=FILE missing: each axis's parameter file is needed");
    }
    files[a] = it->second;
  }
  std::vector<std::string> inputs{bag_path, o.triad_file};
  inputs.insert(inputs.end(), files.begin(), files.end());
  checkOutputPaths(inputs, {out_path, csv_path});

  std::array<Axis, 3> axes;
  for (std::size_t a = 0; a < 3; ++a) {
    axes[a].name = triad->axes[a];
    axes[a].parameter_file = files[a];
    axes[a].processor = std::make_unique<core::GyroProcessor>(
        processor, std::make_shared<const core::GyroParameters>(core::loadParameterFile(files[a])));
    axes[a].noise = std::make_unique<core::RateNoiseEstimator>(o.noise);
    axes[a].frame_id = axes[a].name + "_gyro_link";
  }
  const std::unique_ptr<rosbag::Bag> bag = openBag(bag_path);
  std::vector<std::string> topics;
  std::map<std::string, std::size_t> axis_of_topic;
  for (std::size_t a = 0; a < 3; ++a) {
    const auto chosen = channels.find(axes[a].name);
    axes[a].topic = axisTopic(*bag, axes[a].name, chosen == channels.end() ? std::string() : chosen->second);
    topics.push_back(axes[a].topic);
    axis_of_topic[axes[a].topic] = a;
  }
  checkDistinctAxisTopics(triad->axes, {{axes[0].topic, axes[1].topic, axes[2].topic}});
  std::unique_ptr<OutputBag> out;
  if (!out_path.empty()) out = std::make_unique<OutputBag>(out_path, compression);
  std::unique_ptr<OutputText> csv;
  CsvText text;
  if (!csv_path.empty()) {
    csv = std::make_unique<OutputText>(csv_path);
    csv->stream() << kCsvHeader;
  }

  core::TriadCombiner combiner(combiner_settings, triad);
  std::vector<core::TriadBodySample> completed;
  const auto write = [&](const std::vector<core::TriadBodySample>& samples) {
    for (const core::TriadBodySample& s : samples) {
      const TriadOutput m = toTriadOutputMessage(s, triad->frame_id);
      if (out) {
        out->write("/triad/output", m.header.stamp, m);
        if (s.integrated()) out->write("/imu/data_raw", m.header.stamp, toImuMessage(s, triad->frame_id));
      }
      if (csv) {
        formatRow(m, &text);
        if (text.size() > (1u << 20)) {
          csv->stream().write(text.data(), static_cast<std::streamsize>(text.size()));
          text.clear();
        }
      }
    }
  };

  rosbag::View view(*bag, rosbag::TopicQuery(topics));
  Progress progress("process --triad", view.size());
  ReusedMessageReader<ChannelAmplitudes> reader;
  ChannelAmplitudes msg;
  std::uint64_t n = 0;
  try {
    for (const rosbag::MessageInstance& instance : view) {
      if (!reader.read(instance, &msg)) continue;
      ++n;
      Axis& axis = axes[axis_of_topic.at(instance.getTopic())];
      const std::size_t a = static_cast<std::size_t>(&axis - axes.data());
      axis.processor->process(fromMessage(msg), &axis.result);
      const core::ProcessorResult& r = axis.result;
      if (!r.has_output) continue;
      // What the axis's processor node publishes: its output, and its Imu's variance for a sample
      // without a gap or reset (for those it publishes no Imu).
      std_msgs::Header header = msg.header;
      header.frame_id = axis.frame_id;
      const GyroOutput output = toOutputMessage(header, r);
      ++axis.outputs;
      axis.noise->add(r.alpha, r.increment.dt, r.flags);
      core::AxisOutput in = toAxisOutput(output);
      if (!(r.flags & (core::kFlagGap | core::kFlagReset))) in.rate_variance = axis.noise->variance();
      if (out) out->write("/" + axis.name + "/output", output.header.stamp, output);
      completed.clear();
      combiner.add(a, in, &completed);
      write(completed);
      if (n % 4096 == 0) progress.update(n, n);
    }
  } catch (const rosbag::BagException& e) {
    throw UsageError(std::string("bag read error after ") + std::to_string(n) + " samples (truncated?): " + e.what());
  } catch (const ros::serialization::StreamOverrunException& e) {
    throw UsageError(std::string("bag read error after ") + std::to_string(n) +
                     " samples: a message shorter than its type (corrupt?): " + e.what());
  }
  progress.finish(n);
  // The stamps some axis never delivered, as the gaps they are.
  completed.clear();
  combiner.flush(&completed);
  write(completed);
  if (csv) {
    csv->stream().write(text.data(), static_cast<std::streamsize>(text.size()));
    csv->commit();
  }
  if (out) out->commit();
  const core::TriadCounters& c = combiner.counters();
  std::cerr << "process: triad " << triad->frame_id << ": " << c.samples << " samples, " << c.integrated
            << " combined, " << c.gaps << " gaps, " << c.resets << " resets, " << c.axis_flagged << " axis flagged, "
            << c.timeouts << " waited out, " << c.carried << " stamps skipped by an axis (carried into the next)\n";
  for (std::size_t a = 0; a < 3; ++a) {
    const core::ProcessorCounters& p = axes[a].processor->counters();
    const core::TriadAxisCounters& t = c.axes[a];
    std::cerr << "  axis " << axes[a].name << " (" << axes[a].topic << ", " << axes[a].parameter_file
              << "): " << p.received << " samples, " << axes[a].outputs << " outputs, " << p.rejected() << " rejected, "
              << t.missing << " stamps missing, " << t.mismatched << " intervals mismatched, "
              << p.stamp_jumps + t.stamp_jumps << " stamp jumps dropped\n";
  }
  if (c.integrated == 0) {
    std::cerr << "process: no triad sample combined from all three axes\n";
    return 1;
  }
  return 0;
}

}  // namespace bag_tools
}  // namespace hrg_gyro

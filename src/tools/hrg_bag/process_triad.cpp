#include "process_triad.h"

#include <rosbag/view.h>

#include <algorithm>
#include <array>
#include <deque>
#include <iostream>
#include <map>
#include <memory>

#include "../cli_checks.h"
#include "bag_tools.h"
#include "csv_text.h"
#include "hrg_gyro/core/model/parameter_file.h"
#include "hrg_gyro/core/model/triad_file.h"
#include "hrg_gyro/ros/conversions.h"
#include "read_messages.h"
#include "reused_message_reader.h"
#include "triad_axis_options.h"

namespace hrg_gyro {
namespace bag_tools {
namespace {

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

/// Where the triad's messages go, as the live nodes publish them: each axis's GyroOutput (once the
/// chain hands it on), /triad/output and /imu/data_raw into the bag; the CSV's rows.
class TriadOutputs {
 public:
  TriadOutputs(const std::string& out_path, const std::string& csv_path, const std::string& compression,
               const std::string& frame_id, const std::array<AxisInput, 3>& axes)
      : frame_id_(frame_id) {
    if (!out_path.empty()) bag_ = std::make_unique<OutputBag>(out_path, compression);
    if (!csv_path.empty()) {
      csv_ = std::make_unique<OutputText>(csv_path);
      csv_->stream() << kCsvHeader;
    }
    for (std::size_t a = 0; a < 3; ++a) {
      axis_frames_[a] = axes[a].frame_id;
      axis_topics_[a] = "/" + axes[a].name + "/output";
    }
  }

  /// An axis's output, as its processor node makes it, until its verdict comes (release order).
  void hold(std::size_t axis, const std_msgs::Header& channels_header, const core::ProcessorResult& r) {
    if (!bag_) return;
    std_msgs::Header header = channels_header;
    header.frame_id = axis_frames_[axis];
    held_[axis].push_back(toOutputMessage(header, r));
  }

  /// The outputs decided, with their flags, then the triad samples they completed.
  void write(const std::vector<core::TriadAxisOutput>& outputs, const std::vector<core::TriadBodySample>& samples) {
    if (bag_) {
      for (const core::TriadAxisOutput& o : outputs) {
        GyroOutput& m = held_[o.axis].front();
        m.flags = o.output.flags;
        bag_->write(axis_topics_[o.axis], m.header.stamp, m);
        held_[o.axis].pop_front();
      }
    }
    for (const core::TriadBodySample& s : samples) {
      const TriadOutput m = toTriadOutputMessage(s, frame_id_);
      if (bag_) {
        bag_->write("/triad/output", m.header.stamp, m);
        if (s.integrated()) bag_->write("/imu/data_raw", m.header.stamp, toImuMessage(s, frame_id_));
      }
      if (csv_) {
        formatRow(m, &text_);
        if (text_.size() > (1u << 20)) flushText();
      }
    }
  }

  void commit() {
    if (csv_) {
      flushText();
      csv_->commit();
    }
    if (bag_) bag_->commit();
  }

 private:
  void flushText() {
    csv_->stream().write(text_.data(), static_cast<std::streamsize>(text_.size()));
    text_.clear();
  }

  std::string frame_id_;
  std::array<std::string, 3> axis_frames_, axis_topics_;
  std::unique_ptr<OutputBag> bag_;
  std::unique_ptr<OutputText> csv_;
  CsvText text_;
  std::array<std::deque<GyroOutput>, 3> held_;
};

/// The bag's channels through `triad`, in record order, into `outputs`; the input's end flushes the
/// combiner. Returns the channel messages read.
std::uint64_t replayTriad(const rosbag::Bag& bag, const std::array<AxisInput, 3>& axes, core::TriadProcessor* triad,
                          TriadOutputs* outputs) {
  std::vector<std::string> topics;
  std::map<std::string, std::size_t> axis_of_topic;
  for (std::size_t a = 0; a < 3; ++a) {
    topics.push_back(axes[a].topic);
    axis_of_topic[axes[a].topic] = a;
  }
  rosbag::View view(bag, rosbag::TopicQuery(topics));
  Progress progress("process --triad", view.size());
  ReusedMessageReader<ChannelAmplitudes> reader;
  ChannelAmplitudes msg;
  core::ProcessorResult result;
  std::vector<core::TriadAxisOutput> decided;
  std::vector<core::TriadBodySample> completed;
  std::uint64_t n = 0;  // channel samples
  readMessages(view, progress, [&](const rosbag::MessageInstance& instance) {
    if (!reader.read(instance, &msg)) return;
    ++n;
    const std::size_t axis = axis_of_topic.at(instance.getTopic());
    triad->process(axis, fromMessage(msg), &result);
    if (result.has_output) {
      outputs->hold(axis, msg.header, result);
      decided.clear();
      completed.clear();
      triad->release(&decided, &completed);
      outputs->write(decided, completed);
    }
  });
  progress.finish(n);
  decided.clear();
  completed.clear();
  triad->finish(&decided, &completed);
  outputs->write(decided, completed);
  return n;
}

/// What the run did, on stderr; the exit code: 1 when nothing was combined from all three axes.
int summarize(const core::TriadProcessor& triad, const std::array<AxisInput, 3>& axes) {
  const core::TriadCounters& c = triad.combiner().counters();
  std::cerr << "process: triad " << triad.combiner().parameters().frame_id << ": " << c.samples << " samples, "
            << c.integrated << " combined, " << c.gaps << " gaps, " << c.resets << " resets, " << c.axis_flagged
            << " axis flagged, " << c.timeouts << " waited out, " << c.carried
            << " stamps skipped by an axis (carried into the next)\n";
  for (std::size_t a = 0; a < 3; ++a) {
    const core::ProcessorCounters& p = triad.processor(a).counters();
    const core::TriadAxisCounters& t = c.axes[a];
    std::cerr << "  axis " << axes[a].name << " (" << axes[a].topic << ", " << axes[a].parameter_file
              << "): " << p.received << " samples, " << triad.outputs(a) << " outputs, " << p.rejected()
              << " rejected, " << t.missing << " stamps missing, " << t.mismatched << " intervals mismatched, "
              << p.stamp_jumps + t.stamp_jumps << " stamp jumps dropped\n";
  }
  if (c.integrated == 0) {
    std::cerr << "process: no triad sample combined from all three axes\n";
    return 1;
  }
  return 0;
}

}  // namespace

core::TriadProcessorSettings checkedSettings(const core::ProcessorConfig& processor, const TriadOptions& o) {
  checkProcessorConfig(processor);
  core::TriadProcessorSettings s;
  s.processor = processor;
  s.noise = o.noise;
  s.combiner = o.combiner;
  s.combiner.initial_rate_variance = o.noise.initial_variance;  // the nodes' defaults agree
  try {
    o.noise.validate();
    s.combiner.validate();
  } catch (const core::ConfigError& e) {
    std::string option = e.key();
    if (option == "max_rate" || option == "backward_reset" || option == "forward_jump" || option == "jump_persist") {
      option = "triad_" + option;  // the processors' options have these names
    }
    std::replace(option.begin(), option.end(), '_', '-');
    throw UsageError("--" + option + ": " + e.problem());
  }
  return s;
}

std::array<AxisInput, 3> axisInputs(const TriadOptions& o, const core::TriadParameters& triad) {
  const std::map<std::string, std::string> given = perAxis(o.axis_params, "axis-params");
  checkAxisNames(given, triad.axes, "axis-params");
  std::array<AxisInput, 3> axes;
  for (std::size_t a = 0; a < 3; ++a) {
    const auto it = given.find(triad.axes[a]);
    if (it == given.end()) {
      throw UsageError("--axis-params " + triad.axes[a] + "=FILE missing: each axis's parameter file is needed");
    }
    axes[a].name = triad.axes[a];
    axes[a].parameter_file = it->second;
    axes[a].frame_id = axes[a].name + "_gyro_link";
  }
  return axes;
}

void findAxisTopics(const rosbag::Bag& bag, const TriadOptions& o, std::array<AxisInput, 3>* axes) {
  const std::array<std::string, 3> names{{(*axes)[0].name, (*axes)[1].name, (*axes)[2].name}};
  const std::map<std::string, std::string> channels = perAxis(o.axis_channels, "axis-channels");
  checkAxisNames(channels, names, "axis-channels");
  for (AxisInput& a : *axes) {
    const auto chosen = channels.find(a.name);
    a.topic = axisTopic(bag, a.name, chosen == channels.end() ? std::string() : chosen->second);
  }
  checkDistinctAxisTopics(names, {{(*axes)[0].topic, (*axes)[1].topic, (*axes)[2].topic}});
}

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
  const core::TriadProcessorSettings settings = checkedSettings(processor, o);
  const auto triad = std::make_shared<const core::TriadParameters>(core::loadTriadFile(o.triad_file));
  std::array<AxisInput, 3> axes = axisInputs(o, *triad);
  std::vector<std::string> inputs{bag_path, o.triad_file};
  for (const AxisInput& a : axes) inputs.push_back(a.parameter_file);
  checkOutputPaths(inputs, {out_path, csv_path});
  std::array<core::GyroParameters, 3> parameters;
  for (std::size_t a = 0; a < 3; ++a) parameters[a] = core::loadParameterFile(axes[a].parameter_file);
  const std::unique_ptr<rosbag::Bag> bag = openBag(bag_path);
  findAxisTopics(*bag, o, &axes);

  core::TriadProcessor chain(settings, parameters, triad);
  TriadOutputs outputs(out_path, csv_path, compression, triad->frame_id, axes);
  replayTriad(*bag, axes, &chain, &outputs);
  outputs.commit();
  return summarize(chain, axes);
}

}  // namespace bag_tools
}  // namespace hrg_gyro

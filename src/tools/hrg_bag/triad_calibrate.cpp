#include "triad_calibrate.h"

#include <array>
#include <iostream>
#include <map>
#include <memory>
#include <stdexcept>

#include "bag_tools.h"
#include "hrg_gyro/FixturePosition.h"
#include "hrg_gyro/TurntableState.h"
#include "hrg_gyro/core/calibration/triad_calibration.h"
#include "hrg_gyro/core/calibration/triad_feed.h"
#include "hrg_gyro/core/calibration/triad_result_files.h"
#include "hrg_gyro/core/common/atomic_file.h"
#include "hrg_gyro/core/common/output_directory.h"
#include "hrg_gyro/core/model/parameter_file.h"
#include "hrg_gyro/ros/conversions.h"

namespace hrg_gyro {
namespace bag_tools {
namespace {

/// NAME=VALUE items of a per-axis option, each name given once (whether the names are the triad's
/// axes is checked once the triad file is read: checkAxisNames).
std::map<std::string, std::string> perAxis(const std::vector<std::string>& items, const std::string& option) {
  std::map<std::string, std::string> out;
  for (const std::string& item : items) {
    const std::size_t eq = item.find('=');
    const std::string name = eq == std::string::npos ? std::string() : item.substr(0, eq);
    const std::string value = eq == std::string::npos ? std::string() : item.substr(eq + 1);
    if (name.empty() || value.empty()) {
      throw UsageError("--" + option + " expects NAME=VALUE with NAME an axis of the triad, got '" + item + "'");
    }
    if (!out.emplace(name, value).second) throw UsageError("--" + option + " gives axis " + name + " twice");
  }
  return out;
}

/// Each name of a per-axis option one of the triad's axes.
void checkAxisNames(const std::map<std::string, std::string>& given, const std::array<std::string, 3>& axes,
                    const std::string& option) {
  for (const auto& kv : given) {
    const std::string& name = kv.first;
    if (name != axes[0] && name != axes[1] && name != axes[2]) {
      throw UsageError("--" + option + " " + name + "=" + kv.second + ": '" + name +
                       "' is not an axis of the triad (its axes: " + axes[0] + ", " + axes[1] + ", " + axes[2] + ")");
    }
  }
}

/// Every path against every other before anything is read (core::checkTriadPaths): an output may be
/// its own prior only (--out the --triad file, --axis-out NAME=F the --axis-params NAME=F file),
/// never another input or another output. The axes are the names --axis-params gives; should they
/// not be three, the triad file's names refuse them next, before anything else is read.
void checkPaths(const TriadCalibrateOptions& o, const std::map<std::string, std::string>& params,
                const std::map<std::string, std::string>& outs) {
  std::vector<std::string> outputs{o.out, o.report};
  for (const auto& kv : outs) outputs.push_back(kv.second);
  checkOutputPaths({}, outputs);  // none a directory, none twice
  if (params.size() != 3) return;
  core::TriadResultPaths out_paths, prior_paths;
  out_paths.triad = o.out;
  prior_paths.triad = o.triad;
  std::vector<std::string> unpaired;  // an --axis-out of a name that is no axis: refused with the names
  int slot = 0;
  for (const auto& kv : params) {
    prior_paths.axes[slot] = kv.second;
    out_paths.axes[slot] = outs.at(kv.first);
    ++slot;
  }
  for (const auto& kv : outs) {
    if (!params.count(kv.first)) unpaired.push_back(kv.second);
  }
  unpaired.push_back(o.report);
  try {
    core::checkTriadPaths(out_paths, prior_paths, {o.bag, o.config}, unpaired);
  } catch (const std::runtime_error& e) {
    throw UsageError(std::string("refused: ") + e.what());
  }
}

/// The settings file: the dual-rate settings of the axes' stage, and its `triad` section.
void loadSettings(const std::string& path, core::CalibrationSettings* axis, core::TriadCalibrationSettings* triad) {
  if (path.empty()) return;
  YAML::Node root;
  try {
    root = YAML::Load(core::readBoundedRegularFile(path, core::kMaxParameterFileBytes, "settings file"));
  } catch (const std::runtime_error& e) {  // also YAML::Exception
    throw UsageError("cannot read --config " + path + ": " + e.what());
  }
  try {
    const core::YamlField field(root, "");
    *axis = core::CalibrationSettings::parse(field, {"triad"});
    if (field.has("triad")) *triad = core::TriadCalibrationSettings::parse(field["triad"]);
  } catch (const core::ConfigError& e) {
    throw UsageError("--config " + path + ": " + e.what());
  }
}

std::string topicType(const rosbag::Bag& bag, const std::string& topic) {
  rosbag::View view(bag, rosbag::TopicQuery(topic));
  for (const rosbag::ConnectionInfo* c : view.getConnections()) return c->datatype;
  return std::string();
}

/// `topic`, or else the bag's single topic of `type`; UsageError naming the option otherwise.
std::string findTopic(const rosbag::Bag& bag, const std::string& topic, const std::string& type,
                      const std::string& option) {
  std::map<std::string, std::string> types;
  rosbag::View all(bag);
  for (const rosbag::ConnectionInfo* c : all.getConnections()) types[c->topic] = c->datatype;
  if (!topic.empty()) {
    const auto it = types.find(topic);
    if (it == types.end()) throw UsageError("topic " + topic + " (--" + option + ") is not in the bag");
    if (it->second != type) throw UsageError("topic " + topic + " has type " + it->second + ", expected " + type);
    return topic;
  }
  std::vector<std::string> found;
  for (const auto& kv : types)
    if (kv.second == type) found.push_back(kv.first);
  if (found.size() == 1) return found.front();
  if (found.empty()) {
    throw UsageError("no " + type + " topic in the bag" +
                     (type == ros::message_traits::datatype<FixturePosition>()
                          ? ": a triad session logs the fixture's position (docs/triad.md)"
                          : std::string()));
  }
  throw UsageError("several " + type + " topics in the bag; choose one with --" + option);
}

}  // namespace

int runTriadCalibrate(const TriadCalibrateOptions& o) {
  checkProcessorConfig(o.processor);
  const std::map<std::string, std::string> params = perAxis(o.axis_params, "axis-params");
  std::map<std::string, std::string> outs = perAxis(o.axis_out, "axis-out");
  const std::map<std::string, std::string> channels = perAxis(o.axis_channels, "axis-channels");
  for (const auto& kv : params) {
    // By default each axis's file lies beside the triad file, named after the axis.
    if (!outs.count(kv.first)) outs[kv.first] = core::directoryOf(o.out) + "/" + kv.first + ".yaml";
  }
  checkPaths(o, params, outs);

  const core::TriadParameters prior_triad = [&] {
    if (o.triad.empty()) return core::TriadParameters();
    try {
      return core::loadTriadFile(o.triad);
    } catch (const std::exception& e) {
      throw UsageError("--triad " + o.triad + ": " + e.what());
    }
  }();
  const std::array<std::string, 3>& axes = prior_triad.axes;
  checkAxisNames(params, axes, "axis-params");
  checkAxisNames(outs, axes, "axis-out");
  checkAxisNames(channels, axes, "axis-channels");
  std::array<std::string, 3> channel_topics;
  for (int i = 0; i < 3; ++i) {
    channel_topics[i] = channels.count(axes[i]) ? channels.at(axes[i]) : "/" + axes[i] + "/channels";
  }
  checkDistinctAxisTopics(axes, channel_topics);
  for (const std::string& a : axes) {
    if (!params.count(a)) {
      throw UsageError("--axis-params " + a + "=FILE missing: each axis's prior parameter file is needed (its P is " +
                       "kept, and its latitude places the Earth's rate)");
    }
  }

  core::CalibrationSettings axis_settings;
  core::TriadCalibrationSettings triad_settings;
  loadSettings(o.config, &axis_settings, &triad_settings);
  std::array<core::GyroParameters, 3> prior_axes;
  for (int i = 0; i < 3; ++i) {
    try {
      prior_axes[i] = core::loadParameterFile(params.at(axes[i]));
    } catch (const std::exception& e) {
      throw UsageError("--axis-params " + axes[i] + "=" + params.at(axes[i]) + ": " + e.what());
    }
  }
  for (int i = 1; i < 3; ++i) {
    if (!(prior_axes[i].earth_rate == prior_axes[0].earth_rate)) {
      throw UsageError("the axes' parameter files disagree on the Earth's rate (earth_rate: enabled, latitude): " +
                       axes[0] + " and " + axes[i] + " sit at one site");
    }
  }

  const std::unique_ptr<rosbag::Bag> bag = openBag(o.bag);
  const std::string turntable =
      findTopic(*bag, o.turntable_topic, ros::message_traits::datatype<TurntableState>(), "turntable-topic");
  const std::string fixture =
      findTopic(*bag, o.fixture_topic, ros::message_traits::datatype<FixturePosition>(), "fixture-topic");
  for (int i = 0; i < 3; ++i) {
    const std::string type = topicType(*bag, channel_topics[i]);
    const std::string wanted = ros::message_traits::datatype<ChannelAmplitudes>();
    if (type.empty()) {
      throw UsageError("axis " + axes[i] + ": topic " + channel_topics[i] + " is not in the bag (--axis-channels " +
                       axes[i] + "=TOPIC names another)");
    }
    if (type != wanted) throw UsageError("topic " + channel_topics[i] + " has type " + type + ", expected " + wanted);
  }

  std::array<std::unique_ptr<core::GyroProcessor>, 3> processors;
  for (int i = 0; i < 3; ++i) {
    processors[i] =
        std::make_unique<core::GyroProcessor>(o.processor, std::make_shared<const core::GyroParameters>(prior_axes[i]));
  }
  core::TriadCalibration calibration(axis_settings, triad_settings, prior_axes, prior_triad);
  std::vector<std::string> wanted{channel_topics.begin(), channel_topics.end()};
  wanted.push_back(turntable);
  wanted.push_back(fixture);
  rosbag::View view(*bag, rosbag::TopicQuery(wanted));
  Progress progress("calibrate", view.size());
  std::uint64_t n = 0;
  try {
    for (const rosbag::MessageInstance& m : view) {
      ++n;
      progress.update(n, n);
      const std::string& topic = m.getTopic();
      if (topic == turntable) {
        const TurntableState::ConstPtr t = m.instantiate<TurntableState>();
        if (t) calibration.addTurntable(toNanoseconds(t->header.stamp), t->angle, t->rate, t->header.seq);
        continue;
      }
      if (topic == fixture) {
        const FixturePosition::ConstPtr f = m.instantiate<FixturePosition>();
        if (!f) continue;
        calibration.addFixture(fromMessage(*f));  // checked there: not a rotation, a bad stamp (as live)
        continue;
      }
      for (int i = 0; i < 3; ++i) {
        if (topic != channel_topics[i]) continue;
        const ChannelAmplitudes::ConstPtr c = m.instantiate<ChannelAmplitudes>();
        if (!c) break;
        const core::ChannelSample in = fromMessage(*c);
        const core::ProcessorResult r = processors[i]->process(in);
        if (r.has_wave) calibration.addWave(i, in.stamp, r.wave.theta, in.frequency);
        break;
      }
    }
  } catch (const rosbag::BagException& e) {
    throw UsageError(std::string("bag read error (truncated?): ") + e.what());
  }
  progress.finish(n);

  core::TriadOutcome outcome = calibration.finish();
  outcome.triad.calibration.source = o.bag;
  for (core::CalibrationOutcome& a : outcome.axes) a.parameters.calibration.source = o.bag;
  if (!o.report.empty()) {
    OutputText report(o.report);
    report.stream() << core::emitTriadReport(outcome);
    report.commit();
  }
  std::cout << "calibrate: triad " << (outcome.accepted ? "ACCEPTED" : "REFUSED");
  if (!outcome.accepted) std::cout << ": " << outcome.reason;
  std::cout << "\n";
  for (const core::GateResult& g : outcome.gates) {
    std::cout << "  " << (g.passed ? "pass" : "FAIL") << "  " << g.name << ": " << g.message << "\n";
  }
  for (const std::string& note : outcome.notes) std::cout << "  note: " << note << "\n";
  for (int i = 0; i < 3; ++i) {
    const core::CalibrationOutcome& a = outcome.axes[i];
    std::cout << "calibrate: axis " << axes[i] << " " << (a.accepted ? "accepted" : "refused")
              << ", peak nonlinearity of its K " << a.nonlinearity_ppm << " ppm\n";
  }
  if (outcome.positions_fitted > 0) {
    const Eigen::IOFormat rows(Eigen::StreamPrecision, 0, " ", "\n", "    [", "]");
    std::cout << "calibrate: axis matrix M from " << outcome.positions_fitted << " positions (std in brackets):\n"
              << outcome.triad.axis_to_body.format(rows) << "\n    ("
              << outcome.triad.axis_to_body_std.format(Eigen::IOFormat(3, 0, " ", "; ")) << ")\n";
  }
  if (outcome.bias_estimated) {
    std::cout << "calibrate: body bias " << outcome.triad.bias.transpose() << " rad/s (std "
              << outcome.triad.bias_std.transpose() << ")\n";
  }
  if (!outcome.accepted) {
    std::cout << "calibrate: nothing written\n";
    return 1;
  }
  core::TriadResultPaths paths;
  paths.triad = o.out;
  for (int i = 0; i < 3; ++i) paths.axes[i] = outs.at(axes[i]);
  const std::vector<std::string> set{paths.axes[0], paths.axes[1], paths.axes[2], paths.triad};
  try {
    core::saveTriadResult(outcome, paths);
    for (const std::string& written : set) std::cout << "calibrate: wrote " << written << "\n";
  } catch (const core::BackupNotKept& e) {
    for (const std::string& written : set) std::cout << "calibrate: wrote " << written << "\n";
    throw OutputError(std::string("the calibration was accepted and written, but: ") + e.what());
  } catch (const std::exception& e) {
    throw OutputError(std::string("the calibration was accepted but not written: ") + e.what());
  }
  return 0;
}

}  // namespace bag_tools
}  // namespace hrg_gyro

#include "triad_calibrate.h"

#include <array>
#include <iostream>
#include <map>
#include <memory>
#include <stdexcept>

#include "bag_tools.h"
#include "hrg_gyro/FixturePosition.h"
#include "hrg_gyro/TurntableState.h"
#include "hrg_gyro/core/calibration/triad/triad_calibration.h"
#include "hrg_gyro/core/calibration/triad/triad_result_files.h"
#include "hrg_gyro/core/common/atomic_file.h"
#include "hrg_gyro/core/common/output_directory.h"
#include "hrg_gyro/core/model/parameter_file.h"
#include "hrg_gyro/core/model/triad_file.h"
#include "hrg_gyro/core/processing/triad_processor.h"
#include "hrg_gyro/ros/conversions.h"
#include "read_messages.h"
#include "triad_axis_options.h"

namespace hrg_gyro {
namespace bag_tools {
namespace {

/// The run's inputs once read and checked: the priors and settings, each axis's files and topics.
struct TriadInputs {
  core::TriadParameters prior_triad;
  std::array<core::GyroParameters, 3> prior_axes;
  core::CalibrationSettings axis_settings;
  core::TriadCalibrationSettings triad_settings;
  std::array<std::string, 3> channel_topics, outs;  // in the triad's axis order
  std::string turntable_topic, fixture_topic;
};

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

/// The prior triad file (--triad; "" the nominal triad) and the axes' per-axis options against its
/// axis names: each axis's prior parameter file, output file and channels topic.
void readPriors(const TriadCalibrateOptions& o, TriadInputs* in) {
  const std::map<std::string, std::string> params = perAxis(o.axis_params, "axis-params");
  std::map<std::string, std::string> outs = perAxis(o.axis_out, "axis-out");
  const std::map<std::string, std::string> channels = perAxis(o.axis_channels, "axis-channels");
  for (const auto& kv : params) {
    // By default each axis's file lies beside the triad file, named after the axis.
    if (!outs.count(kv.first)) outs[kv.first] = core::directoryOf(o.out) + "/" + kv.first + ".yaml";
  }
  checkPaths(o, params, outs);
  if (!o.triad.empty()) {
    try {
      in->prior_triad = core::loadTriadFile(o.triad);
    } catch (const std::exception& e) {
      throw UsageError("--triad " + o.triad + ": " + e.what());
    }
  }
  const std::array<std::string, 3>& axes = in->prior_triad.axes;
  checkAxisNames(params, axes, "axis-params");
  checkAxisNames(outs, axes, "axis-out");
  checkAxisNames(channels, axes, "axis-channels");
  for (int i = 0; i < 3; ++i) {
    in->channel_topics[i] = channels.count(axes[i]) ? channels.at(axes[i]) : "/" + axes[i] + "/channels";
  }
  checkDistinctAxisTopics(axes, in->channel_topics);
  for (const std::string& a : axes) {
    if (!params.count(a)) {
      throw UsageError("--axis-params " + a + "=FILE missing: each axis's prior parameter file is needed (its P is " +
                       "kept, and its latitude places the Earth's rate)");
    }
  }
  loadSettings(o.config, &in->axis_settings, &in->triad_settings);
  for (int i = 0; i < 3; ++i) {
    in->outs[i] = outs.at(axes[i]);
    try {
      in->prior_axes[i] = core::loadParameterFile(params.at(axes[i]));
    } catch (const std::exception& e) {
      throw UsageError("--axis-params " + axes[i] + "=" + params.at(axes[i]) + ": " + e.what());
    }
  }
  for (int i = 1; i < 3; ++i) {
    if (!(in->prior_axes[i].earth_rate == in->prior_axes[0].earth_rate)) {
      throw UsageError("the axes' parameter files disagree on the Earth's rate (earth_rate: enabled, latitude): " +
                       axes[0] + " and " + axes[i] + " sit at one site");
    }
  }
}

/// The table's and the fixture's topics, and each axis's channels topic checked in the bag.
void findSessionTopics(const rosbag::Bag& bag, const TriadCalibrateOptions& o, TriadInputs* in) {
  in->turntable_topic =
      findTopic(bag, o.turntable_topic, ros::message_traits::datatype<TurntableState>(), "turntable-topic", true);
  in->fixture_topic = findTopic(bag, o.fixture_topic, ros::message_traits::datatype<FixturePosition>(), "fixture-topic",
                                true, ": a triad session logs the fixture's position (docs/triad.md)");
  const std::string wanted = ros::message_traits::datatype<ChannelAmplitudes>();
  for (int i = 0; i < 3; ++i) {
    const std::string& topic = in->channel_topics[i];
    rosbag::View view(bag, rosbag::TopicQuery(topic));
    std::string type;
    for (const rosbag::ConnectionInfo* c : view.getConnections()) type = c->datatype;
    const std::string& axis = in->prior_triad.axes[i];
    if (type.empty()) {
      throw UsageError("axis " + axis + ": topic " + topic + " is not in the bag (--axis-channels " + axis +
                       "=TOPIC names another)");
    }
    if (type != wanted) throw UsageError("topic " + topic + " has type " + type + ", expected " + wanted);
  }
}

/// The bag's table, fixture and channels (each axis's through its processor) into the calibration,
/// in record order; its outcome.
core::TriadOutcome calibrate(const rosbag::Bag& bag, const TriadCalibrateOptions& o, const TriadInputs& in) {
  core::TriadProcessor processors(o.processor, in.prior_axes);
  core::TriadCalibration calibration(in.axis_settings, in.triad_settings, in.prior_axes, in.prior_triad);
  std::vector<std::string> wanted{in.channel_topics.begin(), in.channel_topics.end()};
  wanted.push_back(in.turntable_topic);
  wanted.push_back(in.fixture_topic);
  rosbag::View view(bag, rosbag::TopicQuery(wanted));
  Progress progress("calibrate", view.size());
  core::ProcessorResult r;
  const std::uint64_t n = readMessages(view, progress, [&](const rosbag::MessageInstance& m) {
    const std::string& topic = m.getTopic();
    if (topic == in.turntable_topic) {
      const TurntableState::ConstPtr t = m.instantiate<TurntableState>();
      if (t) calibration.addTurntable(toNanoseconds(t->header.stamp), t->angle, t->rate, t->header.seq);
      return;
    }
    if (topic == in.fixture_topic) {
      const FixturePosition::ConstPtr f = m.instantiate<FixturePosition>();
      if (f) calibration.addFixture(fromMessage(*f));  // checked there: not a rotation, a bad stamp (as live)
      return;
    }
    for (std::size_t i = 0; i < 3; ++i) {
      if (topic != in.channel_topics[i]) continue;
      const ChannelAmplitudes::ConstPtr c = m.instantiate<ChannelAmplitudes>();
      if (!c) return;
      const core::ChannelSample sample = fromMessage(*c);
      processors.process(i, sample, &r);
      if (r.has_wave) calibration.addWave(static_cast<int>(i), sample.stamp, r.wave.theta, sample.frequency);
      return;
    }
  });
  progress.finish(n);
  core::TriadOutcome outcome = calibration.finish();
  outcome.triad.calibration.source = o.bag;
  for (core::CalibrationOutcome& a : outcome.axes) a.parameters.calibration.source = o.bag;
  return outcome;
}

/// The verdict, the gates and notes, each axis, M and the bias on stdout.
void printOutcome(const core::TriadOutcome& outcome) {
  std::cout << "calibrate: triad " << (outcome.accepted ? "ACCEPTED" : "REFUSED");
  if (!outcome.accepted) std::cout << ": " << outcome.reason;
  std::cout << "\n";
  for (const core::GateResult& g : outcome.gates) {
    std::cout << "  " << (g.passed ? "pass" : "FAIL") << "  " << g.name << ": " << g.message << "\n";
  }
  for (const std::string& note : outcome.notes) std::cout << "  note: " << note << "\n";
  for (int i = 0; i < 3; ++i) {
    const core::CalibrationOutcome& a = outcome.axes[i];
    std::cout << "calibrate: axis " << outcome.axis_names[i] << " " << (a.accepted ? "accepted" : "refused")
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
}

/// The axes' files and the triad file written as one set.
void writeResult(const core::TriadOutcome& outcome, const TriadCalibrateOptions& o, const TriadInputs& in) {
  core::TriadResultPaths paths;
  paths.triad = o.out;
  paths.axes = in.outs;
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
}

}  // namespace

int runTriadCalibrate(const TriadCalibrateOptions& o) {
  checkProcessorConfig(o.processor);
  TriadInputs in;
  readPriors(o, &in);
  const std::unique_ptr<rosbag::Bag> bag = openBag(o.bag);
  findSessionTopics(*bag, o, &in);
  const core::TriadOutcome outcome = calibrate(*bag, o, in);
  if (!o.report.empty()) {
    OutputText report(o.report);
    report.stream() << core::emitTriadReport(outcome);
    report.commit();
  }
  printOutcome(outcome);
  if (!outcome.accepted) {
    std::cout << "calibrate: nothing written\n";
    return 1;
  }
  writeResult(outcome, o, in);
  return 0;
}

}  // namespace bag_tools
}  // namespace hrg_gyro

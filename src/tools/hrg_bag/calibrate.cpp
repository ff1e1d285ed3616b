// hrg_bag calibrate: the calibrator offline -- the processor and the calibration session of the
// live nodes, fed from the bag in record order, with the same quality gates.
#include <iostream>
#include <memory>
#include <stdexcept>

#include "../cli_checks.h"
#include "bag_tools.h"
#include "hrg_gyro/GroundTruth.h"
#include "hrg_gyro/TurntableState.h"
#include "hrg_gyro/core/calibration/calibration_feed.h"
#include "hrg_gyro/core/calibration/calibration_session.h"
#include "hrg_gyro/core/common/atomic_file.h"
#include "hrg_gyro/core/model/parameter_file.h"
#include "hrg_gyro/ros/conversions.h"
#include "read_messages.h"
#include "triad_calibrate.h"

namespace hrg_gyro {

namespace {

struct CalibrateOptions {
  std::string bag, method, params, out, report, plot, config;
  bag_tools::GyroTopics topics;
  core::ProcessorConfig processor;
  bag_tools::TriadCalibrateOptions triad;  // --method triad: its own inputs
};

/// The method asked for: --method, else --config's, else the default.
core::CalibrationMethodKind chosenMethod(const CalibrateOptions& o) {
  if (!o.method.empty()) return core::parseCalibrationMethod(o.method);
  if (o.config.empty()) return core::CalibrationSettings().method;
  try {
    const YAML::Node root =
        YAML::Load(core::readBoundedRegularFile(o.config, core::kMaxParameterFileBytes, "settings file"));
    if (root.IsMap() && root["method"] && root["method"].IsScalar())
      return core::parseCalibrationMethod(root["method"].as<std::string>());
  } catch (const std::exception&) {
    // read and reported with the rest of the settings below
  }
  return core::CalibrationSettings().method;
}

int runTriad(const CalibrateOptions& o) {
  using namespace bag_tools;
  if (!o.params.empty()) {
    throw UsageError("--method triad takes each axis's prior with --axis-params NAME=FILE, not --params");
  }
  if (!o.topics.channels.empty() || !o.topics.truth.empty()) {
    throw UsageError(
        "--method triad: each axis's channels are /NAME/channels (--axis-channels NAME=TOPIC), "
        "and no generator reference is used");
  }
  if (!o.plot.empty()) {
    throw UsageError("--plot draws a single axis's report; the triad's report is drawn by hrg_bag report");
  }
  TriadCalibrateOptions t = o.triad;
  t.bag = o.bag;
  t.out = o.out;
  t.report = o.report;
  t.config = o.config;
  t.turntable_topic = o.topics.turntable;
  t.processor = o.processor;
  return runTriadCalibrate(t);
}

/// Before anything is read: the triad's options refused, the processor's limits, the outputs.
void checkSingleAxisUsage(const CalibrateOptions& o) {
  using namespace bag_tools;
  const bool triad_options = !o.triad.triad.empty() || !o.triad.axis_params.empty() || !o.triad.axis_out.empty() ||
                             !o.triad.axis_channels.empty() || !o.triad.fixture_topic.empty();
  if (triad_options) {
    throw UsageError("--triad, --axis-params, --axis-out, --axis-channels and --fixture-topic are for --method triad");
  }
  checkProcessorConfig(o.processor);
  // --out may be the prior itself (--params X --out X): the prior is read whole before anything
  // else and replaced only by an accepted calibration, keeping the old file as X.bak, as the live
  // calibrator refreshes its parameter file. The report and the plot may never replace it.
  checkOutputPaths({o.bag, o.config}, {o.out, o.report, o.plot});
  checkOutputPaths({o.params}, {o.report, o.plot});
}

/// The calibrator's settings: --config's, through the node's own parser, and --method over its method.
core::CalibrationSettings readSettings(const CalibrateOptions& o) {
  using bag_tools::UsageError;
  core::CalibrationSettings settings;
  if (!o.config.empty()) {
    YAML::Node root;
    try {
      // Bounded like a parameter file, and never a FIFO or a device (which would block or never end).
      root = YAML::Load(core::readBoundedRegularFile(o.config, core::kMaxParameterFileBytes, "settings file"));
    } catch (const std::runtime_error& e) {  // also YAML::Exception
      throw UsageError("cannot read --config " + o.config + ": " + e.what());
    }
    try {
      settings = core::CalibrationSettings::parse(core::YamlField(root, ""));
    } catch (const core::ConfigError& e) {
      throw UsageError("--config " + o.config + ": " + e.what());
    }
  }
  if (!o.method.empty()) settings.method = core::parseCalibrationMethod(o.method);  // checked by --method's validator
  return settings;
}

/// The bag's records, in record order, through the calibrator's record switch (channels through
/// `processor`) into `session`.
void feedBag(rosbag::Bag& bag, const bag_tools::GyroTopics& topics, const core::CalibrationMethodTraits& method,
             core::GyroProcessor& processor, core::CalibrationSession& session) {
  using namespace bag_tools;
  std::vector<std::string> wanted{topics.channels};
  // The field method synchronises with the precession loop's state in place of the table's.
  if (method.virtual_rotation) {
    wanted.push_back(topics.precession);
  } else if (!topics.turntable.empty()) {
    wanted.push_back(topics.turntable);
  }
  if (!topics.truth.empty()) wanted.push_back(topics.truth);
  rosbag::View view(bag, rosbag::TopicQuery(wanted));
  Progress progress("calibrate", view.size());
  core::CalibrationFeed feed(&session, &processor);
  PrecessionStateReader precession_reader;  // also a bag recorded before PrecessionState.source
  PrecessionState precession;
  const std::uint64_t n = readMessages(view, progress, [&](const rosbag::MessageInstance& m) {
    const std::string& topic = m.getTopic();
    if (topic == topics.channels) {
      const ChannelAmplitudes::ConstPtr c = m.instantiate<ChannelAmplitudes>();
      if (c) feed.addChannels(fromMessage(*c));
    } else if (topic == topics.precession) {
      if (precession_reader.read(m, &precession)) {
        feed.addPrecessionState(toNanoseconds(precession.header.stamp), precession.angle, precession.rate,
                                precession.header.seq);
      }
    } else if (topic == topics.turntable) {
      const TurntableState::ConstPtr t = m.instantiate<TurntableState>();
      if (t) feed.addTableState(toNanoseconds(t->header.stamp), t->angle, t->rate, t->header.seq);
    } else {
      const GroundTruth::ConstPtr g = m.instantiate<GroundTruth>();
      if (!g) return;
      if (g->generator) {
        feed.addReference(toNanoseconds(g->header.stamp), {g->amplitude, g->quadrature, g->theta, g->phase});
      } else {
        feed.addSweepEnd(toNanoseconds(g->header.stamp));
      }
    }
  });
  progress.finish(n);
}

/// The verdict, the gates, the notes, what the rotation stream held and the diagnosis, on stdout.
void printOutcome(const core::CalibrationOutcome& outcome) {
  std::cout << "calibrate: " << core::nameOf(outcome.method) << " " << (outcome.accepted ? "ACCEPTED" : "REFUSED");
  if (!outcome.accepted) std::cout << ": " << outcome.reason;
  std::cout << "\n";
  for (const core::GateResult& g : outcome.gates) {
    std::cout << "  " << (g.passed ? "pass" : "FAIL") << "  " << g.name << ": " << g.message << "\n";
  }
  for (const std::string& note : outcome.notes) std::cout << "  note: " << note << "\n";
  const core::RotationRecordRejects& r = outcome.rotation_rejected;
  // A field run's table stream is the precession loop's state.
  std::cout << "calibrate: "
            << (core::traitsOf(outcome.method).virtual_rotation ? "precession states " : "turntable records ")
            << outcome.rotation_records << ", dropped " << r.total() << " (bad rate " << r.bad_rate << ", bad angle "
            << r.bad_angle << ", zero stamp " << r.bad_stamp << ", duplicate " << r.duplicate << ", out of order "
            << r.out_of_order << ", stamp jump " << r.stamp_jump << "), restarts " << outcome.restarts << "\n";
  for (const core::DefectDiagnosis& d : outcome.diagnosis) {
    std::cout << "calibrate: root-cause diagnosis (first order, read against the P in force) " << core::describe(d);
  }
}

/// The parameter file, written when the calibration is accepted (and said either way).
void writeParameters(const CalibrateOptions& o, const core::CalibrationOutcome& outcome) {
  if (!outcome.accepted) {
    std::cout << "calibrate: " << o.out << " not written\n";
    return;
  }
  try {
    core::saveParameterFile(o.out, outcome.parameters);
  } catch (const std::exception& e) {
    throw bag_tools::OutputError(std::string("the calibration was accepted but not written: ") + e.what());
  }
  if (outcome.scale_factor.empty()) {
    std::cout << "calibrate: wrote " << o.out << " (D refreshed, K kept from " << o.params << ")\n";
  } else {
    std::cout << "calibrate: wrote " << o.out << " (peak nonlinearity of the new K: " << outcome.nonlinearity_ppm
              << " ppm)\n";
  }
}

int runCalibrate(const CalibrateOptions& o) {
  using namespace bag_tools;
  if (chosenMethod(o) == core::CalibrationMethodKind::kTriad) return runTriad(o);
  checkSingleAxisUsage(o);
  const core::CalibrationSettings settings = readSettings(o);
  const core::CalibrationMethodTraits& method = core::traitsOf(settings.method);
  if (settings.method == core::CalibrationMethodKind::kField && o.params.empty()) {
    // The field method keeps K and the latitude from its prior: the nominal one would be written back
    // as if a table had calibrated it.
    throw UsageError(
        "--method field needs --params: the table-calibrated file whose K it keeps and whose D it "
        "refreshes");
  }
  const auto prior = std::make_shared<const core::GyroParameters>(o.params.empty() ? core::GyroParameters()
                                                                                   : core::loadParameterFile(o.params));
  const std::unique_ptr<rosbag::Bag> bag = openBag(o.bag);
  const GyroTopics topics = findTopics(*bag, o.topics, true, method.needs_turntable,
                                       method.virtual_rotation ? TopicNeed::kRequired : TopicNeed::kNo);
  if (method.uses_generator_pairs && topics.truth.empty()) {
    throw UsageError(std::string(method.name) + " needs the generator reference (a GroundTruth topic)");
  }
  core::GyroProcessor processor(o.processor, prior);
  core::CalibrationSession session(settings, *prior);
  feedBag(*bag, topics, method, processor, session);
  core::CalibrationOutcome outcome = session.finish();
  outcome.parameters.calibration.source = o.bag;
  if (!o.report.empty()) {
    OutputText report(o.report);
    report.stream() << core::emitCalibrationReport(outcome);
    report.commit();
  }
  printOutcome(outcome);
  writeParameters(o, outcome);
  if (!o.plot.empty()) plot("calibration", o.report, o.plot);
  return outcome.accepted ? 0 : 1;
}

/// --method: the calibrator's methods, checked against the core's list.
CLI::Validator knownMethod() {
  return CLI::Validator(
      [](std::string& m) -> std::string {
        try {
          core::parseCalibrationMethod(m);
          return "";
        } catch (const std::invalid_argument& e) {
          return e.what();
        }
      },
      "");
}

/// BAG, --method, the outputs, the prior and the settings; the topics and the processor's limits.
void addRunOptions(CLI::App& cmd, CalibrateOptions* o) {
  using namespace bag_tools;
  cmd.add_option("BAG", o->bag,
                 "input bag: channels, turntable state or, for field, the precession state (and the generator "
                 "reference)")
      ->required();
  cmd.add_option("--method", o->method,
                 core::calibrationMethodNames("|") + " (default: --config's, else " +
                     core::nameOf(core::CalibrationSettings().method) + ")")
      ->check(knownMethod());
  cmd.add_option("--out", o->out,
                 "calibrated parameter file (triad: the triad file), written atomically only when every gate passes")
      ->required()
      ->check(tools::notEmpty());
  cmd.add_option("--params", o->params,
                 "prior parameter file (default: the nominal model at latitude 0; required by --method field)")
      ->check(tools::notEmpty());
  cmd.add_option("--config", o->config,
                 "calibrator settings (YAML: bins, window, gates/..., thermal/..., as the node's)")
      ->check(tools::notEmpty());
  CLI::Option* report =
      cmd.add_option("--report", o->report, "calibration report (YAML), written either way")->check(tools::notEmpty());
  cmd.add_option("--plot", o->plot, "PNG drawn from the report")->needs(report)->check(tools::notEmpty());
  addTopicOptions(cmd, &o->topics, true);
  cmd.add_option("--precession-topic", o->topics.precession,
                 "field: the precession loop's hrg_gyro/PrecessionState topic (default: the only one in the bag)")
      ->check(tools::notEmpty());
  addProcessorOptions(cmd, &o->processor);
}

/// --method triad's own inputs.
void addTriadOptions(CLI::App& cmd, bag_tools::TriadCalibrateOptions* t) {
  cmd.add_option("--triad", t->triad, "triad: prior triad file (axis names and order, frame_id; default nominal)")
      ->check(tools::notEmpty());
  cmd.add_option("--axis-params", t->axis_params, "triad: NAME=FILE, each axis's prior parameter file (all three)");
  cmd.add_option("--axis-out", t->axis_out,
                 "triad: NAME=FILE, each axis's calibrated parameter file (default: NAME.yaml beside --out)");
  cmd.add_option("--axis-channels", t->axis_channels, "triad: NAME=TOPIC, an axis's channels (default /NAME/channels)");
  cmd.add_option("--fixture-topic", t->fixture_topic,
                 "triad: the fixture's positions (hrg_gyro/FixturePosition; default: the bag's single one)")
      ->check(bag_tools::topicName());
}

constexpr const char* kCalibrateFooter =
    "Processes the bag's channels with the prior parameters and runs the calibrator's method with its\n"
    "quality gates on the turntable plateaus. Thermal writes K and D as splines over the resonator\n"
    "frequency (the bag's channels must carry it).\n"
    "Field (docs/field_calibration.md): a still gyro whose precession loop turned the wave both ways; reads\n"
    "the loop's state (hrg_gyro/PrecessionState) in place of the table, refreshes D(theta) and keeps K.\n"
    "Triad (docs/triad.md): each axis's channels through its own processor, the table and the fixture's\n"
    "positions; writes each axis's parameter file and the triad file as one set: all four written,\n"
    "synced and read back before the first is replaced, none replaced on a failure.\n"
    "Every output replaces its path only when complete; an output that is the same file as an input\n"
    "or another output is refused before anything runs, but for --out naming the --params file (triad:\n"
    "--out the --triad file, --axis-out NAME=F the --axis-params NAME=F file): the prior is then\n"
    "refreshed in place when the calibration is accepted (the old file kept as .bak).\n"
    "Exit 0 accepted, 1 refused by a gate, 2 bad usage or unreadable input, 3 an output could not\n"
    "be written (nothing left at its path, an existing file unchanged).";

}  // namespace

namespace bag_tools {

Command addCalibrateCommand(CLI::App& root) {
  auto o = std::make_shared<CalibrateOptions>();
  CLI::App* cmd = root.add_subcommand("calibrate", "the calibrator offline, with its quality gates");
  addRunOptions(*cmd, o.get());
  addTriadOptions(*cmd, &o->triad);
  cmd->footer(kCalibrateFooter);
  return [o] { return runCalibrate(*o); };
}

}  // namespace bag_tools

}  // namespace hrg_gyro

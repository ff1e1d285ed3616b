// hrg_bag calibrate: the calibrator offline -- the processor and the calibration session of the
// live nodes, fed from the bag in record order, with the same quality gates.
#include <fstream>
#include <iostream>
#include <map>
#include <memory>

#include "bag_tools.h"
#include "hrg_gyro/GroundTruth.h"
#include "hrg_gyro/TurntableState.h"
#include "hrg_gyro/core/calibration_session.h"
#include "hrg_gyro/core/parameter_file.h"
#include "hrg_gyro/ros/conversions.h"

namespace hrg_gyro {

int calibrateCommand(int argc, char** argv) {
  using namespace bag_tools;
  std::vector<std::string> valued{"method", "params", "out", "report", "plot", "config", "channels-topic",
                                  "turntable-topic", "truth-topic"};
  valued.insert(valued.end(), kProcessorOptions.begin(), kProcessorOptions.end());
  const Args args(argc, argv, valued, {});
  if (args.help() || args.positional().size() != 1) {
    std::cout << "usage: hrg_bag calibrate BAG --method dual_rate|constant_rate|step|correction_matrix|thermal --out OUT.yaml\n"
                 "       [--params IN.yaml] [--config SETTINGS.yaml] [--report REPORT.yaml] [--plot OUT.png]\n"
                 "Processes the bag's channels with IN.yaml (default: the nominal model at latitude 0) and runs\n"
                 "the calibrator's method with its quality gates on the turntable plateaus. SETTINGS.yaml holds\n"
                 "calibrator parameters (bins, window, gates/..., thermal/..., as the node's). OUT.yaml is written\n"
                 "atomically only when every gate passes; thermal writes K and D as splines over the resonator\n"
                 "frequency (the bag's channels must carry it). Exit 0 accepted, 1 refused, 2 bad input.\n";
    return args.help() ? 0 : 2;
  }
  core::CalibrationSettings settings;
  if (args.has("config")) {
    YAML::Node root;
    try {
      root = YAML::LoadFile(args.get("config"));
    } catch (const YAML::Exception& e) {
      throw UsageError("cannot read --config " + args.get("config") + ": " + e.what());
    }
    settings = core::CalibrationSettings::parse(core::YamlField(root, ""));
  }
  settings.method = args.get("method", settings.method);
  if (!core::CalibrationSettings::knownMethod(settings.method)) throw UsageError("unknown --method " + settings.method);
  const std::string out_path = args.require("out");
  const auto prior = std::make_shared<const core::GyroParameters>(
      args.has("params") ? core::loadParameterFile(args.get("params")) : core::GyroParameters());
  const std::unique_ptr<rosbag::Bag> bag = openBag(args.positional()[0]);
  const GyroTopics topics = findTopics(*bag, args, true, settings.method != "correction_matrix");
  if (settings.method == "correction_matrix" && topics.truth.empty()) {
    throw UsageError("the correction matrix needs the generator reference (a GroundTruth topic)");
  }

  core::GyroProcessor processor(processorConfig(args), prior);
  core::CalibrationSession session(settings, *prior);
  std::map<core::Nanoseconds, core::ChannelVector> raw;
  std::vector<std::string> wanted{topics.channels};
  if (!topics.turntable.empty()) wanted.push_back(topics.turntable);
  if (!topics.truth.empty()) wanted.push_back(topics.truth);
  rosbag::View view(*bag, rosbag::TopicQuery(wanted));
  Progress progress("calibrate", view.size());
  std::uint64_t n = 0;
  try {
    for (const rosbag::MessageInstance& m : view) {
      ++n;
      progress.update(n, n);
      if (m.getTopic() == topics.channels) {
        const ChannelAmplitudes::ConstPtr c = m.instantiate<ChannelAmplitudes>();
        if (!c) continue;
        const core::ChannelSample in = fromMessage(*c);
        if (settings.method == "correction_matrix") {
          raw[in.stamp] = in.z;
          continue;
        }
        const core::ProcessorResult r = processor.process(in);
        if (r.has_wave) session.addWave(in.stamp, r.wave.theta, in.frequency, r.wave.quadrature / r.wave.amplitude);
      } else if (m.getTopic() == topics.turntable) {
        const TurntableState::ConstPtr t = m.instantiate<TurntableState>();
        if (t) session.addTurntable(toNanoseconds(t->header.stamp), t->angle, t->rate);
      } else {
        const GroundTruth::ConstPtr g = m.instantiate<GroundTruth>();
        if (!g || !g->generator) continue;
        const core::Nanoseconds t = toNanoseconds(g->header.stamp);
        const auto it = raw.find(t);
        if (it == raw.end()) continue;
        session.addGeneratorPair(t, it->second, core::idealChannels({g->amplitude, g->quadrature, g->theta, g->phase}));
        raw.erase(raw.begin(), std::next(it));
      }
    }
  } catch (const rosbag::BagException& e) {
    throw UsageError(std::string("bag read error (truncated?): ") + e.what());
  }
  progress.finish(n);
  core::CalibrationOutcome o = session.finish();
  o.parameters.calibration.source = args.positional()[0];
  if (args.has("report")) {
    std::ofstream report(args.get("report"));
    report << core::emitCalibrationReport(o);
    if (!report) throw UsageError("cannot write " + args.get("report"));
  }
  std::cout << "calibrate: " << o.method << " " << (o.accepted ? "ACCEPTED" : "REFUSED");
  if (!o.accepted) std::cout << ": " << o.reason;
  std::cout << "\n";
  for (const core::GateResult& g : o.gates) {
    std::cout << "  " << (g.passed ? "pass" : "FAIL") << "  " << g.name << ": " << g.message << "\n";
  }
  for (const std::string& note : o.notes) std::cout << "  note: " << note << "\n";
  for (const core::DefectDiagnosis& d : o.diagnosis) {
    std::cout << "calibrate: root-cause diagnosis (first order, read against the P in force) " << core::describe(d);
  }
  if (o.accepted) {
    core::saveParameterFile(out_path, o.parameters);
    std::cout << "calibrate: wrote " << out_path << " (peak nonlinearity of the new K: " << o.nonlinearity_ppm
              << " ppm)\n";
  } else {
    std::cout << "calibrate: " << out_path << " not written\n";
  }
  if (args.has("plot")) {
    if (!args.has("report")) throw UsageError("--plot needs --report (the plot is drawn from the report)");
    if (runPlotter({"calibration", args.get("report"), args.get("plot")}) != 0) {
      std::cerr << "calibrate: plotting failed (is python3-matplotlib installed?)\n";
    }
  }
  return o.accepted ? 0 : 1;
}

}  // namespace hrg_gyro

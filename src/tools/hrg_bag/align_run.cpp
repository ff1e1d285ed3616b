#include "align_run.h"

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>
#include <stdexcept>

#include "../cli_checks.h"
#include "hrg_gyro/core/common/atomic_file.h"

namespace hrg_gyro {
namespace bag_tools {
namespace {

/// Whether a number read back is the one written (12 significant digits, NaN for NaN).
bool sameNumber(double written, double read) {
  if (std::isnan(written) || std::isnan(read)) return std::isnan(written) && std::isnan(read);
  return std::abs(written - read) <= 1e-10 * std::max(1.0, std::abs(written));
}

void checkReadBack(const YAML::Node& doc, const core::AlignmentResult& result,
                   const std::vector<WindowResult>& windows) {
  if (doc["accepted"].as<bool>() != result.accepted || doc["gate"].as<std::string>() != result.gate ||
      !sameNumber(result.heading, doc["heading_deg"].as<double>()) ||
      !sameNumber(result.heading_sigma, doc["heading_sigma_deg"].as<double>())) {
    throw std::runtime_error("the result does not read back as written");
  }
  const YAML::Node w = doc["windows"];
  if (!w.IsSequence() || w.size() != windows.size()) throw std::runtime_error("the windows do not read back");
  for (std::size_t i = 0; i < windows.size(); ++i) {
    if (!sameNumber(windows[i].result.heading, w[i]["heading_deg"].as<double>()) ||
        !sameNumber(windows[i].seconds, w[i]["window_s"].as<double>())) {
      throw std::runtime_error("window " + std::to_string(i) + " does not read back as written");
    }
  }
}

}  // namespace

void addAlignOptions(CLI::App& cmd, AlignOptions* o) {
  cmd.add_option("BAG", o->bag,
                 "input bag: the triad's output (or its axes' channels with --triad), the indexer's state, the "
                 "accelerometer")
      ->required()
      ->check(tools::notEmpty());
  cmd.add_option("--settings", o->settings,
                 "alignment settings (YAML: mode, latitude, duration, noise/..., level/..., indexer/..., as the "
                 "gyrocompass node's parameters)")
      ->required()
      ->check(tools::notEmpty());
  cmd.add_option("--duration", o->duration, "s of gyro stamps in the window (default: the settings' duration)")
      ->transform(tools::finiteNumber())
      ->check(tools::above(0.0));
  cmd.add_option("--start", o->start, "s of gyro stamps skipped from the bag's first gyro sample (default 0)")
      ->transform(tools::finiteNumber())
      ->check(CLI::NonNegativeNumber);
  cmd.add_option("--output", o->output,
                 "the result (YAML), written atomically, read back before it replaces the path; written also "
                 "when refused")
      ->check(tools::notEmpty());
  cmd.add_option("--windows", o->windows,
                 "S1,S2,...: also solve the window's first S1, S2, ... s alone (the heading against window length, "
                 "under `windows` of --output)")
      ->check(tools::notEmpty());
  cmd.add_option("--scan", o->scan,
                 "S: consecutive windows of --duration every S s from --start until the bag ends, each aligned "
                 "alone (the quiet stretches of a long log, and how the windows agree); --output then writes the "
                 "scan")
      ->transform(tools::finiteNumber())
      ->check(tools::above(0.0));
  const std::string group = "Topics (default: the bag's single topic of the type)";
  cmd.add_option("--triad-topic", o->triad_topic, "hrg_gyro/TriadOutput, the triad's body samples")
      ->check(tools::notEmpty())
      ->group(group);
  cmd.add_option("--gyro-topic", o->gyro_topic, "hrg_gyro/GyroOutput, one gyro's outputs (single_gyro)")
      ->check(tools::notEmpty())
      ->group(group);
  cmd.add_option("--turntable-topic", o->turntable_topic, "hrg_gyro/TurntableState, the indexer (mode indexed)")
      ->check(tools::notEmpty())
      ->group(group);
  cmd.add_option("--imu-topic", o->imu_topic,
                 "sensor_msgs/Imu as the gyros (any IMU: gyro_input imu, its imu/ settings; default with gyro_input "
                 "imu: the one ending in imu/data_raw); its linear_acceleration the level unless imu/accelerometer "
                 "false")
      ->check(tools::notEmpty())
      ->group(group);
  cmd.add_option("--accelerometer-topic", o->accelerometer_topic,
                 "sensor_msgs/Imu of the accelerometer (level/source accelerometer; default: the one ending in "
                 "accel/data_raw)")
      ->check(tools::notEmpty())
      ->group(group);
}

std::vector<double> parseWindows(const std::string& text, double duration) {
  std::vector<double> windows;
  if (text.empty()) return windows;
  std::stringstream items(text);
  std::string item;
  while (std::getline(items, item, ',')) {
    std::string canonical = item;
    const std::string problem = tools::finiteNumber()(canonical);
    if (!problem.empty()) throw std::invalid_argument("'" + item + "': " + problem);
    const double s = std::stod(canonical);
    if (!(s > 0.0)) throw std::invalid_argument("'" + item + "': a window must be longer than 0 s");
    if (s > duration) {
      throw std::invalid_argument("'" + item + "': longer than the window (" + tools::shortest(duration) +
                                  " s, --duration or the settings' duration)");
    }
    if (!windows.empty() && !(s > windows.back())) {
      throw std::invalid_argument("'" + item + "': the windows must be given in ascending order, each once");
    }
    windows.push_back(s);
  }
  if (text.back() == ',') throw std::invalid_argument("'" + text + "' ends in a comma");
  return windows;
}

AlignmentRun::AlignmentRun(const core::AlignmentSettings& settings, const std::vector<double>& windows,
                           const core::TriadParameters& triad) {
  compasses_.emplace_back(settings, triad);
  for (double seconds : windows) {
    core::AlignmentSettings shorter = settings;
    shorter.duration = seconds;
    compasses_.emplace_back(shorter, triad);
  }
}

void AlignmentRun::addTriad(const core::TriadBodySample& sample) {
  for (core::Gyrocompass& g : compasses_) g.addTriad(sample);
}
void AlignmentRun::addAxis(const core::AxisOutput& output) {
  for (core::Gyrocompass& g : compasses_) g.addAxis(output);
}
void AlignmentRun::addSweepAxis(std::size_t axis, const core::AxisOutput& output) {
  for (core::Gyrocompass& g : compasses_) g.addSweepAxis(axis, output);
}
void AlignmentRun::addPrecession(std::size_t axis, const core::PrecessionStateRecord& record) {
  for (core::Gyrocompass& g : compasses_) g.addPrecession(axis, record);
}
void AlignmentRun::addIndexer(const core::IndexerRecord& record) {
  for (core::Gyrocompass& g : compasses_) g.addIndexer(record);
}
void AlignmentRun::addAccelerometer(const core::AccelerometerRecord& record) {
  for (core::Gyrocompass& g : compasses_) g.addAccelerometer(record);
}

bool AlignmentRun::complete() const {
  return std::all_of(compasses_.begin(), compasses_.end(), [](const core::Gyrocompass& g) { return g.complete(); });
}

void AlignmentRun::inputEnded(const std::string& input) {
  for (core::Gyrocompass& g : compasses_) {
    if (g.complete()) continue;
    const core::AlignmentProgress p = g.progress();
    char reason[256];
    std::snprintf(reason, sizeof reason, "%s ended after %.3f s of gyro stamps, short of the %.3f s window",
                  input.c_str(), p.seconds, p.duration);
    g.abort(reason);
  }
}

std::vector<WindowResult> AlignmentRun::finishWindows() const {
  std::vector<WindowResult> out;
  for (std::size_t i = 1; i < compasses_.size(); ++i) {
    out.push_back(WindowResult{compasses_[i].settings().duration, compasses_[i].finish()});
  }
  return out;
}

std::string emitAlignmentRun(const core::AlignmentResult& result, const std::vector<WindowResult>& windows,
                             const std::string& bag, const std::string& settings) {
  // The inputs and the windows after the result's own document, through yaml-cpp's emitter (quoting,
  // .nan, every double to the digits that read back the same).
  YAML::Emitter e;
  e << YAML::BeginMap << YAML::Key << "input" << YAML::Value << YAML::Flow << YAML::BeginMap << YAML::Key << "bag"
    << YAML::Value << YAML::DoubleQuoted << bag << YAML::Key << "settings" << YAML::Value << YAML::DoubleQuoted
    << settings << YAML::EndMap;
  e << YAML::Key << "windows" << YAML::Value << YAML::BeginSeq;
  for (const WindowResult& w : windows) {
    const core::AlignmentResult& r = w.result;
    e << YAML::Flow << YAML::BeginMap << YAML::Key << "window_s" << YAML::Value << w.seconds << YAML::Key << "accepted"
      << YAML::Value << r.accepted << YAML::Key << "gate" << YAML::Value << YAML::DoubleQuoted << r.gate << YAML::Key
      << "seconds" << YAML::Value << r.seconds << YAML::Key << "heading_deg" << YAML::Value << r.heading << YAML::Key
      << "heading_sigma_deg" << YAML::Value << r.heading_sigma << YAML::Key << "noise_rad" << YAML::Value
      << r.budget.noise << YAML::Key << "total_rad" << YAML::Value << r.budget.total << YAML::EndMap;
  }
  e << YAML::EndSeq << YAML::EndMap;
  if (!e.good()) throw std::runtime_error("YAML emitter error: " + e.GetLastError());
  return core::emitAlignmentResult(result) +
         "# input: the bag and settings aligned. windows: the window's first window_s seconds solved alone\n"
         "# (--windows), the heading against window length: heading deg with its 1 sigma, the budget's noise\n"
         "# (falls with the window) and total, rad.\n" +
         e.c_str() + "\n";
}

void writeAlignmentFile(const std::string& path, const std::string& text, const core::AlignmentResult& result,
                        const std::vector<WindowResult>& windows) {
  core::writeFileAtomically(path, text, {}, [&](const std::string& temporary) {
    YAML::Node doc;
    try {
      doc = YAML::LoadFile(temporary);
      checkReadBack(doc, result, windows);
    } catch (const YAML::Exception& e) {
      throw std::runtime_error(std::string("the written result does not read back: ") + e.what());
    }
  });
}

ScanAgreement scanAgreement(const std::vector<ScanWindow>& windows) {
  ScanAgreement a;
  double first = 0.0, previous = 0.0, lo = 0.0, hi = 0.0;
  for (const ScanWindow& w : windows) {
    if (!w.result.accepted) continue;
    const double h = w.result.heading;
    if (a.accepted == 0) first = previous = lo = hi = h;
    // Headings compared on the circle: the spread against the first, each against the one before.
    const double unwrapped = first + std::remainder(h - first, 360.0);
    lo = std::min(lo, unwrapped);
    hi = std::max(hi, unwrapped);
    a.largest_consecutive = std::max(a.largest_consecutive, std::abs(std::remainder(h - previous, 360.0)));
    previous = h;
    ++a.accepted;
  }
  a.spread = hi - lo;
  return a;
}

std::string emitScan(const std::vector<ScanWindow>& windows, const std::string& bag, const std::string& settings) {
  YAML::Emitter y;
  y.SetDoublePrecision(12);
  y << YAML::BeginMap << YAML::Key << "bag" << YAML::Value << bag << YAML::Key << "settings" << YAML::Value << settings;
  y << YAML::Key << "windows" << YAML::Value << YAML::BeginSeq;
  for (const ScanWindow& w : windows) {
    const core::AlignmentResult& r = w.result;
    y << YAML::BeginMap << YAML::Key << "start_s" << YAML::Value << w.start << YAML::Key << "accepted" << YAML::Value
      << r.accepted << YAML::Key << "gate" << YAML::Value << r.gate;
    if (r.accepted) {
      y << YAML::Key << "heading_deg" << YAML::Value << r.heading << YAML::Key << "heading_sigma_deg" << YAML::Value
        << r.heading_sigma << YAML::Key << "noise_rad" << YAML::Value << r.budget.noise << YAML::Key << "estimator"
        << YAML::Value << r.estimator;
    } else {
      y << YAML::Key << "reason" << YAML::Value << r.reason;
    }
    y << YAML::EndMap;
  }
  y << YAML::EndSeq;
  const ScanAgreement a = scanAgreement(windows);
  if (a.accepted >= 2) {
    y << YAML::Key << "accepted_spread_deg" << YAML::Value << a.spread << YAML::Key
      << "largest_consecutive_difference_deg" << YAML::Value << a.largest_consecutive;
  }
  y << YAML::EndMap;
  return std::string("# hrg_bag align --scan: consecutive windows, each aligned alone\n") + y.c_str() + "\n";
}

void writeScanFile(const std::string& path, const std::string& text, const std::vector<ScanWindow>& windows) {
  core::writeFileAtomically(path, text, {}, [&](const std::string& temporary) {
    try {
      const YAML::Node w = YAML::LoadFile(temporary)["windows"];
      bool same = w.IsSequence() && w.size() == windows.size();
      for (std::size_t i = 0; same && i < windows.size(); ++i) {
        same = sameNumber(windows[i].start, w[i]["start_s"].as<double>()) &&
               w[i]["accepted"].as<bool>() == windows[i].result.accepted &&
               (!windows[i].result.accepted || sameNumber(windows[i].result.heading, w[i]["heading_deg"].as<double>()));
      }
      if (!same) throw std::runtime_error("the scan does not read back as written");
    } catch (const YAML::Exception& e) {
      throw std::runtime_error(std::string("the written scan does not read back: ") + e.what());
    }
  });
}

}  // namespace bag_tools
}  // namespace hrg_gyro

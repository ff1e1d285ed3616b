// hrg_bag align without the bag: its own options (CLI11, checked by name), the alignment over the
// window together with the alignments over the window's first --windows seconds (each a
// core::Gyrocompass fed the same records, the heading against window length), and the result file
// (core::emitAlignmentResult's YAML with the windows under `windows`), written atomically and read back
// before it replaces anything. No ROS: align.cpp reads the bag into it.
#pragma once

#include <CLI/CLI.hpp>
#include <string>
#include <vector>

#include "hrg_gyro/core/alignment/gyrocompass.h"

namespace hrg_gyro {
namespace bag_tools {

struct AlignOptions {
  std::string bag, settings, output;
  double duration = 0.0;  ///< s; 0: the settings' duration
  double start = 0.0;     ///< s of gyro stamps skipped from the first sample
  std::string windows;    ///< "30,60,120": s, each at most the window
  double scan = 0.0;      ///< s; > 0: consecutive windows every `scan` s from --start until the bag ends
  std::string triad_topic, gyro_topic, turntable_topic, accelerometer_topic;
  std::string imu_topic;  ///< sensor_msgs/Imu as the gyros (gyro_input imu); "" the settings' input
};

/// BAG, --settings, --duration, --start, --output, --windows and the topic options.
void addAlignOptions(CLI::App& command, AlignOptions* options);

/// --windows "30,60,120": ascending lengths in s, each above 0 and at most `duration`; "" none. A
/// std::invalid_argument says what is wrong (the caller names the option).
std::vector<double> parseWindows(const std::string& text, double duration);

/// One window's solution: its length and result.
struct WindowResult {
  double seconds = 0.0;
  core::AlignmentResult result;
};

/// The alignment over the window (`settings.duration`) and over each of its first `windows` s, fed the
/// same records in the same order: the window's result equals a lone Gyrocompass's on those records.
class AlignmentRun {
 public:
  AlignmentRun(const core::AlignmentSettings& settings, const std::vector<double>& windows,
               const core::TriadParameters& triad = core::TriadParameters());

  void addTriad(const core::TriadBodySample& sample);
  void addAxis(const core::AxisOutput& output);
  void addSweepAxis(std::size_t axis, const core::AxisOutput& output);
  void addPrecession(std::size_t axis, const core::PrecessionStateRecord& record);
  void addIndexer(const core::IndexerRecord& record);
  void addAccelerometer(const core::AccelerometerRecord& record);

  /// Every window is full or refused (a window refused early leaves the shorter ones to fill).
  bool complete() const;
  const core::Gyrocompass& window() const { return compasses_.front(); }
  /// The input ended: every alignment whose window is not full is aborted, saying how far it got.
  void inputEnded(const std::string& input);
  core::AlignmentResult finish() const { return compasses_.front().finish(); }
  std::vector<WindowResult> finishWindows() const;

 private:
  std::vector<core::Gyrocompass> compasses_;  // [0] the window, then the --windows
};

/// The result file: emitAlignmentResult's document, the inputs, and the windows (heading against window
/// length).
std::string emitAlignmentRun(const core::AlignmentResult& result, const std::vector<WindowResult>& windows,
                             const std::string& bag, const std::string& settings);

/// One window of a scan (--scan): where it started, and its result.
struct ScanWindow {
  double start = 0.0;  ///< s after the bag's first gyro sample
  core::AlignmentResult result;
};

/// How a scan's accepted windows agree: their number, the spread of their headings and the largest
/// difference between consecutive ones (deg, on the circle).
struct ScanAgreement {
  std::size_t accepted = 0;
  double spread = 0.0, largest_consecutive = 0.0;
};
ScanAgreement scanAgreement(const std::vector<ScanWindow>& windows);

/// The scan's file: each window's start, verdict, heading, sigma and budget's noise term, and how the
/// accepted ones agree (their spread and their consecutive differences), as YAML.
std::string emitScan(const std::vector<ScanWindow>& windows, const std::string& bag, const std::string& settings);

/// Writes emitScan's `text` to `path` atomically: read back (YAML, its windows' starts, verdicts and
/// headings those of `windows`) before it replaces the path. std::runtime_error on any failure, the
/// path then unchanged.
void writeScanFile(const std::string& path, const std::string& text, const std::vector<ScanWindow>& windows);

/// Writes `text` to `path` atomically: read back (YAML, its accepted, heading and windows those of
/// `result` and `windows`) before it replaces the path. std::runtime_error on any failure, the path
/// then unchanged.
void writeAlignmentFile(const std::string& path, const std::string& text, const core::AlignmentResult& result,
                        const std::vector<WindowResult>& windows);

}  // namespace bag_tools
}  // namespace hrg_gyro

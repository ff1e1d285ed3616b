// hrg_bag process --triad: three gyros' channels through the triad's processing chain offline
// (core::TriadProcessor: per axis the processor node's GyroProcessor and RateNoiseEstimator for the
// variance its Imu carries, then the triad node's TriadCombiner) with the same message conversions as
// the live processor and triad nodes, so the TriadOutput stream is bit for bit the triad node's on the
// same channels.
#pragma once

#include <rosbag/bag.h>

#include <CLI/CLI.hpp>
#include <array>
#include <string>
#include <vector>

#include "hrg_gyro/core/processing/triad_processor.h"

namespace hrg_gyro {
namespace bag_tools {

/// What --triad adds to the single-axis options of process.
struct TriadOptions {
  std::string triad_file;
  std::vector<std::string> axis_params;    ///< NAME=FILE, each axis's parameter file
  std::vector<std::string> axis_channels;  ///< NAME=TOPIC, an axis's channels (default /NAME/channels)
  core::RateNoiseSettings noise;           ///< each axis's, as its processor node's
  core::TriadCombinerSettings combiner;    ///< as the triad node's
};

/// One axis of the triad and where the bag holds it.
struct AxisInput {
  std::string name, parameter_file, topic;
  std::string frame_id;  ///< of its outputs, as triad.launch names it
};

/// The chain's settings from the options, each refusal naming its option (a UsageError).
core::TriadProcessorSettings checkedSettings(const core::ProcessorConfig& processor, const TriadOptions& options);
/// The axes in the triad's order: names and parameter files (--axis-params, each axis's needed).
std::array<AxisInput, 3> axisInputs(const TriadOptions& options, const core::TriadParameters& triad);
/// Each axis's channels topic in `bag`: --axis-channels NAME=TOPIC, or /NAME/channels, or the one
/// ChannelAmplitudes topic ending in /NAME/channels; two axes on one topic refused.
void findAxisTopics(const rosbag::Bag& bag, const TriadOptions& options, std::array<AxisInput, 3>* axes);

/// --triad, --axis-params, --axis-channels (the forms of hrg_bag calibrate --method triad) and the
/// triad node's settings as options (--stamp-tolerance, --max-wait, --max-pending,
/// --angular-velocity-variance, --initial-angular-velocity-variance). Returns the --triad option.
CLI::Option* addTriadOptions(CLI::App& command, TriadOptions* options);

/// Runs the triad on `bag`: each axis of the triad file needs its --axis-params NAME=FILE; its
/// channels are --axis-channels NAME=TOPIC, or the bag's /NAME/channels (or the one
/// ChannelAmplitudes topic ending in /NAME/channels). `out`: /triad/output, /imu/data_raw and each
/// /NAME/output; `csv`: one row per triad sample. Returns the exit code.
int runTriadProcess(const std::string& bag, const std::string& out, const std::string& csv,
                    const std::string& compression, const core::ProcessorConfig& processor, const TriadOptions& triad);

}  // namespace bag_tools
}  // namespace hrg_gyro

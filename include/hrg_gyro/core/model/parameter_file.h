// The parameter file: one YAML schema (docs/ros_api.md, 'Parameter file'), read by the processor,
// written by the calibrator.
//
// Reading is bounded and validates every key, naming the offending one in the error
// (ConfigError::key()): only a regular file of at most kMaxParameterFileBytes is read (a FIFO, a
// device or a directory is refused without blocking), a key given twice is refused, and the model
// must be physically plausible (limits below).
// Writing is round-trip exact (shortest text that reads back to the same double) and atomic through
// AtomicOutputFile: the text is checked by parsing it back, written to a unique temporary beside
// the (link-resolved) file, fsync'ed, read back and validated again, the previous file is kept as
// <file>.bak, and only then is the new file renamed over the old one, keeping the old file's mode.
// A reader therefore always finds either the complete old file or the complete new one.
#pragma once

#include <yaml-cpp/yaml.h>

#include <cstddef>
#include <string>

#include "hrg_gyro/core/common/yaml_field.h"
#include "hrg_gyro/core/model/gyro_parameters.h"

namespace hrg_gyro {
namespace core {

constexpr int kParameterSchemaVersion = 1;

/// Largest parameter file read. A file at the node and order limits below is about 0.2 MiB.
constexpr std::size_t kMaxParameterFileBytes = 1 << 20;
/// Most frequency nodes per model: the spline set-up and its overshoot check grow with the cube of
/// the count. A temperature range needs a handful.
constexpr std::size_t kMaxFrequencyNodes = 64;
/// |K0| = 2k with the Bryan factor k of the resonator's mode, below 1 for any shell or ring
/// (hemisphere 0.28, ring 0.4): |K0| must lie in [kMinScaleFactorMagnitude, kMaxScaleFactorMagnitude].
/// The lower bound is 28 times below a hemisphere: smaller values are unit or exponent slips, and
/// dividing by them would turn noise into huge rates.
constexpr double kMinScaleFactorMagnitude = 0.01;
constexpr double kMaxScaleFactorMagnitude = 2.0;
/// Largest plausible drift, rad/s of electrical angle: |D0| + sum |harmonics| (0.18 rad/s, about 10 deg/s
/// of body rate for K0 = -0.56). Catches unit slips such as deg/h entered as rad/s.
constexpr double kMaxDriftMagnitude = 0.1;

/// One model section (scale_factor or drift schema), shared with the simulator scenarios.
HarmonicModel parseScaleFactorModel(const YamlField& section);
HarmonicModel parseDriftModel(const YamlField& section);

/// Validates and converts a parsed document. Throws ConfigError naming the key.
GyroParameters parseParameters(const YAML::Node& root);
/// The `calibration` (provenance) block of a parameter or triad file: method, time, source, notes.
CalibrationProvenance parseProvenance(const YamlField& section);
/// Writes that block (key and map) into an open map.
void emitProvenance(YAML::Emitter& out, const CalibrationProvenance& provenance);
/// Reads and validates a file. Throws ConfigError (unreadable file, not a regular file, above the
/// size limit, YAML syntax error with its line, or a bad key).
GyroParameters loadParameterFile(const std::string& path);
/// The same from text already in memory (services, tests).
GyroParameters parseParameterText(const std::string& text);

/// The file text, with a comment on every key (units, conventions).
std::string emitParameters(const GyroParameters& parameters);

struct SaveOptions {
  bool keep_backup = true;  ///< keep the replaced file as <file>.bak, beside the link-resolved file
};
/// Atomic, validated save (see the file comment). A `path` that is a symbolic link stays one: the
/// file it points to is replaced. Throws std::runtime_error on any failure, in which case the file
/// at `path` is untouched.
void saveParameterFile(const std::string& path, const GyroParameters& parameters, const SaveOptions& options = {});

}  // namespace core
}  // namespace hrg_gyro

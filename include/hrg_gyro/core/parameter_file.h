// The parameter file: one YAML schema (docs/ros_api.md, 'Parameter file'), read by the processor,
// written by the calibrator.
//
// Reading validates every key and names the offending one in the error (ConfigError::key()).
// Writing is round-trip exact (shortest text that reads back to the same double) and atomic: the
// text is checked by parsing it back, written to a temporary file in the same directory, fsync'ed,
// read back and validated again, the previous file is kept as <path>.bak, and only then is the new
// file renamed over the old one. A reader therefore always finds either the complete old file or
// the complete new one, never a partial file.
#pragma once

#include <string>

#include <yaml-cpp/yaml.h>

#include "hrg_gyro/core/gyro_parameters.h"
#include "hrg_gyro/core/yaml_field.h"

namespace hrg_gyro {
namespace core {

constexpr int kParameterSchemaVersion = 1;

/// One model section (scale_factor or drift schema), shared with the simulator scenarios.
HarmonicModel parseScaleFactorModel(const YamlField& section);
HarmonicModel parseDriftModel(const YamlField& section);

/// Validates and converts a parsed document. Throws ConfigError naming the key.
GyroParameters parseParameters(const YAML::Node& root);
/// Reads and validates a file. Throws ConfigError (unreadable file, YAML syntax error with its
/// line, or a bad key).
GyroParameters loadParameterFile(const std::string& path);
/// The same from text already in memory (services, tests).
GyroParameters parseParameterText(const std::string& text);

/// The file text, with a comment on every key (units, conventions).
std::string emitParameters(const GyroParameters& parameters);

struct SaveOptions {
  bool keep_backup = true;  ///< keep the replaced file as <path>.bak
};
/// Atomic, validated save (see the file comment). Throws std::runtime_error on any failure, in
/// which case the file at `path` is untouched.
void saveParameterFile(const std::string& path, const GyroParameters& parameters, const SaveOptions& options = {});

}  // namespace core
}  // namespace hrg_gyro

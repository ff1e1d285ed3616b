// The calibrators' check of ~output_directory at start-up: every file a calibrator writes (its
// parameter files, their backups and temporaries, its report) lies inside that one directory
// (core::isInsideDirectory: links and ".." resolved, a link at the file itself followed).
#pragma once

#include <stdexcept>
#include <string>

#include "hrg_gyro/core/common/atomic_file.h"
#include "hrg_gyro/core/common/output_directory.h"

namespace hrg_gyro {

/// "" when `file` would be written inside `directory`; otherwise why not, as the calibrators say it:
/// "'FILE' (a link to 'TARGET') is outside ~output_directory 'DIRECTORY' (or its directory does not
/// exist)".
inline std::string outsideOutputDirectory(const std::string& file, const std::string& directory) {
  if (core::isInsideDirectory(file, directory)) return std::string();
  std::string target = file;
  try {
    target = core::resolveOutputTarget(file);
  } catch (const std::runtime_error& e) {
    target = e.what();  // a link loop
  }
  return "'" + file + "'" + (target != file ? " (a link to '" + target + "')" : "") +
         " is outside ~output_directory '" + directory + "' (or its directory does not exist)";
}

}  // namespace hrg_gyro

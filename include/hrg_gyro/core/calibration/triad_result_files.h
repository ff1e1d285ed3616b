// The files an accepted triad calibration writes: each axis's parameter file and the triad file,
// as one set. Every text is built and checked (it must read back as what was calibrated) before any
// file is touched, then each is written atomically; the triad file goes last, since it is what ties
// the three axis files together. A failure while writing stops there: the files already replaced are
// complete and valid (each on its own), the others untouched, and the error names which is which.
#pragma once

#include <array>
#include <string>
#include <vector>

#include "hrg_gyro/core/calibration/triad_outcome.h"

namespace hrg_gyro {
namespace core {

struct TriadResultPaths {
  std::string triad;                ///< the triad file (M, bias, frame_id)
  std::array<std::string, 3> axes;  ///< each axis's parameter file, in the triad's axis order
};

/// Writes an accepted outcome's four files (refuses a refused outcome). `keep_backup`: each replaced
/// file kept as <file>.bak. Returns the paths written, in order. Throws std::runtime_error.
std::vector<std::string> saveTriadResult(const TriadOutcome& outcome, const TriadResultPaths& paths,
                                         bool keep_backup = true);

}  // namespace core
}  // namespace hrg_gyro

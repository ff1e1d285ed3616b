// The files an accepted triad calibration writes: each axis's parameter file and the triad file,
// as one set (core::AtomicOutputSet). Every text is built and checked (it must read back as what was
// calibrated) before any file is touched; then the four temporaries are written, synced and read
// back, and each current file is linked aside, before the first rename; the triad file is renamed
// last, since it is what ties the three axis files together. A failure before the renames changes
// nothing (the four files and their .bak as they were, no temporary); a failed rename puts back the
// files already renamed. checkTriadPaths is the rule for the paths, checked before anything is read.
#pragma once

#include <array>
#include <string>
#include <vector>

#include "hrg_gyro/core/calibration/triad/triad_outcome.h"

namespace hrg_gyro {
namespace core {

struct TriadResultPaths {
  std::string triad;                ///< the triad file (M, bias, frame_id)
  std::array<std::string, 3> axes;  ///< each axis's parameter file, in the triad's axis order
};

/// The paths of a triad calibration, by file identity (core::sameFile: links followed, hard links,
/// other spellings such as dir/../): each of the four `outputs` must differ from every other output
/// and from every input but its own prior, which it may refresh in place (the triad file
/// `priors.triad`, axis i's file `priors.axes[i]`, as `hrg_bag calibrate --params P --out P` does);
/// `other_outputs` (the report) must differ from every input and output; and with `keep_backup`, no
/// output's backup (<file>.bak) may be an input or another output. `other_inputs`: the bag, the
/// settings file. Empty paths (a nominal prior, an option not given) are skipped. Throws
/// std::runtime_error naming both paths.
void checkTriadPaths(const TriadResultPaths& outputs, const TriadResultPaths& priors,
                     const std::vector<std::string>& other_inputs = {},
                     const std::vector<std::string>& other_outputs = {}, bool keep_backup = true);

/// Writes an accepted outcome's four files (refuses a refused outcome) as one set. `keep_backup`:
/// each replaced file kept as <file>.bak. Checks the four paths among themselves (checkTriadPaths
/// without inputs). Returns the paths written, in order. Throws std::runtime_error, BackupNotKept
/// when the new set is in place but a previous version could not be kept.
std::vector<std::string> saveTriadResult(const TriadOutcome& outcome, const TriadResultPaths& paths,
                                         bool keep_backup = true);

}  // namespace core
}  // namespace hrg_gyro

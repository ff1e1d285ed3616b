// Confinement of written files: the calibrator writes the parameter file, its backup and temporary
// and the report only inside one configured output directory. The check resolves symbolic links
// and ".." so that neither a link nor a relative path can lead a write elsewhere.
#pragma once

#include <string>

namespace hrg_gyro {
namespace core {

/// The directory part of a path ("." for a bare file name).
std::string directoryOf(const std::string& path);

/// True when the file `path` would be written inside `directory` (or a subdirectory of it). Both
/// the directory and the file's parent directory must exist; links are resolved, including a link
/// at `path` itself (the writer replaces the file it points to, see resolveOutputTarget): a link
/// inside the directory that points outside is outside. A link loop is outside too.
bool isInsideDirectory(const std::string& path, const std::string& directory);

}  // namespace core
}  // namespace hrg_gyro

#include "hrg_gyro/core/common/output_directory.h"

#include <filesystem>
#include <stdexcept>
#include <system_error>

#include "hrg_gyro/core/common/atomic_file.h"

namespace hrg_gyro {
namespace core {

std::string directoryOf(const std::string& path) {
  const std::size_t slash = path.find_last_of('/');
  return slash == std::string::npos ? "." : (slash == 0 ? "/" : path.substr(0, slash));
}

bool isInsideDirectory(const std::string& path, const std::string& directory) {
  namespace fs = std::filesystem;
  std::string target;
  try {
    target = resolveOutputTarget(path);  // the file a write would really replace
  } catch (const std::runtime_error&) {
    return false;  // a link loop, an unreadable link: nowhere a write could safely go
  }
  std::error_code ec_dir, ec_parent;
  const fs::path dir = fs::canonical(directory, ec_dir);
  const fs::path parent = fs::canonical(directoryOf(target), ec_parent);
  if (ec_dir || ec_parent) return false;
  // Component-wise prefix: /a/bc is not inside /a/b.
  auto d = dir.begin(), p = parent.begin();
  for (; d != dir.end(); ++d, ++p) {
    if (p == parent.end() || *d != *p) return false;
  }
  return true;
}

}  // namespace core
}  // namespace hrg_gyro

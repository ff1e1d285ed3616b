#include "hrg_gyro/core/resonator/shell_parameters.h"

#include <cmath>
#include <stdexcept>
#include <string>

#include "hrg_gyro/core/common/units.h"

namespace hrg_gyro {
namespace core {

double ShellParameters::angularFrequency() const { return kTwoPi * frequency; }

void ShellParameters::validate() const {
  const auto require = [](bool ok, const char* field, const std::string& what) {
    if (!ok) throw std::invalid_argument(std::string("resonator ") + field + ": " + what);
  };
  require(std::isfinite(frequency) && frequency > 0.0, "frequency", "must be a positive number of Hz");
  require(std::isfinite(bryan_factor) && bryan_factor > 0.0 && bryan_factor < 1.0, "bryan_factor",
          "must lie in (0, 1)");
  require(std::isfinite(damping_time) && damping_time > 0.0, "damping_time", "must be a positive number of s");
  require(std::isfinite(damping_anisotropy) && std::abs(damping_anisotropy) < 2.0 / damping_time, "damping_anisotropy",
          "must be finite and below 2/damping_time in magnitude (both modes damped)");
  require(std::isfinite(damping_axis), "damping_axis", "must be finite");
  require(std::isfinite(frequency_split), "frequency_split", "must be finite");
  require(std::isfinite(frequency_axis), "frequency_axis", "must be finite");
}

}  // namespace core
}  // namespace hrg_gyro

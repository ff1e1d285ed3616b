// Fuzz target: the parameter-file loader on arbitrary text. Every input must either be refused with
// a ConfigError (the processor then keeps its model) or give a model that is usable as is: finite
// and non-zero K everywhere, finite D, and an emitted file that reads back to the same parameters.
#include <cmath>
#include <string>

#include "fuzz_check.h"
#include "hrg_gyro/core/model/parameter_file.h"

namespace hrg_gyro {
namespace fuzz {

int parameterFileTarget(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  core::GyroParameters parameters;
  try {
    parameters = core::parseParameterText(text);
  } catch (const core::ConfigError&) {
    return 0;  // refused, with the key named: the expected outcome for most inputs
  }
  // Accepted: K must keep its sign and D stay finite over theta and over (and beyond) the nodes.
  const double k0 = parameters.scale_factor.meanAt(NAN);
  for (double f : {double(NAN), -1.0, 0.0, 4990.0, 5000.0, 5010.5, 1e300}) {
    for (int i = 0; i < 16; ++i) {
      const double theta = -7.0 + i * 0.9;
      const double k = parameters.scale_factor(theta, f);
      const double d = parameters.drift(theta, f);
      HRG_FUZZ_CHECK_FINITE(k);
      HRG_FUZZ_CHECK_FINITE(d);
      HRG_FUZZ_CHECK(k != 0.0);
      HRG_FUZZ_CHECK((k < 0.0) == (k0 < 0.0));
    }
  }
  // Round trip: what the calibrator would write reads back to the same parameters.
  const std::string emitted = core::emitParameters(parameters);
  core::GyroParameters again;
  try {
    again = core::parseParameterText(emitted);
  } catch (const core::ConfigError& e) {
    std::fprintf(stderr, "emitted file refused: %s\n%s\n", e.what(), emitted.c_str());
    HRG_FUZZ_CHECK(false);
  }
  HRG_FUZZ_CHECK(again == parameters);
  return 0;
}

}  // namespace fuzz
}  // namespace hrg_gyro

#ifdef HRG_LIBFUZZER
extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  return hrg_gyro::fuzz::parameterFileTarget(data, size);
}
#endif

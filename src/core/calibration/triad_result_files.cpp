#include "hrg_gyro/core/calibration/triad_result_files.h"

#include <memory>
#include <stdexcept>

#include "hrg_gyro/core/common/atomic_file.h"
#include "hrg_gyro/core/common/yaml_field.h"
#include "hrg_gyro/core/model/parameter_file.h"

namespace hrg_gyro {
namespace core {

std::vector<std::string> saveTriadResult(const TriadOutcome& outcome, const TriadResultPaths& paths, bool keep_backup) {
  if (!outcome.accepted) throw std::runtime_error("refusing to write a refused triad calibration: " + outcome.reason);
  checkDistinct({}, {paths.axes[0], paths.axes[1], paths.axes[2], paths.triad});

  // Every text first, each checked to read back as what it holds: nothing is touched on a refusal.
  std::array<std::string, 4> texts;
  for (int i = 0; i < 3; ++i) {
    texts[i] = emitParameters(outcome.axes[i].parameters);
    try {
      if (parseParameterText(texts[i]) != outcome.axes[i].parameters)
        throw std::runtime_error("parameters do not survive a round trip");
    } catch (const ConfigError& e) {
      throw std::runtime_error("refusing to write invalid parameters of axis " + outcome.axis_names[i] + ": " +
                               e.what());
    }
  }
  texts[3] = emitTriadParameters(outcome.triad);
  try {
    if (parseTriadParameters(YAML::Load(texts[3])) != outcome.triad)
      throw std::runtime_error("the triad does not survive a round trip");
  } catch (const ConfigError& e) {
    throw std::runtime_error(std::string("refusing to write an invalid triad: ") + e.what());
  }

  // Then the temporaries, all complete before the first rename.
  const std::array<std::string, 4> targets{{paths.axes[0], paths.axes[1], paths.axes[2], paths.triad}};
  OutputFileOptions options;
  options.keep_backup = keep_backup;
  std::array<std::unique_ptr<AtomicOutputFile>, 4> files;
  for (int k = 0; k < 4; ++k) {
    files[k] = std::make_unique<AtomicOutputFile>(targets[k], options);
    files[k]->write(texts[k]);
  }
  std::vector<std::string> written;
  for (int k = 0; k < 4; ++k) {
    try {
      if (k < 3) {
        const GyroParameters& expected = outcome.axes[k].parameters;
        files[k]->commit([&](const std::string& temporary) {
          if (loadParameterFile(temporary) != expected)
            throw std::runtime_error("written file reads back differently: " + temporary);
        });
      } else {
        files[k]->commit([&](const std::string& temporary) {
          if (loadTriadFile(temporary) != outcome.triad)
            throw std::runtime_error("written file reads back differently: " + temporary);
        });
      }
    } catch (const std::exception& e) {
      std::string done;
      for (const std::string& w : written) done += (done.empty() ? "" : ", ") + w;
      throw std::runtime_error(std::string(e.what()) +
                               (done.empty() ? "; nothing was replaced" : "; already replaced: " + done) +
                               "; not written: " + targets[k] + (k < 3 ? " and the rest" : ""));
    }
    written.push_back(targets[k]);
  }
  return written;
}

}  // namespace core
}  // namespace hrg_gyro

#include "hrg_gyro/core/calibration/triad/triad_result_files.h"

#include <stdexcept>

#include "hrg_gyro/core/common/atomic_file.h"
#include "hrg_gyro/core/common/yaml_field.h"
#include "hrg_gyro/core/model/parameter_file.h"
#include "hrg_gyro/core/model/triad_file.h"

namespace hrg_gyro {
namespace core {
namespace {

/// A path of the check, with the slot of the set it belongs to (0..2 the axes, 3 the triad file; -1 none).
struct SlottedPath {
  std::string path;
  int slot;
};

std::vector<SlottedPath> slotted(const TriadResultPaths& paths, const std::vector<std::string>& others) {
  std::vector<SlottedPath> out;
  for (int i = 0; i < 3; ++i) {
    if (!paths.axes[i].empty()) out.push_back({paths.axes[i], i});
  }
  if (!paths.triad.empty()) out.push_back({paths.triad, 3});
  for (const std::string& p : others) {
    if (!p.empty()) out.push_back({p, -1});
  }
  return out;
}

}  // namespace

void checkTriadPaths(const TriadResultPaths& outputs, const TriadResultPaths& priors,
                     const std::vector<std::string>& other_inputs, const std::vector<std::string>& other_outputs,
                     bool keep_backup) {
  const std::vector<SlottedPath> in = slotted(priors, other_inputs), out = slotted(outputs, other_outputs);
  for (std::size_t o = 0; o < out.size(); ++o) {
    for (std::size_t other = 0; other < o; ++other) {
      if (sameFile(out[o].path, out[other].path)) {
        throw std::runtime_error("outputs '" + out[other].path + "' and '" + out[o].path + "' are the same file");
      }
    }
    for (const SlottedPath& i : in) {
      if (out[o].slot >= 0 && out[o].slot == i.slot) continue;  // refreshed in place
      if (sameFile(out[o].path, i.path)) {
        throw std::runtime_error("output '" + out[o].path + "' is the same file as input '" + i.path +
                                 "': writing it would destroy what is being read");
      }
    }
  }
  if (!keep_backup) return;
  for (const SlottedPath& o : out) {
    if (o.slot < 0) continue;  // written without a backup
    const std::string backup = backupPathOf(o.path);
    for (const SlottedPath& i : in) {
      if (sameFile(backup, i.path)) {
        throw std::runtime_error("output '" + o.path + "' keeps its previous version as '" + backup +
                                 "', the same file as input '" + i.path + "': writing it would replace that input");
      }
    }
    for (const SlottedPath& other : out) {
      if (&other != &o && sameFile(backup, other.path)) {
        throw std::runtime_error("output '" + o.path + "' keeps its previous version as '" + backup +
                                 "', the same file as output '" + other.path + "'");
      }
    }
  }
}

std::vector<std::string> saveTriadResult(const TriadOutcome& outcome, const TriadResultPaths& paths, bool keep_backup) {
  if (!outcome.accepted) throw std::runtime_error("refusing to write a refused triad calibration: " + outcome.reason);
  for (const std::string& p : {paths.axes[0], paths.axes[1], paths.axes[2], paths.triad}) {
    if (p.empty()) throw std::runtime_error("a triad result path is empty");
  }
  checkTriadPaths(paths, {}, {}, {}, keep_backup);

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

  // Then the set: every temporary written, synced and read back from the disk before the first rename.
  const std::array<std::string, 4> targets{{paths.axes[0], paths.axes[1], paths.axes[2], paths.triad}};
  OutputFileOptions options;
  options.keep_backup = keep_backup;
  AtomicOutputSet set;
  for (int k = 0; k < 4; ++k) {
    AtomicOutputFile::Verifier verify;
    if (k < 3) {
      const GyroParameters& expected = outcome.axes[k].parameters;
      verify = [&expected](const std::string& temporary) {
        if (loadParameterFile(temporary) != expected)
          throw std::runtime_error("written file reads back differently: " + temporary);
      };
    } else {
      verify = [&outcome](const std::string& temporary) {
        if (loadTriadFile(temporary) != outcome.triad)
          throw std::runtime_error("written file reads back differently: " + temporary);
      };
    }
    set.add(targets[k], options, verify).write(texts[k]);
  }
  set.commit();
  return {targets.begin(), targets.end()};
}

}  // namespace core
}  // namespace hrg_gyro

// hrg_bag report and hrg_bag batch: the HTML calibration report and the campaign of many bags. Both
// are Python scripts (matplotlib figures, jinja2 page) installed beside hrg_bag; these commands hand
// them their arguments unchanged, so `hrg_bag report --help` is the script's own help.
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <string>
#include <vector>

#include "bag_tools.h"

namespace hrg_gyro {

namespace {

/// Replaces hrg_bag by `/usr/bin/python3 script arguments...`: its exit code is the command's.
int runScript(const std::string& script_name, const std::vector<std::string>& arguments) {
  const std::string script = bag_tools::packageScript(script_name);
  std::vector<std::string> argv_s{"/usr/bin/python3", script};
  argv_s.insert(argv_s.end(), arguments.begin(), arguments.end());
  std::vector<char*> argv;
  for (std::string& a : argv_s) argv.push_back(a.data());
  argv.push_back(nullptr);
  ::execv(argv[0], argv.data());  // returns only on failure
  throw bag_tools::UsageError("cannot run " + script + " with /usr/bin/python3: " + std::strerror(errno));
}

bag_tools::Command addForwardingCommand(CLI::App& root, const std::string& name, const std::string& script,
                                        const std::string& description) {
  CLI::App* cmd = root.add_subcommand(name, description);
  cmd->prefix_command();  // every argument after the command's name goes to the script
  cmd->set_help_flag();   // --help too: the script prints its own
  return [cmd, script] { return runScript(script, cmd->remaining()); };
}

}  // namespace

namespace bag_tools {

Command addReportCommand(CLI::App& root) {
  return addForwardingCommand(root, "report", "hrg_report.py",
                              "one calibration as a self-contained HTML page (hrg_bag report --help)");
}

Command addBatchCommand(CLI::App& root) {
  return addForwardingCommand(root, "batch", "hrg_batch.py",
                              "calibrate a folder of bags in parallel, reports and an index (hrg_bag batch --help)");
}

}  // namespace bag_tools
}  // namespace hrg_gyro

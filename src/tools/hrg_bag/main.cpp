// hrg_bag: recorded gyro sessions without a ROS master. One executable, one subcommand per job;
// the command line (CLI11) and its --help come from the same option definitions.
#include <iostream>
#include <map>
#include <string>

#include "../cli_checks.h"
#include "bag_tools.h"
#include "hrg_gyro/core/common/yaml_field.h"

int main(int argc, char** argv) {
  using namespace hrg_gyro::bag_tools;
  CLI::App app("Recorded gyro sessions without a ROS master (hrg_bag <command> --help for each).", "hrg_bag");
  app.get_formatter()->label("Usage", "usage");
  app.get_formatter()->column_width(34);
  app.footer(
      "Exit codes: 0 success, 1 refused or invalid data, 2 bad usage or unreadable input, 3 an output could\n"
      "not be written (nothing is left at its path; an existing file is unchanged).");
  app.require_subcommand(1);
  const std::map<std::string, Command> commands = {
      {"simulate", addSimulateCommand(app)},   {"info", addInfoCommand(app)},     {"process", addProcessCommand(app)},
      {"calibrate", addCalibrateCommand(app)}, {"allan", addAllanCommand(app)},   {"report", addReportCommand(app)},
      {"batch", addBatchCommand(app)},         {"import", addImportCommand(app)}, {"export", addExportCommand(app)},
      {"align", addAlignCommand(app)},
  };
  if (argc < 2) {
    std::cerr << app.help();
    return 2;
  }
  if (argv[1][0] != '-' && commands.count(argv[1]) == 0) {
    // CLI11 would only say that a subcommand is required; name what was typed instead.
    std::cerr << "hrg_bag: unknown command '" << argv[1] << "'\n" << app.help();
    return 2;
  }
  const int parsed = hrg_gyro::tools::parseCommandLine(app, argc, argv);
  if (parsed >= 0) return parsed;
  std::string name;
  for (const auto& kv : commands) {
    if (app.got_subcommand(kv.first)) name = kv.first;
  }
  try {
    return commands.at(name)();
  } catch (const OutputError& e) {
    std::cerr << "hrg_bag " << name << ": " << e.what() << "\n";
    return kExitOutputError;
  } catch (const UsageError& e) {
    std::cerr << "hrg_bag " << name << ": " << e.what() << "\n";
  } catch (const hrg_gyro::core::ConfigError& e) {
    std::cerr << "hrg_bag " << name << ": " << e.what() << "\n";
  } catch (const std::exception& e) {
    std::cerr << "hrg_bag " << name << ": " << e.what() << "\n";
  }
  return 2;
}

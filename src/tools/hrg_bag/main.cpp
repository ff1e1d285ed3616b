// hrg_bag: recorded gyro sessions without a ROS master. One executable, one subcommand per job.
#include <cstring>
#include <iostream>
#include <string>

#include "bag_tools.h"
#include "hrg_gyro/core/yaml_field.h"

namespace hrg_gyro {
int simulateCommand(int argc, char** argv);
int infoCommand(int argc, char** argv);
int processCommand(int argc, char** argv);
int calibrateCommand(int argc, char** argv);
int allanCommand(int argc, char** argv);
}  // namespace hrg_gyro

namespace {

void usage(std::ostream& out) {
  out << "usage: hrg_bag <command> [options]   (hrg_bag <command> --help for each)\n"
         "  simulate   --scenario FILE.yaml --out OUT.bag [--seed N]      the simulator into a bag\n"
         "  info       BAG                                                validate a gyro bag\n"
         "  process    BAG --params P.yaml [--out OUT.bag] [--csv OUT.csv] the processor offline\n"
         "  calibrate  BAG --method M [--params IN.yaml] --out OUT.yaml    the calibrator offline\n"
         "             [--report REPORT.yaml] [--plot OUT.png]\n"
         "  allan      BAG [--params P.yaml] [--csv OUT.csv] [--plot OUT.png]  Allan deviation\n"
         "Exit codes: 0 success, 1 refused or invalid data, 2 bad usage or unreadable input.\n";
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 2 || !std::strcmp(argv[1], "-h") || !std::strcmp(argv[1], "--help")) {
    usage(std::cout);
    return argc < 2 ? 2 : 0;
  }
  const std::string command = argv[1];
  try {
    if (command == "simulate") return hrg_gyro::simulateCommand(argc - 2, argv + 2);
    if (command == "info") return hrg_gyro::infoCommand(argc - 2, argv + 2);
    if (command == "process") return hrg_gyro::processCommand(argc - 2, argv + 2);
    if (command == "calibrate") return hrg_gyro::calibrateCommand(argc - 2, argv + 2);
    if (command == "allan") return hrg_gyro::allanCommand(argc - 2, argv + 2);
    std::cerr << "hrg_bag: unknown command '" << command << "'\n";
    usage(std::cerr);
    return 2;
  } catch (const hrg_gyro::bag_tools::UsageError& e) {
    std::cerr << "hrg_bag " << command << ": " << e.what() << "\n";
    return 2;
  } catch (const hrg_gyro::core::ConfigError& e) {
    std::cerr << "hrg_bag " << command << ": " << e.what() << "\n";
    return 2;
  } catch (const std::exception& e) {
    std::cerr << "hrg_bag " << command << ": " << e.what() << "\n";
    return 2;
  }
}

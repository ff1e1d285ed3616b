// The calibrator in triad mode (TriadCalibratorRos) on bad parameters: a missing triad file or axis
// parameter file is refused with the key named; an axis map that lacks an axis or names one the
// triad does not have, an unreadable axis file, two axes on one file, an axis file that is the triad
// file's .bak, a file to write outside ~output_directory (also through a link) are refused; so is an
// unknown key, at the top level or in the triad section (as the single-axis calibrator refuses its
// unknown keys); so is a bad number of the node's own (queue, hold, periods), with the key and the
// value named; ~method chooses the wrapper.
#include <gtest/gtest.h>
#include <ros/ros.h>
#include <unistd.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <map>
#include <string>

#include "hrg_gyro/ros/triad_calibrator_ros.h"

namespace hrg_gyro {
namespace {

namespace fs = std::filesystem;
using Keys = std::vector<std::string>;
using Files = std::map<std::string, std::string>;

class TriadCalibratorParameters : public ::testing::Test {
 protected:
  void SetUp() override {
    char pattern[] = "/tmp/hrg_triad_parameters.XXXXXX";
    ASSERT_NE(::mkdtemp(pattern), nullptr);
    dir_ = pattern;
    const std::string config = std::string(HRG_GYRO_SOURCE_DIR) + "/config/";
    fs::copy_file(config + "triad.yaml", dir_ + "/triad.yaml");
    for (const char* axis : {"x", "y", "z"}) {
      fs::copy_file(config + "params_uncalibrated.yaml", dir_ + "/" + axis + ".yaml");
    }
  }
  void TearDown() override { fs::remove_all(dir_); }

  /// A fresh private namespace with the files of the work directory (and `method: triad`).
  ros::NodeHandle node(const std::string& name, bool with_files = true) {
    ros::NodeHandle pnh(name + "/calibrator");
    pnh.setParam("method", std::string("triad"));
    pnh.setParam("autostart", false);
    if (with_files) {
      pnh.setParam("triad_file", dir_ + "/triad.yaml");
      pnh.setParam("axis_parameter_files", axisFiles());
    }
    return pnh;
  }
  Files axisFiles() const { return {{"x", dir_ + "/x.yaml"}, {"y", dir_ + "/y.yaml"}, {"z", dir_ + "/z.yaml"}}; }

  /// The message of the exception the constructor throws ("" if it does not).
  static std::string refusal(const std::string& name) {
    try {
      TriadCalibratorRos node(ros::NodeHandle(name), ros::NodeHandle(name + "/calibrator"));
    } catch (const std::exception& e) {
      return e.what();
    }
    return std::string();
  }

  std::string dir_;
};

TEST_F(TriadCalibratorParameters, TheMethodChoosesTheWrapper) {
  EXPECT_TRUE(TriadCalibratorRos::selected(node("choose_triad")));
  ros::NodeHandle single("choose_single/calibrator");
  single.setParam("method", std::string("dual_rate"));
  EXPECT_FALSE(TriadCalibratorRos::selected(single));
  EXPECT_FALSE(TriadCalibratorRos::selected(ros::NodeHandle("choose_unset/calibrator")));
}

TEST_F(TriadCalibratorParameters, AValidSetStartsWithoutUnknownKeys) {
  node("valid");
  TriadCalibratorRos calibrator(ros::NodeHandle("valid"), ros::NodeHandle("valid/calibrator"));
  EXPECT_EQ(calibrator.parameters().unknownKeys(), Keys{});
}

TEST_F(TriadCalibratorParameters, AMissingTriadFileIsRefusedNamingTheKey) {
  ros::NodeHandle pnh = node("no_triad_file", false);
  pnh.setParam("axis_parameter_files", axisFiles());
  const std::string message = refusal("no_triad_file");
  EXPECT_NE(message.find("~triad_file is required"), std::string::npos) << message;
  pnh.setParam("triad_file", dir_ + "/absent.yaml");
  const std::string absent = refusal("no_triad_file");
  EXPECT_NE(absent.find("~triad_file " + dir_ + "/absent.yaml"), std::string::npos) << absent;
}

TEST_F(TriadCalibratorParameters, MissingAxisFilesAreRefusedNamingTheKey) {
  ros::NodeHandle pnh = node("no_axis_files", false);
  pnh.setParam("triad_file", dir_ + "/triad.yaml");
  const std::string none = refusal("no_axis_files");
  EXPECT_NE(none.find("~axis_parameter_files is required"), std::string::npos) << none;
  EXPECT_NE(none.find("{x: FILE, y: FILE, z: FILE}"), std::string::npos) << none;

  Files two = axisFiles();
  two.erase("z");
  pnh.setParam("axis_parameter_files", two);
  const std::string lacking = refusal("no_axis_files");
  EXPECT_NE(lacking.find("~axis_parameter_files/z is missing"), std::string::npos) << lacking;

  Files four = axisFiles();
  four["w"] = dir_ + "/x.yaml";
  pnh.deleteParam("axis_parameter_files");
  pnh.setParam("axis_parameter_files", four);
  const std::string extra = refusal("no_axis_files");
  EXPECT_NE(extra.find("~axis_parameter_files/w: 'w' is not an axis"), std::string::npos) << extra;

  Files unreadable = axisFiles();
  unreadable["y"] = dir_ + "/absent.yaml";
  pnh.deleteParam("axis_parameter_files");
  pnh.setParam("axis_parameter_files", unreadable);
  const std::string absent = refusal("no_axis_files");
  EXPECT_NE(absent.find("~axis_parameter_files/y " + dir_ + "/absent.yaml"), std::string::npos) << absent;

  pnh.deleteParam("axis_parameter_files");
  pnh.setParam("axis_parameter_files", std::vector<std::string>{dir_ + "/x.yaml", dir_ + "/y.yaml", dir_ + "/z.yaml"});
  const std::string list = refusal("no_axis_files");
  EXPECT_NE(list.find("~axis_parameter_files is required: a map"), std::string::npos) << list;

  Files shared = axisFiles();
  shared["y"] = dir_ + "/x.yaml";
  pnh.deleteParam("axis_parameter_files");
  pnh.setParam("axis_parameter_files", shared);
  const std::string same = refusal("no_axis_files");
  EXPECT_NE(same.find("must be distinct"), std::string::npos) << same;

  // An axis's file that is where the triad file keeps its previous version: a write would replace it.
  fs::copy_file(dir_ + "/y.yaml", dir_ + "/triad.yaml.bak");
  Files backup = axisFiles();
  backup["y"] = dir_ + "/triad.yaml.bak";
  pnh.deleteParam("axis_parameter_files");
  pnh.setParam("axis_parameter_files", backup);
  const std::string bak = refusal("no_axis_files");
  EXPECT_NE(bak.find("'" + dir_ + "/triad.yaml' keeps its previous version as '" + dir_ + "/triad.yaml.bak'"),
            std::string::npos)
      << bak;
  fs::remove(dir_ + "/triad.yaml.bak");
}

TEST_F(TriadCalibratorParameters, FilesOutsideTheOutputDirectoryAreRefused) {
  fs::create_directory(dir_ + "/out");
  ros::NodeHandle pnh = node("outside");
  pnh.setParam("output_directory", dir_ + "/out");
  const std::string triad = refusal("outside");  // the triad file lies in dir_, not in dir_/out
  EXPECT_NE(triad.find("~triad_file '" + dir_ + "/triad.yaml' is outside ~output_directory"), std::string::npos)
      << triad;

  pnh.setParam("output_directory", dir_);
  pnh.setParam("report_file", std::string("/tmp/hrg_triad_report_elsewhere.yaml"));
  const std::string report = refusal("outside");
  EXPECT_NE(report.find("~report_file '/tmp/hrg_triad_report_elsewhere.yaml' is outside"), std::string::npos) << report;
  pnh.deleteParam("report_file");

  // An axis file that is a link inside the directory to a file outside it.
  char other[] = "/tmp/hrg_triad_outside.XXXXXX";
  ASSERT_NE(::mkdtemp(other), nullptr);
  fs::copy_file(dir_ + "/y.yaml", std::string(other) + "/y.yaml");
  fs::remove(dir_ + "/y.yaml");
  fs::create_symlink(std::string(other) + "/y.yaml", dir_ + "/y.yaml");
  const std::string link = refusal("outside");
  EXPECT_NE(link.find("~axis_parameter_files/y '" + dir_ + "/y.yaml' (a link to"), std::string::npos) << link;
  fs::remove_all(other);
}

TEST_F(TriadCalibratorParameters, UnknownKeysAreRefusedNamingThem) {
  // As in the single-axis mode, a key the calibrator does not know stops it at start-up (a typo in a
  // file name key must not leave the default in force), in the triad section too.
  ros::NodeHandle pnh = node("typo");
  pnh.setParam("stream_hld", 1.0);
  const std::string top = refusal("typo");
  EXPECT_NE(top.find("stream_hld: unknown key"), std::string::npos) << top;
  pnh.deleteParam("stream_hld");
  pnh.setParam("triad/azimth", 0.3);
  const std::string section = refusal("typo");
  EXPECT_NE(section.find("triad.azimth: unknown key"), std::string::npos) << section;
  pnh.deleteParam("triad/azimth");
  TriadCalibratorRos calibrator(ros::NodeHandle("typo"), pnh);
  EXPECT_EQ(calibrator.parameters().unknownKeys(), Keys{});
}

TEST_F(TriadCalibratorParameters, SingleAxisKeysAreRefusedWhereTheyWouldMislead) {
  ros::NodeHandle pnh = node("stages");
  pnh.setParam("stages", std::vector<std::string>{"correction_matrix", "dual_rate"});
  const std::string message = refusal("stages");
  EXPECT_NE(message.find("~stages is for the single-axis methods"), std::string::npos) << message;
  pnh.deleteParam("stages");
  pnh.setParam("stream_hold", -1.0);
  const std::string hold = refusal("stages");
  EXPECT_NE(hold.find("~stream_hold"), std::string::npos) << hold;
}

TEST_F(TriadCalibratorParameters, BadNumbersAreRefusedNamingTheKey) {
  // The node's own numbers (the calibration settings are the core parser's, tested there): never a
  // queue of 0, a NaN hold or an infinite period started silently.
  struct Case {
    const char* key;
    double value;
    const char* expected;
  };
  const std::vector<Case> cases = {
      {"stream_hold", NAN, "must be in [0, 60] s, not nan"},
      {"stream_hold", -1.0, "not -1"},
      {"stream_hold", 61.0, "not 61"},
      {"heap_trim_period", NAN, "must be a finite number (s; <= 0: never), not nan"},
      {"heap_trim_period", INFINITY, "not inf"},
      {"diagnostic_period", 0.0, "must be in (0, 3600] s, not 0"},
      {"diagnostic_period", NAN, "not nan"},
      {"diagnostic_period", INFINITY, "not inf"},
  };
  int n = 0;
  for (const Case& c : cases) {
    const std::string name = "number_" + std::to_string(++n);
    node(name).setParam(c.key, c.value);
    const std::string message = refusal(name);
    EXPECT_NE(message.find(std::string("calibrator (triad): ~") + c.key), std::string::npos)
        << c.key << ": " << message;
    EXPECT_NE(message.find(c.expected), std::string::npos) << c.key << ": " << message;
  }
  for (const int queue : {0, -1}) {
    const std::string name = "queue_" + std::to_string(-queue);
    node(name).setParam("queue_size", queue);
    const std::string message = refusal(name);
    EXPECT_NE(
        message.find("calibrator (triad): ~queue_size must be at least 1 (messages), not " + std::to_string(queue)),
        std::string::npos)
        << message;
  }
  // A negative trim period is the documented "never": accepted.
  node("never_trim").setParam("heap_trim_period", -1.0);
  EXPECT_EQ(refusal("never_trim"), "");
}

}  // namespace
}  // namespace hrg_gyro

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "triad_calibrator_parameters_test");
  ros::AsyncSpinner spinner(1);
  spinner.start();
  return RUN_ALL_TESTS();
}

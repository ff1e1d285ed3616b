// The parameter templates in config/ list every private parameter each node reads (a node started
// on its template falls back to no default) and nothing else (no unknown key); a typo in a key is
// reported as unknown, and a node started without a template lists its defaults.
#include <gtest/gtest.h>
#include <ros/ros.h>
#include <unistd.h>

#include <filesystem>
#include <map>

#include "hrg_gyro/ros/calibrator_ros.h"
#include "hrg_gyro/ros/driver_sim_ros.h"
#include "hrg_gyro/ros/processor_ros.h"
#include "hrg_gyro/ros/triad_calibrator_ros.h"
#include "hrg_gyro/ros/triad_ros.h"

namespace hrg_gyro {
namespace {

using Keys = std::vector<std::string>;

TEST(ParameterTemplateTest, ProcessorTemplateIsComplete) {
  ProcessorRos node(ros::NodeHandle("template"), ros::NodeHandle("template/processor"));
  EXPECT_EQ(node.parameters().defaultedKeys(), Keys{}) << "keys config/processor.yaml lacks";
  EXPECT_EQ(node.parameters().unknownKeys(), Keys{}) << "keys config/processor.yaml has that the node does not read";
  EXPECT_GT(node.parameters().readKeys().size(), 20u);
}

TEST(ParameterTemplateTest, CalibratorTemplateIsComplete) {
  CalibratorRos node(ros::NodeHandle("template"), ros::NodeHandle("template/calibrator"));
  EXPECT_EQ(node.parameters().defaultedKeys(), Keys{}) << "keys config/calibrator.yaml lacks";
  EXPECT_EQ(node.parameters().unknownKeys(), Keys{});
  EXPECT_GT(node.parameters().readKeys().size(), 40u);
}

TEST(ParameterTemplateTest, TriadCalibratorTemplateIsComplete) {
  // The same template with method triad (parameter_templates.test) and the files the launch would
  // name: the triad mode reads every key of it too, and finds none it does not know.
  char pattern[] = "/tmp/hrg_triad_template.XXXXXX";
  ASSERT_NE(::mkdtemp(pattern), nullptr);
  const std::string dir = pattern, config = std::string(HRG_GYRO_SOURCE_DIR) + "/config/";
  std::filesystem::copy_file(config + "triad.yaml", dir + "/triad.yaml");
  std::map<std::string, std::string> files;
  for (const std::string axis : {"x", "y", "z"}) {
    files[axis] = dir + "/" + axis + ".yaml";
    std::filesystem::copy_file(config + "params_uncalibrated.yaml", files[axis]);
  }
  ros::NodeHandle pnh("template_triad/calibrator");
  pnh.setParam("triad_file", dir + "/triad.yaml");
  pnh.setParam("axis_parameter_files", files);
  {
    ASSERT_TRUE(TriadCalibratorRos::selected(pnh));
    TriadCalibratorRos node(ros::NodeHandle("template_triad"), pnh);
    EXPECT_EQ(node.parameters().defaultedKeys(), Keys{}) << "keys config/calibrator.yaml lacks";
    EXPECT_EQ(node.parameters().unknownKeys(), Keys{});
    EXPECT_GT(node.parameters().readKeys().size(), 45u);
  }
  std::filesystem::remove_all(dir);
}

TEST(ParameterTemplateTest, DriverSimTemplateIsComplete) {
  DriverSimRos node(ros::NodeHandle("template"), ros::NodeHandle("template/driver_sim"), false);
  EXPECT_EQ(node.parameters().defaultedKeys(), Keys{}) << "keys config/driver_sim.yaml lacks";
  EXPECT_EQ(node.parameters().unknownKeys(), Keys{});
}

// The same template serves a triad scenario: the node reads it whole and the triad section is the
// core parser's.
TEST(ParameterTemplateTest, DriverSimTemplateIsCompleteForATriad) {
  DriverSimRos node(ros::NodeHandle("triad_template"), ros::NodeHandle("triad_template/driver_sim"), false);
  EXPECT_EQ(node.parameters().defaultedKeys(), Keys{}) << "keys config/driver_sim.yaml lacks";
  EXPECT_EQ(node.parameters().unknownKeys(), Keys{});
}

TEST(ParameterTemplateTest, TriadTemplateIsComplete) {
  TriadRos node(ros::NodeHandle("template"), ros::NodeHandle("template/triad"));
  EXPECT_EQ(node.parameters().defaultedKeys(), Keys{}) << "keys config/triad_node.yaml lacks";
  EXPECT_EQ(node.parameters().unknownKeys(), Keys{}) << "keys config/triad_node.yaml has that the node does not read";
  EXPECT_GT(node.parameters().readKeys().size(), 10u);
}

TEST(ParameterTemplateTest, TyposAreUnknownKeys) {
  ProcessorRos node(ros::NodeHandle("typo"), ros::NodeHandle("typo/processor"));
  EXPECT_EQ(node.parameters().unknownKeys(), (Keys{"bias_capture/durration", "max_gapp"}));
}

TEST(ParameterTemplateTest, MistypedValuesAreRefused) {
  // YAML reads 1.0e6 (no exponent sign) as text: it must not fall back to the default silently.
  ros::NodeHandle("mistyped/processor").setParam("max_amplitude", std::string("1.0e6"));
  ros::NodeHandle("mistyped/processor")
      .setParam("parameter_file", std::string(HRG_GYRO_SOURCE_DIR) + "/config/params_uncalibrated.yaml");
  try {
    ProcessorRos node(ros::NodeHandle("mistyped"), ros::NodeHandle("mistyped/processor"));
    FAIL() << "a text value for ~max_amplitude was accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("max_amplitude"), std::string::npos) << e.what();
  }
}

TEST(ParameterTemplateTest, DefaultsAreListedWithoutTemplate) {
  ProcessorRos node(ros::NodeHandle("bare"), ros::NodeHandle("bare/processor"));
  const Keys defaulted = node.parameters().defaultedKeys();
  EXPECT_NE(std::find(defaulted.begin(), defaulted.end(), "max_gap"), defaulted.end());
  EXPECT_NE(std::find(defaulted.begin(), defaulted.end(), "bias_capture/duration"), defaulted.end());
  EXPECT_EQ(std::find(defaulted.begin(), defaulted.end(), "parameter_file"), defaulted.end());
}

}  // namespace
}  // namespace hrg_gyro

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "parameter_templates_test");
  ros::AsyncSpinner spinner(1);
  spinner.start();
  return RUN_ALL_TESTS();
}

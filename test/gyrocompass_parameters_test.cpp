// The gyrocompass node (GyrocompassRos) on its parameters: its template is complete and exact (every
// key read, none unknown), and each bad value or unknown key, at the top level or in a section, is
// refused at start-up with the key named, never started with a setting it does not understand.
#include <gtest/gtest.h>
#include <ros/ros.h>

#include <string>
#include <vector>

#include "hrg_gyro/ros/gyrocompass_ros.h"

namespace hrg_gyro {
namespace {

using Keys = std::vector<std::string>;

/// The message of the exception the constructor throws in namespace `name` ("" if it starts).
std::string refusal(const std::string& name) {
  try {
    GyrocompassRos node(ros::NodeHandle(name), ros::NodeHandle(name + "/gyrocompass"));
  } catch (const std::exception& e) {
    return e.what();
  }
  return std::string();
}

/// A namespace no case has used yet (one counter for every instantiation of expectRefused).
std::string freshName() {
  static int n = 0;
  return "bad_" + std::to_string(++n);
}

/// The smallest set that starts: a latitude and a noise model (every term given, the accelerometer's
/// sigmas, the hold's scale-factor sigma).
void setMinimal(ros::NodeHandle pnh, double latitude) {
  pnh.setParam("latitude", latitude);
  for (const char* key :
       {"noise/angle_random_walk", "noise/rate_random_walk", "noise/residual_bias", "noise/residual_drift_harmonics",
        "level/accelerometer_bias_sigma", "level/accelerometer_mounting_sigma"}) {
    pnh.setParam(key, 1e-8);
  }
  pnh.setParam("hold/enabled", true);
  pnh.setParam("hold/scale_factor_sigma", 1e-6);
}

/// A fresh namespace with a valid minimal set, then `key` set to `value`: refused naming `named`.
template <typename T>
void expectRefused(const std::string& key, const T& value, const std::string& named) {
  const std::string name = freshName();
  ros::NodeHandle pnh(name + "/gyrocompass");
  setMinimal(pnh, 0.9);
  pnh.setParam(key, value);
  const std::string message = refusal(name);
  EXPECT_NE(message.find("gyrocompass: ~" + named), std::string::npos) << key << ": " << message;
}

TEST(GyrocompassParameters, TheTemplateIsCompleteAndExact) {
  GyrocompassRos node(ros::NodeHandle("template"), ros::NodeHandle("template/gyrocompass"));
  EXPECT_EQ(node.parameters().defaultedKeys(), Keys{}) << "keys config/gyrocompass.yaml lacks";
  EXPECT_EQ(node.parameters().unknownKeys(), Keys{}) << "keys config/gyrocompass.yaml has that the node does not read";
  EXPECT_GT(node.parameters().readKeys().size(), 35u);
}

TEST(GyrocompassParameters, AMinimalSetStarts) {
  setMinimal(ros::NodeHandle("minimal/gyrocompass"), -0.5);
  EXPECT_EQ(refusal("minimal"), "");
}

TEST(GyrocompassParameters, WithoutANoiseModelItDoesNotStart) {
  // The template alone claims no precision: it names the first term nobody measured.
  const std::string alone = refusal("template_alone");
  EXPECT_NE(alone.find("gyrocompass: ~noise/angle_random_walk: rad/sqrt(s): not given"), std::string::npos) << alone;
  // Each term, the level's sigmas and the hold's.
  for (const char* key :
       {"noise/rate_random_walk", "noise/residual_bias", "noise/residual_drift_harmonics",
        "level/accelerometer_bias_sigma", "level/accelerometer_mounting_sigma", "hold/scale_factor_sigma"}) {
    const std::string name = freshName();
    ros::NodeHandle pnh(name + "/gyrocompass");
    setMinimal(pnh, 0.9);
    pnh.deleteParam(key);
    const std::string message = refusal(name);
    EXPECT_NE(message.find(std::string("gyrocompass: ~") + key), std::string::npos) << key << ": " << message;
  }
  // A calibrated triad file gives the residual bias.
  const std::string name = freshName();
  ros::NodeHandle pnh(name + "/gyrocompass");
  setMinimal(pnh, 0.9);
  pnh.deleteParam("noise/residual_bias");
  pnh.setParam("triad_file", std::string(HRG_GYRO_SOURCE_DIR) + "/test/models/triad_calibrated.yaml");
  EXPECT_EQ(refusal(name), "");
}

TEST(GyrocompassParameters, BadAndUnknownKeysAreRefusedByName) {
  EXPECT_NE(refusal("no_latitude").find("gyrocompass: ~latitude"), std::string::npos) << refusal("no_latitude");
  expectRefused("latitud", 0.9, "latitud");
  expectRefused("latitude", 2.0, "latitude");
  expectRefused("mode", std::string("gyro"), "mode");
  expectRefused("noise/residual_bias", -1e-9, "noise.residual_bias");
  expectRefused("estimator", std::string("kalman"), "estimator");
  expectRefused("max_earth_sigmas", 0.0, "max_earth_sigmas");
  expectRefused("motion/max_excluded", 0.95, "motion.max_excluded");
  expectRefused("level/accelerometer_mounting_sigma", -1e-3, "level.accelerometer_mounting_sigma");
  expectRefused("hold/scale_factor_sigma", 0.5, "hold/scale_factor_sigma");
  expectRefused("hold/max_bridge", 2.0, "hold/max_bridge");
  expectRefused("noise/residual_biass", 1e-9, "noise.residual_biass");
  expectRefused("level/source", std::string("magnetometer"), "level.source");
  expectRefused("motion/max_scatter", 0.5, "motion.max_scatter");
  expectRefused("hold/covariance_interval", 0.0, "hold/covariance_interval");
  expectRefused("hold/enable", true, "hold/enable");
  expectRefused("queue_size", 0, "queue_size");
  expectRefused("stall_timeout", 0.0, "stall_timeout");
  expectRefused("triad_file", std::string("/nonexistent/triad.yaml"), "triad_file");
  expectRefused("mode", std::string("sweep"), "mode sweep needs ~triad_file");
}

}  // namespace
}  // namespace hrg_gyro

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "gyrocompass_parameters_test");
  ros::AsyncSpinner spinner(1);
  spinner.start();
  return RUN_ALL_TESTS();
}

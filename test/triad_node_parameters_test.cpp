// The triad node (TriadRos) on bad numeric parameters: each is refused at start-up with the key, the
// rule and the value named, as the processor refuses its own, never started silently with a queue of
// 0, a NaN timeout or an infinite rate. A valid set (also on the edges of each rule) starts.
#include <gtest/gtest.h>
#include <ros/ros.h>

#include <cmath>
#include <string>
#include <vector>

#include "hrg_gyro/ros/triad_ros.h"

namespace hrg_gyro {
namespace {

using Keys = std::vector<std::string>;

class TriadNodeParameters : public ::testing::Test {
 protected:
  /// A fresh private namespace with the nominal triad file.
  static ros::NodeHandle node(const std::string& name) {
    ros::NodeHandle pnh(name + "/triad");
    pnh.setParam("triad_file", std::string(HRG_GYRO_SOURCE_DIR) + "/config/triad.yaml");
    return pnh;
  }

  /// The message of the exception the constructor throws ("" if it does not).
  static std::string refusal(const std::string& name) {
    try {
      TriadRos triad(ros::NodeHandle(name), ros::NodeHandle(name + "/triad"));
    } catch (const std::exception& e) {
      return e.what();
    }
    return std::string();
  }

  /// `key` set to `value` alone is refused, the message naming the key and `expected` text.
  /// A namespace no case has used yet (one counter for every instantiation of expectRefused).
  static std::string freshName() {
    static int n = 0;
    return "bad_" + std::to_string(++n);
  }

  template <typename T>
  static void expectRefused(const std::string& key, const T& value, const std::string& expected) {
    const std::string name = freshName();
    node(name).setParam(key, value);
    const std::string message = refusal(name);
    EXPECT_NE(message.find("triad: ~" + key), std::string::npos) << key << " = " << value << ": " << message;
    EXPECT_NE(message.find(expected), std::string::npos) << key << " = " << value << ": " << message;
  }
};

TEST_F(TriadNodeParameters, AValidSetStartsOnTheEdgesOfEachRule) {
  ros::NodeHandle pnh = node("edges");
  pnh.setParam("queue_size", 1);
  pnh.setParam("max_pending", 1);
  pnh.setParam("max_unpaired", 1);
  pnh.setParam("rate_tolerance", 0.0);
  pnh.setParam("stamp_tolerance", 0.0);
  pnh.setParam("diagnostic_period", 3600.0);
  pnh.setParam("stall_timeout", 1e-3);
  pnh.setParam("expected_rate", 1e-3);
  {
    TriadRos triad(ros::NodeHandle("edges"), pnh);
    EXPECT_EQ(triad.parameters().unknownKeys(), Keys{});
  }
  pnh.setParam("rate_tolerance", 1.0);
  pnh.setParam("diagnostic_period", 1e-3);
  EXPECT_EQ(refusal("edges"), "");
}

TEST_F(TriadNodeParameters, QueuesAndCountsMustHoldOne) {
  expectRefused("queue_size", 0, "must be at least 1 (messages), not 0");
  expectRefused("queue_size", -1, "must be at least 1 (messages), not -1");
  expectRefused("max_pending", 0, "must be at least 1");
  expectRefused("max_unpaired", 0, "must be at least 1");
  expectRefused("max_unpaired", -5, "not -5");
}

TEST_F(TriadNodeParameters, TimesAndRatesMustBePositiveAndFinite) {
  expectRefused("stall_timeout", NAN, "must be a positive finite number (s), not nan");
  expectRefused("stall_timeout", 0.0, "not 0");
  expectRefused("stall_timeout", -1.0, "not -1");
  expectRefused("stall_timeout", INFINITY, "not inf");
  expectRefused("expected_rate", INFINITY, "must be a positive finite number (Hz), not inf");
  expectRefused("expected_rate", NAN, "not nan");
  expectRefused("expected_rate", 0.0, "not 0");
  expectRefused("rate_tolerance", NAN, "must be in [0, 1] (relative), not nan");
  expectRefused("rate_tolerance", -0.1, "not -0.1");
  expectRefused("rate_tolerance", 1.5, "not 1.5");
  expectRefused("diagnostic_period", 0.0, "must be in (0, 3600] s, not 0");
  expectRefused("diagnostic_period", -1.0, "not -1");
  expectRefused("diagnostic_period", NAN, "not nan");
  expectRefused("diagnostic_period", INFINITY, "not inf");
}

TEST_F(TriadNodeParameters, TheCombinersSettingsAreRefusedNamingTheKey) {
  expectRefused("stamp_tolerance", NAN, "must be >= 0");
  expectRefused("stamp_tolerance", -1e-3, "must be >= 0");
  expectRefused("max_wait", 0.0, "must be positive");
  expectRefused("max_wait", INFINITY, "must be positive");
  expectRefused("initial_angular_velocity_variance", 0.0, "must be in [1e-20, 1e12]");
  expectRefused("initial_angular_velocity_variance", NAN, "must be in [1e-20, 1e12]");
  expectRefused("initial_angular_velocity_variance", 5e-324, "must be in [1e-20, 1e12]");
  expectRefused("max_rate", INFINITY, "must be positive");
  expectRefused("backward_reset", NAN, "must be positive");
  expectRefused("forward_jump", 0.0, "must be positive");
  expectRefused("jump_persist", 0, "must be in [1, 1000]");
  expectRefused("angular_velocity_variance", 0.0, "must be positive");
  expectRefused("angular_velocity_variance", NAN, "must be positive");
}

TEST_F(TriadNodeParameters, AMistypedNumberIsRefused) {
  // YAML reads 1.0e6 (no exponent sign) as text: it must not fall back to the default.
  expectRefused("queue_size", std::string("1.0e6"), "wrong type");
  expectRefused("stall_timeout", std::string("0.5 s"), "wrong type");
}

}  // namespace
}  // namespace hrg_gyro

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "triad_node_parameters_test");
  ros::AsyncSpinner spinner(1);
  spinner.start();
  return RUN_ALL_TESTS();
}

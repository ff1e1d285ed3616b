// The triad file: the equation and every key emitted and read back exactly, the nominal triad from
// the minimal file, every bad key named (axis names that are no ROS name component among them), and
// the atomic save that refuses an invalid triad and keeps the previous file.
#include "hrg_gyro/core/model/triad_file.h"

#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include <cstdio>
#include <fstream>
#include <string>

#include "hrg_gyro/core/common/yaml_field.h"

namespace hrg_gyro {
namespace core {
namespace {

TriadParameters sample() {
  TriadParameters t;
  t.frame_id = "imu_body";
  t.axes = {{"gx", "gy", "gz"}};
  t.axis_to_body << 1.000002, -3e-5, 1.2e-5, 4e-5, 0.999998, -2e-5, -1e-5, 2.5e-5, 1.0000001;
  t.bias << 1e-7, -2e-7, 3e-8;
  t.axis_to_body_std.setConstant(1.5e-6);
  t.bias_std << 1e-8, 1e-8, 2e-8;
  t.calibration.method = ParameterOrigin::manual();
  t.calibration.time = "2026-11-25T12:00:00Z";
  t.calibration.source = "bench 3";
  return t;
}

std::string refusedKey(const std::string& yaml) {
  try {
    parseTriadParameters(YAML::Load(yaml));
  } catch (const ConfigError& e) {
    return e.key();
  }
  return "";
}

const char* kValid =
    "frame_id: imu_link\naxes: [x, y, z]\naxis_to_body: [[1, 0, 0], [0, 1, 0], [0, 0, 1]]\nbias: [0, 0, 0]\n";

TEST(TriadFileTest, EmitsTheEquationAndReadsBackExactly) {
  const TriadParameters t = sample();
  const std::string text = emitTriadParameters(t);
  EXPECT_NE(text.find("omega_body = M omega_axis - bias"), std::string::npos) << text;
  EXPECT_NE(text.find("misalignment A_ij"), std::string::npos) << text;
  EXPECT_EQ(parseTriadParameters(YAML::Load(text)), t);
  // A = M^-1 is the axes' directions: M A = I.
  EXPECT_LT((t.axis_to_body * t.bodyToAxis() - Eigen::Matrix3d::Identity()).norm(), 1e-15);
}

TEST(TriadFileTest, TheMinimalFileIsTheNominalTriad) {
  const TriadParameters t = parseTriadParameters(YAML::Load(kValid));
  EXPECT_EQ(t.axis_to_body, Eigen::Matrix3d::Identity());
  EXPECT_EQ(t.bias, Eigen::Vector3d::Zero());
  EXPECT_TRUE(t.calibration.method.isNone());
}

TEST(TriadFileTest, EveryBadKeyIsNamed) {
  const std::string v = kValid;
  auto with = [&](const std::string& key, const std::string& value) {
    YAML::Node n = YAML::Load(v);
    n[key] = YAML::Load(value);
    YAML::Emitter e;
    e << n;
    return std::string(e.c_str());
  };
  EXPECT_EQ(refusedKey(v + "axis_to_bdy: 1\n"), "axis_to_bdy");  // a typo
  EXPECT_EQ(refusedKey(with("frame_id", "\"/imu\"")), "frame_id");
  EXPECT_EQ(refusedKey(with("frame_id", "\"imu link\"")), "frame_id");
  EXPECT_EQ(refusedKey(with("axes", "[x, y]")), "axes");
  EXPECT_EQ(refusedKey(with("axes", "[x, x, z]")), "axes[1]");
  EXPECT_EQ(refusedKey(with("axis_to_body", "[[1, 0, 0], [0, 1, 0]]")), "axis_to_body");
  EXPECT_EQ(refusedKey(with("axis_to_body", "[[1, 0, 0], [0, 1, 0], [0, .nan, 1]]")), "axis_to_body[2][1]");
  // Axes swapped (y and x): far from the identity.
  EXPECT_EQ(refusedKey(with("axis_to_body", "[[0, 1, 0], [1, 0, 0], [0, 0, 1]]")), "axis_to_body");
  EXPECT_EQ(refusedKey(with("bias", "[0, 0]")), "bias");
  EXPECT_EQ(refusedKey(with("bias", "[0, 0, 1]")), "bias");  // 1 rad/s: deg/s taken for rad/s?
  EXPECT_EQ(refusedKey(with("bias_std", "[0, -1, 0]")), "bias_std");
  EXPECT_EQ(refusedKey(with("calibration", "{method: magic}")), "calibration.method");
}

// The triad node subscribes `<axis>/output` and a launch puts each axis's processor in the namespace
// `<axis>`: a name that is no ROS name component would kill the node when it makes the topic.
TEST(TriadFileTest, AxisNamesAreRosNameComponents) {
  auto axes = [](const std::string& second) {
    YAML::Node n = YAML::Load(kValid);
    n["axes"][1] = second;
    YAML::Emitter e;
    e << n;
    return std::string(e.c_str());
  };
  for (const std::string& bad :
       {std::string(".."), std::string("~y"), std::string("y:z"), std::string("y z"), std::string(" y"),
        std::string("y\t"), std::string("y\x01"), std::string("y\x7f"), std::string("y/z"), std::string("/y"),
        std::string("1y"), std::string("_y"), std::string("y-z"), std::string("y.z"), std::string("\xc3\xbf"),
        std::string("y\xc3\xbf"), std::string("")}) {
    try {
      parseTriadParameters(YAML::Load(axes(bad)));
      ADD_FAILURE() << "axis name '" << bad << "' accepted";
    } catch (const ConfigError& e) {
      EXPECT_EQ(e.key(), "axes[1]") << bad;
      EXPECT_NE(std::string(e.what()).find("axes[1]: "), std::string::npos) << e.what();
      EXPECT_NE(e.problem().find("a letter, then letters, digits or '_'"), std::string::npos) << e.what();
    }
  }
  // Control characters are shown escaped, never written raw into a log line.
  try {
    parseTriadParameters(YAML::Load(axes("y\x1b[2J")));
    ADD_FAILURE() << "an escape sequence accepted";
  } catch (const ConfigError& e) {
    EXPECT_NE(e.problem().find("'y\\x1B[2J'"), std::string::npos) << e.problem();
    EXPECT_EQ(e.problem().find('\x1b'), std::string::npos);
  }
  for (const char* good : {"y", "Y", "gyro_2", "y2", "axis_B_10"}) {
    EXPECT_EQ(parseTriadParameters(YAML::Load(axes(good))).axes[1], good);
  }
  EXPECT_TRUE(isValidAxisName("x"));
  EXPECT_FALSE(isValidAxisName("x."));
  // Distinct, as written (ROS names are case-sensitive).
  EXPECT_EQ(refusedKey(axes("x")), "axes[1]");
  EXPECT_EQ(parseTriadParameters(YAML::Load(axes("X"))).axes[1], "X");
}

TEST(TriadFileTest, SavedAtomicallyAndLoadedBack) {
  const std::string dir = ::testing::TempDir();
  const std::string path = dir + "/triad_file_test.yaml";
  std::remove(path.c_str());
  std::remove((path + ".bak").c_str());
  const TriadParameters t = sample();
  saveTriadFile(path, t);
  EXPECT_EQ(loadTriadFile(path), t);
  TriadParameters u = t;
  u.bias(2) = 5e-8;
  saveTriadFile(path, u);
  EXPECT_EQ(loadTriadFile(path), u);
  EXPECT_EQ(loadTriadFile(path + ".bak"), t);
  TriadParameters bad = t;
  bad.axis_to_body(0, 1) = 0.5;
  EXPECT_THROW(saveTriadFile(path, bad), std::runtime_error);
  EXPECT_EQ(loadTriadFile(path), u);  // untouched
  std::remove(path.c_str());
  std::remove((path + ".bak").c_str());
}

}  // namespace
}  // namespace core
}  // namespace hrg_gyro

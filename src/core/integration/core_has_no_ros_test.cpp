// The core library must build and run without ROS: no file under a core/ folder may include a ROS
// header (roscpp, messages, nodelet, rosbag, diagnostics, pluginlib, or this package's messages).
#include <dirent.h>
#include <gtest/gtest.h>

#include <fstream>
#include <regex>
#include <string>
#include <vector>

namespace {

void listFiles(const std::string& dir, std::vector<std::string>* out) {
  DIR* d = opendir(dir.c_str());
  if (!d) return;
  while (dirent* e = readdir(d)) {
    const std::string name = e->d_name;
    if (name == "." || name == "..") continue;
    const std::string path = dir + "/" + name;
    if (e->d_type == DT_DIR) {
      listFiles(path, out);
    } else {
      out->push_back(path);
    }
  }
  closedir(d);
}

TEST(CoreLayout, NoRosIncludesUnderCore) {
  const std::string root = HRG_GYRO_SOURCE_DIR;
  std::vector<std::string> files;
  listFiles(root + "/include/hrg_gyro/core", &files);
  listFiles(root + "/src/core", &files);
  ASSERT_GT(files.size(), 20u);
  const std::regex ros_include(
      R"(^\s*#\s*include\s*[<"](ros/|roscpp|rosbag/|nodelet/|pluginlib/|diagnostic_updater/|diagnostic_msgs/|)"
      R"(std_msgs/|sensor_msgs/|std_srvs/|rosgraph_msgs/|message_filters/|hrg_gyro/[A-Z]))");
  for (const auto& path : files) {
    std::ifstream in(path);
    std::string line;
    int n = 0;
    while (std::getline(in, line)) {
      ++n;
      EXPECT_FALSE(std::regex_search(line, ros_include)) << path << ":" << n << ": " << line;
    }
  }
}

}  // namespace

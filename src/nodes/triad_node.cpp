// The triad node: a thin main around hrg_gyro::TriadRos (also available as the nodelet hrg_gyro/Triad).
#include <ros/ros.h>

#include "hrg_gyro/ros/triad_ros.h"

int main(int argc, char** argv) {
  ros::init(argc, argv, "triad");
  ros::NodeHandle nh, pnh("~");
  try {
    hrg_gyro::TriadRos node(nh, pnh);
    ros::spin();  // services and diagnostics; the axes' topics have their own input thread
  } catch (const std::exception& e) {
    ROS_FATAL("%s", e.what());
    return 1;
  }
  return 0;
}

// The session_monitor node: a thin main around hrg_gyro::SessionMonitorRos (also available as a nodelet).
#include <ros/ros.h>

#include "hrg_gyro/ros/session_monitor_ros.h"

int main(int argc, char** argv) {
  ros::init(argc, argv, "session_monitor");
  ros::NodeHandle nh, pnh("~");
  try {
    hrg_gyro::SessionMonitorRos node(nh, pnh);
    ros::spin();
  } catch (const std::exception& e) {
    ROS_FATAL("%s", e.what());
    return 1;
  }
  return 0;
}

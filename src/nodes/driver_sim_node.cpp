// The driver_sim node: a thin main around hrg_gyro::DriverSimRos (also available as a nodelet).
#include <ros/ros.h>

#include "hrg_gyro/ros/driver_sim_ros.h"

int main(int argc, char** argv) {
  ros::init(argc, argv, "driver_sim");
  ros::NodeHandle nh, pnh("~");
  try {
    hrg_gyro::DriverSimRos node(nh, pnh, true);
    ros::spin();
  } catch (const std::exception& e) {
    ROS_FATAL("%s", e.what());
    return 1;
  }
  return 0;
}

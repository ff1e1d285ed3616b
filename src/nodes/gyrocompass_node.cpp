// The gyrocompass node: a thin main around hrg_gyro::GyrocompassRos (also available as the nodelet
// hrg_gyro/Gyrocompass).
#include <ros/ros.h>

#include "hrg_gyro/ros/gyrocompass_ros.h"

int main(int argc, char** argv) {
  ros::init(argc, argv, "gyrocompass");
  ros::NodeHandle nh, pnh("~");
  try {
    hrg_gyro::GyrocompassRos node(nh, pnh);
    ros::spin();
  } catch (const std::exception& e) {
    ROS_FATAL("%s", e.what());
    return 1;
  }
  return 0;
}

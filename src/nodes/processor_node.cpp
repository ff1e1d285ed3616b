// The processor node: a thin main around hrg_gyro::ProcessorRos (also available as a nodelet).
#include <ros/ros.h>

#include "hrg_gyro/ros/processor_ros.h"

int main(int argc, char** argv) {
  ros::init(argc, argv, "processor");
  ros::NodeHandle nh, pnh("~");
  try {
    hrg_gyro::ProcessorRos node(nh, pnh);
    // Two threads: ~capture_bias waits seconds for its samples; diagnostics and ~reload go on.
    ros::MultiThreadedSpinner spinner(2);
    spinner.spin();
  } catch (const std::exception& e) {
    ROS_FATAL("%s", e.what());
    return 1;
  }
  return 0;
}

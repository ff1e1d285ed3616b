// The calibrator node: a thin main around hrg_gyro::CalibratorRos, or hrg_gyro::TriadCalibratorRos
// when ~method is triad (also available as a nodelet).
#include <ros/ros.h>

#include "hrg_gyro/ros/calibrator_ros.h"
#include "hrg_gyro/ros/triad_calibrator_ros.h"

int main(int argc, char** argv) {
  ros::init(argc, argv, "calibrator");
  ros::NodeHandle nh, pnh("~");
  try {
    if (hrg_gyro::TriadCalibratorRos::selected(pnh)) {
      hrg_gyro::TriadCalibratorRos node(nh, pnh);
      ros::spin();
    } else {
      hrg_gyro::CalibratorRos node(nh, pnh);
      ros::spin();
    }
  } catch (const std::exception& e) {
    ROS_FATAL("%s", e.what());
    return 1;
  }
  return 0;
}

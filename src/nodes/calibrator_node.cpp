// The calibrator node: a thin main around hrg_gyro::CalibratorRos, or hrg_gyro::TriadCalibratorRos
// when ~method is triad (also available as a nodelet).
// On SIGINT (roslaunch's stop, Ctrl-C) a field run's virtual rotation is stopped while ROS can
// still publish the command, then the node shuts down as ROS's own handler would.
#include <ros/ros.h>

#include <csignal>

#include "hrg_gyro/ros/calibrator_ros.h"
#include "hrg_gyro/ros/triad_calibrator_ros.h"

namespace {
volatile std::sig_atomic_t g_sigint = 0;
void onSigint(int) { g_sigint = 1; }
}  // namespace

int main(int argc, char** argv) {
  ros::init(argc, argv, "calibrator", ros::init_options::NoSigintHandler);
  std::signal(SIGINT, onSigint);
  ros::NodeHandle nh, pnh("~");
  try {
    if (hrg_gyro::TriadCalibratorRos::selected(pnh)) {
      hrg_gyro::TriadCalibratorRos node(nh, pnh);
      const ros::WallTimer stop = nh.createWallTimer(ros::WallDuration(0.05), [](const ros::WallTimerEvent&) {
        if (g_sigint) ros::requestShutdown();
      });
      ros::spin();
    } else {
      hrg_gyro::CalibratorRos node(nh, pnh);
      const ros::WallTimer stop = nh.createWallTimer(ros::WallDuration(0.05), [&node](const ros::WallTimerEvent&) {
        if (!g_sigint) return;
        node.stopVirtualRotation("the node was interrupted");
        ros::WallDuration(0.2).sleep();  // the command on its way before the connections close
        ros::requestShutdown();
      });
      ros::spin();
    }
  } catch (const std::exception& e) {
    ROS_FATAL("%s", e.what());
    return 1;
  }
  return 0;
}

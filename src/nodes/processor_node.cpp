// The processor node: a thin main around hrg_gyro::ProcessorRos (also available as a nodelet).
#include <ros/ros.h>

#include "hrg_gyro/ros/processor_ros.h"

int main(int argc, char** argv) {
  ros::init(argc, argv, "processor");
  ros::NodeHandle nh, pnh("~");
  try {
    hrg_gyro::ProcessorRos node(nh, pnh);
    // ~shutdown_when_idle: a replay ends once the processor is through the bag (playback.launch),
    // not when rosbag play is: a processor that lags under load still has samples queued then.
    ros::WallTimer idle_timer;
    if (node.shutdownWhenIdle() > 0.0) {
      idle_timer = nh.createWallTimer(ros::WallDuration(0.1), [&node](const ros::WallTimerEvent&) {
        if (!node.idleFor(node.shutdownWhenIdle())) return;
        ROS_INFO("processor: no channel amplitudes for %.1f s after the last (~shutdown_when_idle): done",
                 node.shutdownWhenIdle());
        ros::requestShutdown();
      });
    }
    // Two threads: ~capture_bias waits seconds for its samples; diagnostics and ~reload go on.
    ros::MultiThreadedSpinner spinner(2);
    spinner.spin();
  } catch (const std::exception& e) {
    ROS_FATAL("%s", e.what());
    return 1;
  }
  return 0;
}

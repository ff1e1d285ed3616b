// The timer that drives a node's diagnostic_updater, safe under a looping bag.
//
// diagnostic_updater::Updater::update() publishes when now >= the next due time; when sim time
// jumps back (rosbag play -l), that due time lies a whole bag in the future and the node would go
// silent for a pass. The timer notices the jump and forces an update, which re-arms the period.
#pragma once

#include <diagnostic_updater/diagnostic_updater.h>
#include <ros/ros.h>

namespace hrg_gyro {

inline ros::Timer createDiagnosticsTimer(ros::NodeHandle& nh, diagnostic_updater::Updater& updater) {
  // The updater publishes at its own ~diagnostic_period (1 s); this only gives it the chance.
  return nh.createTimer(ros::Duration(0.1), [&updater, last = ros::Time()](const ros::TimerEvent&) mutable {
    const ros::Time now = ros::Time::now();
    if (!last.isZero() && now < last) {
      updater.force_update();
    } else {
      updater.update();
    }
    last = now;
  });
}

}  // namespace hrg_gyro

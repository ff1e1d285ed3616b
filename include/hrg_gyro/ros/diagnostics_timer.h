// The timer that drives a node's diagnostic_updater, on the wall clock.
//
// diagnostic_updater::Updater::update() publishes when ROS time has reached its next due time. Two
// cases of sim time would silence it: /clock stopping (a paused or crashed bag player, a dead
// driver), when no diagnostic at all would say that the input stalled; and /clock jumping back (rosbag
// play -l), when the due time lies a whole bag in the future. So the timer runs on the wall clock:
// while ROS time advances it lets the updater keep its own period; when ROS time went back it
// forces an update (which re-arms the period); while ROS time stands still it forces one every
// period of wall time, stamped with the stopped clock.
#pragma once

#include <diagnostic_updater/diagnostic_updater.h>
#include <ros/ros.h>

namespace hrg_gyro {

inline ros::WallTimer createDiagnosticsTimer(ros::NodeHandle& nh, diagnostic_updater::Updater& updater) {
  struct Clocks {
    ros::Time last;             // ROS time at the previous tick
    ros::WallTime last_change;  // wall time when ROS time last moved
    ros::WallTime last_forced;  // wall time of the last update forced while ROS time stood still
  };
  // The updater publishes at its own ~diagnostic_period (1 s); this only gives it the chance.
  return nh.createWallTimer(ros::WallDuration(0.1), [&updater, c = Clocks()](const ros::WallTimerEvent&) mutable {
    const ros::Time now = ros::Time::now();
    const ros::WallTime wall = ros::WallTime::now();
    if (c.last_change.isZero()) c.last_change = wall;
    if (now < c.last) {
      updater.force_update();
      c.last_change = wall;
    } else if (now > c.last) {
      updater.update();
      c.last_change = wall;
    } else {
      const double period = updater.getPeriod();
      if ((wall - c.last_change).toSec() >= period && (wall - c.last_forced).toSec() >= period) {
        updater.force_update();
        c.last_forced = wall;
      }
    }
    c.last = now;
  });
}

}  // namespace hrg_gyro

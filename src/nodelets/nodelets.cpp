// The four wrappers as nodelets, for zero-copy pipelines in one manager. Each owns the same wrapper
// class as its node. The driver never shuts the manager down when its scenario ends; the session
// monitor does when ~shutdown_when_done asks for it (demos and tests).
#include <memory>

#include <nodelet/nodelet.h>
#include <pluginlib/class_list_macros.hpp>

#include "hrg_gyro/ros/calibrator_ros.h"
#include "hrg_gyro/ros/driver_sim_ros.h"
#include "hrg_gyro/ros/processor_ros.h"
#include "hrg_gyro/ros/session_monitor_ros.h"

namespace hrg_gyro {

class DriverSimNodelet : public nodelet::Nodelet {
  void onInit() override { impl_ = std::make_unique<DriverSimRos>(getNodeHandle(), getPrivateNodeHandle(), false); }
  std::unique_ptr<DriverSimRos> impl_;
};

class ProcessorNodelet : public nodelet::Nodelet {
  void onInit() override { impl_ = std::make_unique<ProcessorRos>(getNodeHandle(), getPrivateNodeHandle()); }
  std::unique_ptr<ProcessorRos> impl_;
};

class CalibratorNodelet : public nodelet::Nodelet {
  void onInit() override { impl_ = std::make_unique<CalibratorRos>(getNodeHandle(), getPrivateNodeHandle()); }
  std::unique_ptr<CalibratorRos> impl_;
};

class SessionMonitorNodelet : public nodelet::Nodelet {
  void onInit() override { impl_ = std::make_unique<SessionMonitorRos>(getNodeHandle(), getPrivateNodeHandle()); }
  std::unique_ptr<SessionMonitorRos> impl_;
};

}  // namespace hrg_gyro

PLUGINLIB_EXPORT_CLASS(hrg_gyro::DriverSimNodelet, nodelet::Nodelet)
PLUGINLIB_EXPORT_CLASS(hrg_gyro::ProcessorNodelet, nodelet::Nodelet)
PLUGINLIB_EXPORT_CLASS(hrg_gyro::CalibratorNodelet, nodelet::Nodelet)
PLUGINLIB_EXPORT_CLASS(hrg_gyro::SessionMonitorNodelet, nodelet::Nodelet)

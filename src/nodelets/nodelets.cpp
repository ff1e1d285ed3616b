// The six wrappers as nodelets (the calibrator's: one of two, by ~method), for zero-copy pipelines in one manager.
// Each owns the same wrapper class as its node. The driver never shuts the manager down when its scenario ends; the
// session monitor does when ~shutdown_when_done asks for it (demos and tests).
#include <nodelet/nodelet.h>

#include <exception>
#include <memory>
#include <pluginlib/class_list_macros.hpp>
#include <utility>

#include "hrg_gyro/ros/calibrator_ros.h"
#include "hrg_gyro/ros/driver_sim_ros.h"
#include "hrg_gyro/ros/gyrocompass_ros.h"
#include "hrg_gyro/ros/processor_ros.h"
#include "hrg_gyro/ros/session_monitor_ros.h"
#include "hrg_gyro/ros/triad_calibrator_ros.h"
#include "hrg_gyro/ros/triad_ros.h"

namespace hrg_gyro {

/// Builds a nodelet's wrapper in onInit. The nodelet manager reports a failed load without the
/// exception's message, so the reason is logged here (FATAL, under the nodelet's name) before the
/// exception goes on to fail the load as before.
class LoggingNodelet : public nodelet::Nodelet {
 protected:
  template <class Wrapper, class... Args>
  std::unique_ptr<Wrapper> make(Args&&... args) {
    try {
      return std::make_unique<Wrapper>(std::forward<Args>(args)...);
    } catch (const std::exception& e) {
      NODELET_FATAL("%s failed to start: %s", getName().c_str(), e.what());
      throw;
    }
  }
};

/// The common part of the nodelets that own one wrapper class.
template <class Wrapper>
class WrapperNodelet : public LoggingNodelet {
 protected:
  template <class... Args>
  void create(Args&&... args) {
    impl_ = make<Wrapper>(std::forward<Args>(args)...);
  }

 private:
  std::unique_ptr<Wrapper> impl_;
};

class DriverSimNodelet : public WrapperNodelet<DriverSimRos> {
  void onInit() override { create(getNodeHandle(), getPrivateNodeHandle(), false); }
};

class ProcessorNodelet : public WrapperNodelet<ProcessorRos> {
  void onInit() override { create(getNodeHandle(), getPrivateNodeHandle()); }
};

/// As the calibrator node: the triad wrapper when ~method is triad, the single-axis one otherwise.
class CalibratorNodelet : public LoggingNodelet {
  void onInit() override {
    if (TriadCalibratorRos::selected(getPrivateNodeHandle())) {
      triad_ = make<TriadCalibratorRos>(getNodeHandle(), getPrivateNodeHandle());
    } else {
      single_ = make<CalibratorRos>(getNodeHandle(), getPrivateNodeHandle());
    }
  }

  std::unique_ptr<CalibratorRos> single_;
  std::unique_ptr<TriadCalibratorRos> triad_;
};

class SessionMonitorNodelet : public WrapperNodelet<SessionMonitorRos> {
  void onInit() override { create(getNodeHandle(), getPrivateNodeHandle()); }
};

class TriadNodelet : public WrapperNodelet<TriadRos> {
  void onInit() override { create(getNodeHandle(), getPrivateNodeHandle()); }
};

class GyrocompassNodelet : public WrapperNodelet<GyrocompassRos> {
  void onInit() override { create(getNodeHandle(), getPrivateNodeHandle()); }
};

}  // namespace hrg_gyro

PLUGINLIB_EXPORT_CLASS(hrg_gyro::DriverSimNodelet, nodelet::Nodelet)
PLUGINLIB_EXPORT_CLASS(hrg_gyro::ProcessorNodelet, nodelet::Nodelet)
PLUGINLIB_EXPORT_CLASS(hrg_gyro::CalibratorNodelet, nodelet::Nodelet)
PLUGINLIB_EXPORT_CLASS(hrg_gyro::SessionMonitorNodelet, nodelet::Nodelet)
PLUGINLIB_EXPORT_CLASS(hrg_gyro::TriadNodelet, nodelet::Nodelet)
PLUGINLIB_EXPORT_CLASS(hrg_gyro::GyrocompassNodelet, nodelet::Nodelet)

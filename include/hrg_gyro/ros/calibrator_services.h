// What both calibrator wrappers (CalibratorRos, TriadCalibratorRos) offer beside their topics: the
// run services ~start (StartCalibration), ~finish and ~abort (std_srvs/Trigger), and diagnostics
// under hardware id hrg_gyro -- the run's own status and the process heap's -- published by the
// wall-clock diagnostics timer (diagnostics_timer.h).
#pragma once

#include <diagnostic_updater/diagnostic_updater.h>
#include <ros/ros.h>
#include <std_srvs/Trigger.h>

#include <functional>
#include <string>

#include "hrg_gyro/StartCalibration.h"
#include "hrg_gyro/ros/diagnostics_timer.h"
#include "hrg_gyro/ros/process_heap.h"

namespace hrg_gyro {

/// The run services, advertised on the calibrator's private handle.
struct CalibratorServices {
  ros::ServiceServer start, finish, abort;

  CalibratorServices() = default;
  /// The handlers are the calibrator's members (passed from inside it, where they are accessible).
  template <class Calibrator>
  CalibratorServices(ros::NodeHandle& pnh, Calibrator* calibrator,
                     bool (Calibrator::*on_start)(StartCalibration::Request&, StartCalibration::Response&),
                     bool (Calibrator::*on_finish)(std_srvs::Trigger::Request&, std_srvs::Trigger::Response&),
                     bool (Calibrator::*on_abort)(std_srvs::Trigger::Request&, std_srvs::Trigger::Response&))
      : start(pnh.advertiseService("start", on_start, calibrator)),
        finish(pnh.advertiseService("finish", on_finish, calibrator)),
        abort(pnh.advertiseService("abort", on_abort, calibrator)) {}
};

/// Adds the run's status `name` (filled by `status`) and the process heap's (trimmed every
/// `heap_trim_period` s; <= 0 never) to `updater`, and returns the timer that publishes them.
inline ros::WallTimer startCalibratorDiagnostics(
    ros::NodeHandle& nh, diagnostic_updater::Updater& updater, const std::string& name,
    std::function<void(diagnostic_updater::DiagnosticStatusWrapper&)> status, double heap_trim_period) {
  updater.setHardwareID("hrg_gyro");
  updater.add(name, std::move(status));
  addProcessHeapDiagnostic(updater, heap_trim_period);
  return createDiagnosticsTimer(nh, updater);
}

}  // namespace hrg_gyro

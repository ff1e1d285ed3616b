#include "hrg_gyro/ros/reload_record.h"

#include <ros/console.h>

namespace hrg_gyro {

void ReloadRecord::refuse(const std::string& why, std_srvs::Trigger::Response* res) {
  ++refusals_;
  last_error_ = why;
  res->success = false;
  res->message = "kept the previous " + kept_ + ": " + why;
  ROS_ERROR("%s: reload refused: %s", node_.c_str(), why.c_str());
}

void ReloadRecord::loaded() {
  ++loads_;
  last_error_.clear();
}

std::string ReloadRecord::refusalSummary() const {
  return "last reload refused, previous " + kept_ + " kept: " + last_error_;
}

void ReloadRecord::addCounts(diagnostic_updater::DiagnosticStatusWrapper& stat) const {
  stat.add("reloads", loads_);
  stat.add("refused reloads", refusals_);
}

}  // namespace hrg_gyro

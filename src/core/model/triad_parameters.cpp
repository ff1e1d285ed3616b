#include "hrg_gyro/core/model/triad_parameters.h"

#include <Eigen/Dense>

namespace hrg_gyro {
namespace core {
namespace {

bool isAsciiLetter(char c) { return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z'); }

}  // namespace

bool isValidAxisName(const std::string& name) {
  if (name.empty() || !isAsciiLetter(name.front())) return false;
  for (const char c : name) {
    if (!isAsciiLetter(c) && !(c >= '0' && c <= '9') && c != '_') return false;
  }
  return true;
}

bool isValidFrameId(const std::string& id) {
  if (id.empty() || id.front() == '/') return false;
  for (const unsigned char c : id) {
    if (c <= ' ' || c == 0x7f) return false;
  }
  return true;
}

Eigen::Matrix3d TriadParameters::bodyToAxis() const { return axis_to_body.inverse(); }

bool TriadParameters::operator==(const TriadParameters& o) const {
  return axes == o.axes && frame_id == o.frame_id && axis_to_body == o.axis_to_body && bias == o.bias &&
         axis_to_body_std == o.axis_to_body_std && bias_std == o.bias_std && calibration == o.calibration;
}

}  // namespace core
}  // namespace hrg_gyro

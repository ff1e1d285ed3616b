#include "hrg_gyro/core/model/axis_to_body_matrix.h"

#include <cmath>
#include <cstdio>

namespace hrg_gyro {
namespace core {

double largestMisalignment(const Eigen::Matrix3d& x) { return (x - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff(); }

std::string describeAlignment(const Eigen::Matrix3d& a) {
  char text[512];
  std::snprintf(text, sizeof text,
                "Read from A = M^-1 (the axes' directions in the body frame):\n"
                "  misalignment A_ij, rad: xy %.3e  xz %.3e  yx %.3e  yz %.3e  zx %.3e  zy %.3e\n"
                "  residual scale A_ii - 1: %.3e  %.3e  %.3e",
                a(0, 1), a(0, 2), a(1, 0), a(1, 2), a(2, 0), a(2, 1), a(0, 0) - 1.0, a(1, 1) - 1.0, a(2, 2) - 1.0);
  return text;
}

Eigen::Matrix3d axisToBodyStd(const Eigen::Matrix3d& m, const Eigen::Matrix3d& a_std) {
  Eigen::Matrix3d m_std = Eigen::Matrix3d::Zero();
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) {
      double v = 0.0;
      for (int k = 0; k < 3; ++k)
        for (int l = 0; l < 3; ++l) v += std::pow(m(i, k) * m(l, j) * a_std(k, l), 2);
      m_std(i, j) = std::sqrt(v);
    }
  return m_std;
}

}  // namespace core
}  // namespace hrg_gyro

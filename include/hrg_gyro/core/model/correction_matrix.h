// The amplitude correction Z~ = (E - P) Z of the paper's first refinement stage, and its estimation.
//
// Misplacement and gain errors map the channels exactly linearly, so an exact P exists with
// (E - P) = M^-1 and the structure (docs/math.md, 'Correction matrix')
//   P = [ p1 0 p3 0 ; 0 p1 0 p3 ; -p4 0 p2 0 ; 0 -p4 0 p2 ]   acting on (Ac, Bc, As, Bs),
// p1, p2 ~ channel gain errors, p3, p4 ~ misplacement half-sums. After (E - P) Z the 2 theta
// harmonics of the scale factor vanish; the 4 theta term of the pickoff nonlinearity stays and
// belongs in the K(theta) model.
#pragma once

#include <Eigen/Core>
#include <array>
#include <cstddef>
#include <string>

#include "hrg_gyro/core/model/wave_parameters.h"

namespace hrg_gyro {
namespace core {

struct CorrectionMatrix {
  std::array<double, 4> p{};  ///< p1, p2, p3, p4 (dimensionless)

  Eigen::Matrix4d matrix() const;
  bool isIdentity() const { return p[0] == 0.0 && p[1] == 0.0 && p[2] == 0.0 && p[3] == 0.0; }
  /// (E - P) z
  ChannelVector apply(const ChannelVector& z) const {
    double ac = z[kAc], bc = z[kBc], as = z[kAs], bs = z[kBs];
    apply(&ac, &bc, &as, &bs);
    return ChannelVector(ac, bc, as, bs);
  }
  /// (E - P) z in place on the four channels: doubles, or lanes of samples (each lane then gets the
  /// bits one sample gets).
  template <class V>
  void apply(V* ac, V* bc, V* as, V* bs) const {
    const V c_ac = (1.0 - p[0]) * *ac - p[2] * *as;
    const V c_bc = (1.0 - p[0]) * *bc - p[2] * *bs;
    const V c_as = p[3] * *ac + (1.0 - p[1]) * *as;
    const V c_bs = p[3] * *bc + (1.0 - p[1]) * *bs;
    *ac = c_ac;
    *bc = c_bc;
    *as = c_as;
    *bs = c_bs;
  }
  bool operator==(const CorrectionMatrix& o) const { return p == o.p; }
};

/// Linear least squares of || (E - P) Z_measured - Z_m || over generator pairs, accumulated as
/// normal equations (constant memory however long the generator sweep).
class CorrectionMatrixEstimator {
 public:
  struct Result {
    bool ok = false;
    std::string reason;  ///< why not ok
    CorrectionMatrix correction;
    std::array<double, 4> standard_error{};
    double residual_rms = 0.0;      ///< per channel amplitude, amplitude units
    double condition_number = 0.0;  ///< of the normal matrix, sqrt(lambda_max / lambda_min)
    std::size_t pairs = 0;
  };

  void add(const ChannelVector& measured, const ChannelVector& reference);
  std::size_t pairs() const { return pairs_; }
  void clear() { *this = CorrectionMatrixEstimator(); }
  /// max_condition: refuse a sweep that does not excite all four parameters (e.g. one angle only).
  Result solve(double max_condition = 1e6) const;

 private:
  Eigen::Matrix4d jtj_ = Eigen::Matrix4d::Zero();
  Eigen::Vector4d jty_ = Eigen::Vector4d::Zero();
  double yty_ = 0.0;
  std::size_t pairs_ = 0;
};

}  // namespace core
}  // namespace hrg_gyro

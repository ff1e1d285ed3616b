// Interpolation of a model coefficient over resonator-frequency nodes (the paper's K(theta, f)).
//
// The resonance frequency tracks the resonator temperature monotonically and is known to the
// electronics, so every coefficient of K and D may be given at a few frequency nodes f_j and
// interpolated between them. Both supported schemes (natural cubic spline, piecewise linear) are
// linear in the node values: value(f) = sum_j w_j(f) y_j. weights() exposes w_j(f), which lets one
// sincos-free weight computation serve every coefficient of a model and lets the calibrator fit node
// values directly by least squares. Outside [f_first, f_last] the end values are held (a model is
// not extrapolated beyond the temperatures it was calibrated at); inRange() tells the caller.
#pragma once

#include <Eigen/Core>
#include <cmath>
#include <string>
#include <vector>

namespace hrg_gyro {
namespace core {

enum class Interpolation { kNaturalCubicSpline, kPiecewiseLinear };
const char* toString(Interpolation kind);
/// Parses "natural_cubic_spline" / "piecewise_linear"; returns false for anything else.
bool parseInterpolation(const std::string& text, Interpolation* kind);

class FrequencyInterpolator {
 public:
  /// A single node: the constant interpolator (frequency independent).
  FrequencyInterpolator() : nodes_{0.0} {}
  /// Nodes must be finite and strictly increasing (throws std::invalid_argument otherwise).
  explicit FrequencyInterpolator(std::vector<double> nodes, Interpolation kind = Interpolation::kNaturalCubicSpline);

  const std::vector<double>& nodes() const { return nodes_; }
  std::size_t size() const { return nodes_.size(); }
  Interpolation kind() const { return kind_; }
  /// True when `f` lies within the nodes, where nothing is held. A single node is a constant,
  /// valid at every finite frequency (its one "node" is no calibrated range).
  bool inRange(double f) const {
    if (nodes_.size() == 1) return std::isfinite(f);
    return f >= nodes_.front() && f <= nodes_.back();
  }

  /// Writes size() weights such that value(f) = sum_j w[j] y_j. A non-finite f gets the weights of
  /// the first node (callers flag the missing frequency).
  void weights(double f, double* w) const;

  bool operator==(const FrequencyInterpolator& o) const { return nodes_ == o.nodes_ && kind_ == o.kind_; }

 private:
  std::vector<double> nodes_;
  Interpolation kind_ = Interpolation::kNaturalCubicSpline;
  /// Natural spline: second derivatives at the nodes = curvature_ * y.
  Eigen::MatrixXd curvature_;
};

}  // namespace core
}  // namespace hrg_gyro

// The chains of the increment regression: a session's samples into window means, one chain at a
// time, and the window increments of each chain once it ends.
//
// A chain is a stretch of one plateau without a gap: increments never span two chains. Each sample
// adds its trapezoid to the model's integrals (increment_model.h); the samples of a window are
// averaged, and consecutive window means differenced. Why increments of window means rather than the
// window means themselves: white wave-angle noise makes consecutive increments anti-correlated only
// at lag one, and angle random walk (rate noise) makes them white; the window means would instead
// carry a random walk along a whole chain. So the regression needs no intercept per chain and its
// errors are local.
//
// The table angle is taken as the weighted sum of the logged angle and the integral of the logged
// rate (with the chain's slope from the angle), weighed by what the session says of each source's
// errors; the means are held until the chain ends because the slope and the weights are known only
// then.
#pragma once

#include <Eigen/Core>
#include <cmath>
#include <cstddef>
#include <vector>

#include "hrg_gyro/core/common/units.h"
#include "hrg_gyro/core/estimation/increment_model.h"
#include "hrg_gyro/core/estimation/wave_angle_noise.h"
#include "hrg_gyro/core/model/harmonic_basis.h"

namespace hrg_gyro {
namespace core {

/// The difference of two consecutive window means of a chain.
struct WindowIncrement {
  Eigen::VectorXd dw;  ///< the model's columns, then y (IncrementModel::columns() + 1 entries)
  double dt = 0.0;     ///< s between the two means
  double t_mid = 0.0;  ///< s from the session's first sample to the middle of the two means
  double theta_mid = 0.0, dphi = 0.0;
  double count_before = 0.0, count_after = 0.0;  ///< samples in the two means
  bool follows = false;                          ///< an increment of the same chain comes before it
  int group = 0;
};

class WindowChains {
 public:
  explicit WindowChains(const IncrementModel& model);

  /// Starts a chain of plateau group `group` averaged over windows of `window` s (none may be open).
  void start(int group, double window);
  /// A sample of the open chain (see IncrementRegression::add).
  void add(const IncrementModel& model, Nanoseconds stamp, double theta, double phi, double phi_rate,
           int horizontal_slot, double psi);
  /// Closes the open chain (its last, partial window is left out); its increments, in order.
  std::vector<WindowIncrement> end(const IncrementModel& model);

  bool inChain() const { return in_chain_; }
  /// Window means of the open chain wait for its end.
  bool holdsMeans() const { return !chain_means_.empty(); }
  /// rad^2: an error of the angle that is smooth in time, counted against the angle when the two
  /// sources are weighed.
  void setAngleSmoothError(double variance) { angle_smooth_error_ = variance; }
  /// The angle's weight against the rate integral, time-weighted over the chains (1: the angle).
  double angleWeight() const;
  const std::vector<bool>& slotsSeen() const { return slot_seen_; }
  Nanoseconds sessionOrigin() const { return session_origin_; }
  /// s from the session's first sample to its last.
  double lastSessionTime() const { return last_session_time_; }
  const WaveAngleNoise& angleNoise() const { return noise_; }

 private:
  struct WindowMean {
    Eigen::VectorXd w;  // mean of (z, y): the raw columns until the chain ends, then the regression's
    double t = 0.0, theta = 0.0, phi = 0.0, count = 0.0;
    double t_session = 0.0;  // mean time from the session's first sample
    double phi_rate = 0.0;   // mean rate integral
    double x = 0.0;          // phi - phi_rate
  };
  struct LineSums {
    double n = 0.0, t = 0.0, tt = 0.0, x = 0.0, tx = 0.0;
  };

  /// The trapezoids from the previous sample of the chain to this one.
  void integrate(const IncrementModel& model, double t, double t_session, double phi, double phi_rate,
                 int horizontal_slot, double psi);
  /// The sample into its window's sums, the window closed when the sample starts the next.
  void sumIntoWindow(double t, double t_session, double theta, double phi, double phi_rate);
  void closeWindow();
  void clearWindowSums();
  /// The table's slope on the chain, from the angle: the rate integral keeps only its shape.
  double chainSlope() const;
  /// The chain's differences (angle - rate integral) into the session's, and the angle's weight.
  double weighSources(double slope);

  // The session's first sample: the trend's time origin.
  bool has_origin_ = false;
  Nanoseconds session_origin_ = 0;
  double last_session_time_ = 0.0;
  // The open chain.
  bool in_chain_ = false, has_sample_ = false;
  int group_ = 0;
  double window_ = 0.0;
  Nanoseconds origin_ = 0;
  double t_prev_ = 0.0, phi_prev_ = 0.0, theta_start_ = 0.0, session_t_prev_ = 0.0, phi_rate_prev_ = 0.0;
  int slot_prev_ = -1;
  double psi_prev_ = 0.0;
  std::vector<bool> slot_seen_;          // slots with samples
  std::vector<WindowMean> chain_means_;  // the open chain's, held until it ends
  LineSums line_;                        // of phi - phi_rate against t over the open chain
  bool chain_has_rate_ = true;
  HarmonicBasis basis_;
  Eigen::VectorXd cos_prev_, sin_prev_, cos_now_, sin_now_, integrals_;
  long window_index_ = 0;
  WindowMean sum_;
  WaveAngleNoise noise_;
  // The two table sources, judged over the session: consecutive differences of (angle - integral).
  double source_squares_ = 0.0, source_lag_ = 0.0;
  std::size_t source_count_ = 0, source_lag_count_ = 0;
  double angle_smooth_error_ = 0.0;
  double angle_weight_time_ = 0.0, weighted_chain_time_ = 0.0;
};

}  // namespace core
}  // namespace hrg_gyro

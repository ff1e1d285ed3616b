// The increment model: its columns, the integrals each sample adds to them, and its solution.
//
// The model d theta/dt = K(theta) dphi/dt + D(theta), with phi the body angle (table angle plus the
// Earth's vertical rate times t) and K, D harmonic in theta, integrates along the session to
//   theta(t) - theta(t0) = K0 Phi0 + sum_k (a_k Phic_k + b_k Phis_k) + D0 T + sum_k (c_k Tc_k + d_k Ts_k)
// with Phi0 = integral dphi, Phic_k = integral cos(k theta) dphi, Tc_k = integral cos(k theta) dt and
// so on, all from t0 to t. The identity is linear in the unknown coefficients, and it stays exact
// after averaging both sides over any window and after differencing consecutive window means. Each
// sample adds its trapezoid to the integrals, computed with the measured theta (at 1 kHz theta moves
// ~1e-4 rad per sample, so the trapezoid is exact to far below a ppm). No window or bin smoothing is
// left to correct, and table rate ripple cancels because the actual dphi enters.
//
// A bias that wanders through the session (a gyro warming up, a lab whose temperature drifts) is
// fitted with it as a polynomial in time, D0(t) = D0 + sum_j b_j (t - t_ref)^j, j = 1..trend order:
// its regressors are the integrals of (t - t_ref)^j dt, centred on the mean time of the increments
// (so D0 is the session's mean bias). A polynomial rather than an offset per plateau: within a
// plateau of constant rate an offset is indistinguishable from K0 times the rate, so per-plateau
// offsets would take K0 with them unless rests between plateaus pinned each one; a slow trend is
// separated from K by its time signature (the order of the plateau rates and the curvature it gives
// the wave angle within each plateau). How well the session separates it is measured: the trend's
// inflation of the K0 standard error, and their correlation.
//
// An axis slightly tilted from the table's axis also senses the Earth's horizontal rate, which turns
// with the table: Omega cos(latitude) (h_x cos psi + h_y sin psi), psi the heading of the platter's
// x (the table's azimuth minus its angle) and h the axis's small horizontal component in the platter
// frame, unknown and different in every fixture position. As theta moves with the table angle, that
// rate would land in D's harmonics. Where the caller asks (horizontal slots > 0, one per fixture
// position), each slot adds two columns, the integrals of cos psi dt and sin psi dt over the samples
// tagged with it, whose coefficients (rad/s: K0 Omega cos(latitude) h) are fitted with K and D.
//
// The columns are accumulated raw (phi without the Earth rate, the trend's powers of t from the
// session's first sample): a linear map, regressorMap(), turns them into the fitted ones, so one set
// of sums serves any Earth rate. The fitted harmonics are corrected for the noise of theta inside
// cos(k theta) (wave_angle_noise.h).
#pragma once

#include <Eigen/Core>
#include <vector>

#include "hrg_gyro/core/common/units.h"
#include "hrg_gyro/core/common/weighted_least_squares.h"
#include "hrg_gyro/core/estimation/increment_fit.h"
#include "hrg_gyro/core/model/harmonic_basis.h"

namespace hrg_gyro {
namespace core {

/// The rows and columns `rows` x `cols` of m.
Eigen::MatrixXd selectedSubmatrix(const Eigen::MatrixXd& m, const std::vector<int>& rows, const std::vector<int>& cols);
/// The rows `rows` of column `col` of m.
Eigen::VectorXd selectedColumn(const Eigen::MatrixXd& m, const std::vector<int>& rows, int col);

/// The fitted columns among the accumulated ones: the K block, T, the T harmonics of D's orders
/// (mean, cos..., sin...), then the trend's, then the horizontal Earth rate's of the slots with data.
struct IncrementColumns {
  std::vector<int> sel;
  std::vector<int> without_trend;  ///< sel without the trend's columns
  int trend_at = 0;                ///< index in sel of the trend's first coefficient
  int horizontal_at = 0;           ///< index in sel of the first horizontal column
  std::vector<int> horizontal;     ///< the slots fitted, in order (two columns each)
};

/// The covariances of the fitted coefficients: the block sandwich, what white wave-angle noise alone
/// predicts, and what the estimated bias random walk (and angle random walk) predict (zero if none).
struct IncrementCovariances {
  Eigen::MatrixXd sandwich, white, walk;
};

/// Each fitted coefficient with the basis-noise attenuation undone, and its total standard error.
struct IncrementTerms {
  std::vector<double> value, total_std;
};

/// One sample's step along a chain: the basis (cos, sin of every order of allOrders()) now and at the
/// previous sample, the step of time, table angle and rate integral, and the session times of both.
struct IncrementStep {
  const Eigen::VectorXd *cos_now, *sin_now, *cos_before, *sin_before;
  double dt = 0.0, dphi = 0.0;
  bool has_rate = false;  ///< the chain carries the rate integral: its K block is integrated too
  double drate = 0.0;
  double t_session = 0.0, t_session_before = 0.0;
};

class IncrementModel {
 public:
  /// Orders must be positive; bias_trend_order at most 2; horizontal_slots >= 0.
  IncrementModel(const std::vector<int>& k_orders, const std::vector<int>& d_orders, int bias_trend_order,
                 int horizontal_slots);

  const std::vector<int>& kOrders() const { return k_orders_; }
  const std::vector<int>& dOrders() const { return d_orders_; }
  /// The orders of K and D together, ascending: those of the basis.
  const std::vector<int>& allOrders() const { return all_orders_; }
  int trendOrder() const { return trend_order_; }
  int horizontalSlots() const { return horizontal_slots_; }
  /// The regression's columns; column columns() of the mapped sums is the wave-angle increment y.
  int columns() const { return m_; }
  /// The accumulated sums per sample: the columns with the K block along the table angle, the same
  /// K block along the rate integral (from rateK0()), then y (rawY()).
  int kTerms() const { return k_terms_; }
  int rateK0() const { return rate_k0_; }
  int rawY() const { return raw_y_; }
  /// The T column of K column j's order (K0: T itself).
  int timeColumnOfK(int j) const { return time_column_of_k_[j]; }
  /// A basis for allOrders().
  HarmonicBasis basis() const;

  /// The trapezoid of each integrand over the step into `integrals` (rawY() entries).
  void integrate(const IncrementStep& step, Eigen::VectorXd* integrals) const;
  /// The trapezoid of cos psi dt and sin psi dt into the slot's columns.
  void integrateHorizontal(int slot, double psi, double psi_before, double dt, Eigen::VectorXd* integrals) const;

  /// The linear map of the accumulated columns: the Earth rate added to phi, the trend centred on t_ref.
  Eigen::MatrixXd regressorMap(double earth_rate, double reference_time) const;
  /// slot_seen: the horizontal slots with samples (the others' columns are zero and left out).
  IncrementColumns fittedColumns(const std::vector<bool>& slot_seen) const;
  /// The normal equations of the columns `sel` of the mapped sums `total`, solved.
  LeastSquaresSolution solve(const std::vector<int>& sel, const Eigen::MatrixXd& map, const Eigen::MatrixXd& total,
                             double max_condition) const;
  /// |change of each coefficient| when the Earth rate moves by its standard deviation.
  Eigen::VectorXd earthRateShift(const std::vector<int>& sel, const Eigen::VectorXd& beta, const Eigen::MatrixXd& total,
                                 double earth_rate, double earth_rate_std, double reference_time,
                                 double max_condition) const;
  /// The terms corrected for the angle noise (rad per sample); the error budgets of K and D into
  /// fit->budget and fit->drift_budget.
  IncrementTerms correctedTerms(const Eigen::VectorXd& beta, const IncrementCovariances& covariances,
                                const Eigen::VectorXd& earth_shift, double angle_noise, IncrementFit* fit) const;
  /// One model's terms (mean, cos..., sin... from `offset`) as a fit of `points` increments.
  static void fillFit(const IncrementTerms& terms, const std::vector<int>& orders, int offset, double condition_number,
                      std::size_t points, HarmonicFitResult* f);
  /// The trend's coefficients and how the design confuses it with K0. session_origin: the stamp of
  /// the session's first sample; span: s from it to the last.
  void fitTrend(const IncrementColumns& columns, const IncrementTerms& terms, const LeastSquaresSolution& solution,
                const Eigen::MatrixXd& map, const Eigen::MatrixXd& total, double reference_time,
                Nanoseconds session_origin, double span, BiasTrendFit* trend) const;

 private:
  int orderIndex(int k) const;

  std::vector<int> k_orders_, d_orders_, all_orders_;
  int trend_order_;
  int horizontal_slots_;
  int horizontal0_ = 0;  // the first horizontal column: cos psi dt, sin psi dt per slot
  int m_;  // regressors: K block (1 + 2 nK), then T and the T harmonics of every order, the trend, the slots
  int k_terms_ = 0, rate_k0_ = 0, raw_y_ = 0;
  std::vector<int> time_column_of_k_;
  std::vector<int> k_in_all_;  // index of each K order in all_orders_
};

}  // namespace core
}  // namespace hrg_gyro

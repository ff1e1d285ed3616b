// K(theta) and D(theta) fitted to window increments of the wave angle, exact for any window and any
// sweep, however non-uniform.
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
// Why increments of window means rather than the window means themselves: white wave-angle noise
// makes consecutive increments anti-correlated only at lag one, and angle random walk (rate noise)
// makes them white; the window means would instead carry a random walk along a whole chain. So the
// regression needs no intercept per chain and its errors are local, which lets a cluster sandwich
// (blocks of consecutive increments) estimate the covariance without assuming white errors.
//
// Streaming, in memory that does not grow with the session: the products of the increments are
// summed per block (p^2 each); when the blocks exceed a bound, neighbours are merged (exactly: the
// sums add), so the covariance always rests on 32..64 blocks. A chain is a stretch of one plateau
// without a gap: increments never span two chains. Per wave-angle bin and plateau group the
// increments' sums are kept too, for the binned K(theta) and D(theta) the report shows.
//
// Noise of theta inside cos(k theta) attenuates the regressors by exp(-k^2 s^2 / 2) on average
// (s the per-sample angle noise, estimated from the samples); the fitted harmonics are corrected by
// that factor (a tenth of the correction counts as its uncertainty).
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
// A bias that follows a random walk (rate random walk q, rad/s/sqrt(s)) is what no polynomial
// follows: it leaves each increment an error dt_i b(t_i), correlated over the whole session, which
// the block sandwich (blocks share nothing beyond their neighbours) does not see. The walk is
// estimated from the residuals: the mean residual rates of consecutive blocks (and of pairs and
// fours of them) differ by a variance q^2 a + N^2 c (N the angle random walk), a and c computed
// exactly through the fit, which takes much of a walk into K, D and the trend (a would be
// T1/3 + T2/3 + gap without it); a moment fit of q^2 and N^2 weighted by its own prediction. Where
// q^2 comes out positive, the fit's covariance carries the walk exactly:
//   Cov(X'e) = q^2 integral S(s) S(s)^T ds + N^2 sum x_i x_i^T dt_i,  S(s) = sum_{t_i > s} x_i dt_i,
// summed as the increments arrive (S from prefix sums, so memory stays fixed), and each coefficient's
// statistical variance is the larger of the sandwich and that model (with the white angle noise).
//
// An axis slightly tilted from the table's axis also senses the Earth's horizontal rate, which turns
// with the table: Omega cos(latitude) (h_x cos psi + h_y sin psi), psi the heading of the platter's
// x (the table's azimuth minus its angle) and h the axis's small horizontal component in the platter
// frame, unknown and different in every fixture position. As theta moves with the table angle, that
// rate would land in D's harmonics. Where the caller asks (horizontal slots > 0, one per fixture
// position), each slot adds two columns, the integrals of cos psi dt and sin psi dt over the samples
// tagged with it, whose coefficients (rad/s: K0 Omega cos(latitude) h) are fitted with K and D.
#pragma once

#include <Eigen/Core>
#include <cmath>
#include <map>
#include <string>
#include <vector>

#include "hrg_gyro/core/common/units.h"
#include "hrg_gyro/core/common/weighted_least_squares.h"
#include "hrg_gyro/core/estimation/binned_rate_fit.h"
#include "hrg_gyro/core/estimation/harmonic_fit.h"
#include "hrg_gyro/core/model/harmonic_basis.h"

namespace hrg_gyro {
namespace core {

/// What the reported standard error of each K term is made of (term order: mean, cos..., sin...).
struct IncrementErrorBudget {
  std::vector<double> statistical;   ///< from the data: block sandwich, never below the white-noise prediction
  std::vector<double> angle_noise;   ///< predicted by the white wave-angle noise alone
  std::vector<double> beyond_noise;  ///< statistical beyond that: table angle/rate errors, rate noise, drift
  std::vector<double> earth_rate;    ///< from the Earth-rate uncertainty
  std::vector<double> basis_noise;   ///< from the uncertainty of the basis-noise correction
  std::vector<double> bias_walk;     ///< predicted by the estimated bias random walk (0: none carried)
};

/// The bias random walk estimated from the residuals of the increment fit.
struct BiasWalkFit {
  double rate_random_walk = 0.0;      ///< q, rad/s/sqrt(s) (0 where the estimate is negative)
  double rate_random_walk_std = 0.0;  ///< standard error of q
  double angle_random_walk = 0.0;     ///< N, rad/sqrt(s), fitted with it
  bool carried = false;               ///< q^2 > 0: the covariance carries the walk
};

/// The Earth's horizontal rate that one fixture position's tilt lets into the axis: the coefficients
/// of cos psi and sin psi (psi the heading of the platter's x), rad/s.
struct HorizontalEarthFit {
  int slot = 0;
  double cos = 0.0, sin = 0.0;
  double cos_std = 0.0, sin_std = 0.0;
};

/// The bias trend fitted with K and D (bias_trend_order > 0).
struct BiasTrendFit {
  int order = 0;
  std::vector<double> coefficients;  ///< b_j, rad/s per s^j
  std::vector<double> stds;          ///< their standard errors
  double reference_time = 0.0;       ///< s from the first sample: t_ref, where D0 is the bias
  Nanoseconds reference_stamp = 0;   ///< the same as a stamp
  double span = 0.0;                 ///< s from the first to the last sample fitted
  /// K0's statistical standard error with the trend fitted over that without it (>= 1), and the
  /// correlation of K0 with the linear coefficient: how much the session confuses the two.
  double k0_inflation = 1.0;
  double k0_correlation = 0.0;
};

struct IncrementFit {
  bool ok = false;
  std::string reason;
  HarmonicFitResult k;  ///< K(theta), standard errors include the systematic terms of `budget`
  HarmonicFitResult d;  ///< D(theta), rad/s
  IncrementErrorBudget budget;
  IncrementErrorBudget drift_budget;     ///< the same for the D terms (mean, cos..., sin...)
  std::vector<BinnedCurvePoint> binned;  ///< fitted model plus the binned residual of the two main groups
  double angle_noise = 0.0;              ///< estimated white wave-angle noise per sample, rad
  double mean_window = 0.0;              ///< s between consecutive window means
  std::size_t increments = 0;
  std::size_t blocks = 0;                      ///< blocks of the sandwich covariance
  BiasTrendFit trend;                          ///< order 0: none fitted
  BiasWalkFit walk;                            ///< the bias's random walk, estimated whatever the trend order
  std::vector<HorizontalEarthFit> horizontal;  ///< per horizontal slot with data, in slot order
  /// Weight of the logged table angle against the integral of the logged rate (with the angle's
  /// slope per chain), time-weighted over the chains: 1 the angle alone, 0 the rate's shape alone.
  double angle_weight = 1.0;
};

class IncrementRegression {
 public:
  /// Orders must be positive. bins: wave-angle bins over [0, pi) for the binned curves.
  /// bias_trend_order: degree of the bias's polynomial in time (0: a constant bias; at most 2).
  /// horizontal_slots: fixture positions whose horizontal Earth rate is fitted (0: none).
  IncrementRegression(const std::vector<int>& k_orders, const std::vector<int>& d_orders, int bins,
                      int bias_trend_order = 0, int horizontal_slots = 0);

  /// Starts a chain of plateau group `group` averaged over windows of `window` s (ends any open chain).
  void startChain(int group, double window);
  /// Adds a sample of the open chain: theta the measured wave angle, phi the table angle (without the
  /// Earth rate, which solve() adds), phi_rate the integral of the table's logged rate from the chain's
  /// start (NaN: none); stamps increasing. horizontal_slot: the fixture position whose horizontal
  /// Earth rate the sample carries (-1: none), psi the heading of the platter's x, rad.
  void add(Nanoseconds stamp, double theta, double phi, double phi_rate = NAN, int horizontal_slot = -1,
           double psi = 0.0);
  /// Closes the open chain (its last, partial window is left out).
  void endChain();
  /// rad^2: an error of the angle that is smooth in time (regularised stamps), which the window
  /// means' scatter does not show; counted against the angle when the two sources are weighed.
  void setAngleSmoothError(double variance) { angle_smooth_error_ = variance; }
  bool inChain() const { return in_chain_; }
  int horizontalSlots() const { return horizontal_slots_; }

  std::size_t increments() const { return increments_; }

  /// earth_rate: rad/s added to dphi/dt; earth_rate_std: its uncertainty (propagated to K).
  /// min_bin_time: s of increments a bin needs in both groups to be shown.
  IncrementFit solve(double earth_rate, double earth_rate_std, double min_bin_time, double max_condition) const;

 private:
  struct Block {
    Eigen::MatrixXd products;  // sum w w^T of its increments, w = (dz, dy)
    Eigen::VectorXd sum;       // sum w: the block's residual at the solution
    double time = 0.0;         // s: sum of the increments' dt
    double moment = 0.0;       // sum of dt t (t the increment's mid time from the session's first sample)
    // For the walk's covariances (t_i, dt_i, w_i the increments; P and V the session's prefix sums of
    // w dt and w dt t up to and including each): sum w dt, sum dt V(t), sum dt t P(t), and
    // sum_{i,j in the block} dt_i dt_j min(t_i, t_j).
    Eigen::VectorXd sum_dt, prefix_v, prefix_p;
    double self = 0.0;
    std::size_t count = 0;
  };
  struct BinSums {
    Eigen::VectorXd w;  // sum of the increments' w
    double dt = 0.0, dphi = 0.0;
  };
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
  /// The normal equations of the fitted columns `sel` solved at the Earth rate, with the block
  /// sandwich and the white-noise covariance of the coefficients.
  struct Solved {
    LeastSquaresSolution solution;
    Eigen::MatrixXd sandwich, white;
    Eigen::MatrixXd walk;  // what the estimated bias random walk (and angle random walk) predict; zero if none
  };

  /// The fitted columns among the accumulated ones: the K block, T, the T harmonics of D's orders
  /// (mean, cos..., sin...), then the trend's, then the horizontal Earth rate's of the slots with data.
  struct Columns {
    std::vector<int> sel;
    std::vector<int> without_trend;  ///< sel without the trend's columns
    int trend_at = 0;                ///< index in sel of the trend's first coefficient
    int horizontal_at = 0;           ///< index in sel of the first horizontal column
    std::vector<int> horizontal;     ///< the slots fitted, in order (two columns each)
  };
  /// Each fitted coefficient with the basis-noise attenuation undone, and its total standard error.
  struct Terms {
    std::vector<double> value, total_std;
  };

  void closeWindow();
  /// The per-sample angle noise: the previous sample's deviation from the line through its neighbours.
  void addNoiseSample(double t, double theta);
  /// The trapezoid of cos psi dt and sin psi dt into the slot's columns.
  void addHorizontal(int slot, double psi, double dt);
  /// The chain's window means into increments, the table angle taken as the weighted sum of the
  /// logged angle and the rate integral (with the chain's slope from the angle).
  void flushChain();
  void addIncrement(const WindowMean& a, const WindowMean& b);
  /// The linear map of the accumulated columns: the Earth rate added to phi, the trend centred on t_ref.
  Eigen::MatrixXd regressorMap(double earth_rate, double reference_time) const;
  Solved solveColumns(const std::vector<int>& sel, const Eigen::MatrixXd& map, const std::vector<Block>& blocks,
                      const Eigen::MatrixXd& total, double angle_noise, double max_condition) const;
  // The sections of solve().
  Columns fittedColumns() const;
  /// |change of each coefficient| when the Earth rate moves by its standard deviation.
  Eigen::VectorXd earthRateShift(const std::vector<int>& sel, const Eigen::VectorXd& beta, const Eigen::MatrixXd& total,
                                 double earth_rate, double earth_rate_std, double reference_time,
                                 double max_condition) const;
  /// q and N from the blocks' mean residual rates at the solution.
  BiasWalkFit estimateWalk(const std::vector<Block>& blocks, const std::vector<int>& sel, const Eigen::MatrixXd& map,
                           const LeastSquaresSolution& solution) const;
  /// Cov(X^T e) for a unit bias walk from the session's start: integral of S S^T ds, S(s) the sum of
  /// w dt over the increments after s (raw columns).
  Eigen::MatrixXd walkScoreCovariance() const;
  /// The covariance of the coefficients that the walk predicts.
  Eigen::MatrixXd walkCovariance(const BiasWalkFit& walk, const std::vector<int>& sel, const Eigen::MatrixXd& map,
                                 const Eigen::MatrixXd& inverse) const;
  /// The corrected terms; the error budgets of K and D into fit->budget and fit->drift_budget.
  Terms correctedTerms(const Solved& solved, const Eigen::VectorXd& earth_shift, IncrementFit* fit) const;
  /// One model's terms (mean, cos..., sin... from `offset`) as a fit.
  void fillFit(const Terms& terms, const std::vector<int>& orders, int offset, double condition_number,
               HarmonicFitResult* f) const;
  void fitTrend(const Columns& columns, const Terms& terms, const LeastSquaresSolution& solution,
                const Eigen::MatrixXd& map, const Eigen::MatrixXd& total, double reference_time,
                BiasTrendFit* trend) const;
  /// The binned K and D of the two groups with the most data, and the fits' residual rms about them.
  void binCurves(const std::vector<int>& sel, const Eigen::VectorXd& beta, const Eigen::MatrixXd& map,
                 double earth_rate, double min_bin_time, IncrementFit* fit) const;

  std::vector<int> k_orders_, d_orders_, all_orders_;
  int bins_;
  int trend_order_;
  int horizontal_slots_;
  int horizontal0_ = 0;  // the first horizontal column: cos psi dt, sin psi dt per slot
  int m_;  // regressors: K block (1 + 2 nK), then T and the T harmonics of every order, the trend, the slots
  int k_terms_ = 0, rate_k0_ = 0, raw_y_ = 0;  // the accumulated columns: K block along the rate integral, y
  std::vector<int> time_column_of_k_;
  HarmonicBasis basis_;
  // The session's first sample: the trend's time origin.
  bool has_origin_ = false;
  Nanoseconds session_origin_ = 0;
  double last_session_time_ = 0.0;
  double increment_time_moment_ = 0.0;  // sum of increment dt x mean time: the trend's reference
  // The open chain.
  bool in_chain_ = false, has_sample_ = false, has_mean_ = false;
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
  // The two table sources, judged over the session: consecutive differences of (angle - integral).
  double source_squares_ = 0.0, source_lag_ = 0.0;
  std::size_t source_count_ = 0, source_lag_count_ = 0;
  double angle_smooth_error_ = 0.0;
  double angle_weight_time_ = 0.0, weighted_chain_time_ = 0.0;
  std::vector<int> k_in_all_;  // index of each K order in all_orders_
  Eigen::VectorXd cos_prev_, sin_prev_, cos_now_, sin_now_, integrals_;
  long window_index_ = 0;
  WindowMean sum_, previous_mean_;
  Eigen::VectorXd previous_dz_;  // last increment of the chain, for the lag-one products
  double previous_inverse_count_ = 0.0;
  bool has_previous_dz_ = false;
  // Accumulated over the session.
  std::vector<Block> blocks_;
  Block open_block_;
  std::size_t block_size_ = 8;
  Eigen::MatrixXd white_lag0_, white_lag1_;  // predicted white-noise products, per unit variance
  // The bias walk's covariance: P the prefix sum of w dt over the increments so far, A = integral of
  // P ds and B = integral of P P^T ds over their mid times, V the prefix sum of w dt t; the angle
  // random walk's sum of w w^T dt.
  Eigen::VectorXd walk_prefix_, walk_prefix_integral_, walk_prefix_v_;
  Eigen::MatrixXd walk_products_, arw_products_;
  bool walk_started_ = false;
  double walk_time_ = 0.0;
  std::map<int, std::vector<BinSums>> bins_by_group_;
  std::map<int, double> group_time_;
  std::size_t increments_ = 0;
  double increment_time_ = 0.0;
  // Per-sample angle noise from deviations from the line through the neighbours.
  int history_ = 0;
  double h_theta_[2] = {0.0, 0.0}, h_t_[2] = {0.0, 0.0};
  double noise_sum_ = 0.0;
  std::size_t noise_count_ = 0;
};

}  // namespace core
}  // namespace hrg_gyro

#include "hrg_gyro/core/estimation/increment_regression.h"

#include <string>

namespace hrg_gyro {
namespace core {

IncrementRegression::IncrementRegression(const std::vector<int>& k_orders, const std::vector<int>& d_orders, int bins,
                                         int bias_trend_order, int horizontal_slots)
    : model_(k_orders, d_orders, bias_trend_order, horizontal_slots),
      chains_(model_),
      blocks_(model_.columns()),
      walk_(model_.columns()),
      bins_(bins, model_.columns()) {}

void IncrementRegression::startChain(int group, double window) {
  endChain();
  chains_.start(group, window);
}

void IncrementRegression::add(Nanoseconds stamp, double theta, double phi, double phi_rate, int horizontal_slot,
                              double psi) {
  chains_.add(model_, stamp, theta, phi, phi_rate, horizontal_slot, psi);
}

void IncrementRegression::endChain() {
  for (const WindowIncrement& increment : chains_.end(model_)) addIncrement(increment);
}

void IncrementRegression::addIncrement(const WindowIncrement& increment) {
  // The walk first: the blocks keep its prefix sums up to and including this
  // increment.
  walk_.add(increment.dw, increment.dt, increment.t_mid);
  blocks_.add(increment, walk_.prefix(), walk_.prefixMoment());
  bins_.add(increment);
  ++increments_;
  increment_time_ += increment.dt;
  increment_time_moment_ += increment.dt * increment.t_mid;
}

IncrementCovariances IncrementRegression::covariances(const std::vector<IncrementBlock>& blocks,
                                                      const std::vector<int>& sel, const Eigen::MatrixXd& map,
                                                      const LeastSquaresSolution& solution, double angle_noise,
                                                      BiasWalkFit* walk) const {
  const int p = static_cast<int>(sel.size());
  IncrementCovariances out;
  out.sandwich = IncrementBlocks::sandwich(blocks, sel, map, solution, model_.columns(), increments_);
  out.white = blocks_.white(sel, map, solution.normal_inverse, angle_noise);
  *walk = walk_.estimate(blocks, sel, map, solution);
  out.walk = walk->carried ? walk_.covariance(*walk, sel, map, solution.normal_inverse) : Eigen::MatrixXd::Zero(p, p);
  return out;
}

void IncrementRegression::fillResults(const IncrementColumns& columns, const IncrementTerms& terms,
                                      const LeastSquaresSolution& solution, const Eigen::MatrixXd& map,
                                      const Eigen::MatrixXd& total, double reference_time, IncrementFit* fit) const {
  const int n_kterms = model_.kTerms();
  IncrementModel::fillFit(terms, model_.kOrders(), 0, solution.condition_number, increments_, &fit->k);
  IncrementModel::fillFit(terms, model_.dOrders(), n_kterms, solution.condition_number, increments_, &fit->d);
  if (model_.trendOrder() > 0) {
    model_.fitTrend(columns, terms, solution, map, total, reference_time, chains_.sessionOrigin(),
                    chains_.lastSessionTime(), &fit->trend);
  }
  for (std::size_t j = 0; j < columns.horizontal.size(); ++j) {
    const int at = columns.horizontal_at + 2 * static_cast<int>(j);
    fit->horizontal.push_back(
        {columns.horizontal[j], terms.value[at], terms.value[at + 1], terms.total_std[at], terms.total_std[at + 1]});
  }
}

IncrementFit IncrementRegression::solve(double earth_rate, double earth_rate_std, double min_bin_time,
                                        double max_condition) const {
  if (chains_.inChain() && chains_.holdsMeans()) {
    // The open chain's window means wait for its end: close it on a copy.
    IncrementRegression closed = *this;
    closed.endChain();
    return closed.solve(earth_rate, earth_rate_std, min_bin_time, max_condition);
  }
  IncrementFit fit;
  fit.angle_weight = chains_.angleWeight();
  const IncrementColumns columns = model_.fittedColumns(chains_.slotsSeen());
  const std::vector<int>& sel = columns.sel;
  const int p = static_cast<int>(sel.size());
  const std::vector<IncrementBlock> blocks = blocks_.blocks();
  fit.increments = increments_;
  fit.blocks = blocks.size();
  fit.mean_window = increments_ > 0 ? increment_time_ / increments_ : 0.0;
  fit.angle_noise = chains_.angleNoise().perSample();
  if (increments_ < static_cast<std::size_t>(3 * p) || blocks.size() < 4) {
    fit.reason = std::to_string(increments_) + " window increments in " + std::to_string(blocks.size()) +
                 " blocks; need at least " + std::to_string(3 * p) + " in 4 blocks";
    return fit;
  }
  const Eigen::MatrixXd total = IncrementBlocks::total(blocks);
  // The trend is centred on the mean time of the increments: D0 is then the
  // session's mean bias.
  const double reference_time = increment_time_ > 0.0 ? increment_time_moment_ / increment_time_ : 0.0;
  const Eigen::MatrixXd map = model_.regressorMap(earth_rate, reference_time);
  const LeastSquaresSolution solution = model_.solve(sel, map, total, max_condition);
  if (!solution.ok) {
    fit.reason = "increment regression condition number " + std::to_string(solution.condition_number) + " above " +
                 std::to_string(max_condition);
    return fit;
  }
  const Eigen::VectorXd& beta = solution.coefficients;
  const IncrementCovariances covariance = covariances(blocks, sel, map, solution, fit.angle_noise, &fit.walk);
  // Earth-rate uncertainty: refit with the rate moved by its standard
  // deviation.
  const Eigen::VectorXd earth_shift =
      model_.earthRateShift(sel, beta, total, earth_rate, earth_rate_std, reference_time, max_condition);
  const IncrementTerms terms = model_.correctedTerms(beta, covariance, earth_shift, fit.angle_noise, &fit);
  fillResults(columns, terms, solution, map, total, reference_time, &fit);
  const IncrementBinnedCurves curves =
      bins_.curves(sel, beta, map, toModel(fit.k), toModel(fit.d), earth_rate, min_bin_time);
  fit.binned = curves.points;
  fit.k.residual_rms = curves.k_residual_rms;
  fit.d.residual_rms = curves.d_residual_rms;
  fit.ok = true;
  return fit;
}

}  // namespace core
}  // namespace hrg_gyro

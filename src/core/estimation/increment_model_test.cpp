// The increment model's integrals, its regressor map and column selection, and its solution.
#include "hrg_gyro/core/estimation/increment_model.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

namespace hrg_gyro {
namespace core {
namespace {

TEST(IncrementModelTest, IntegratesTheColumnsOfASweepToTheirClosedForms) {
  // theta = a + b t, phi = w t on [0, 2] s: integral cos(2 theta) dphi = w/(2b) [sin 2theta], the
  // trend's integral of t^2 dt = t^3 / 3 exactly, the slot's integral of cos psi dt with psi fixed.
  const IncrementModel model({2}, {2, 4}, 2, 1);
  HarmonicBasis basis = model.basis();
  const int n_all = static_cast<int>(model.allOrders().size());
  ASSERT_EQ(n_all, 2);
  Eigen::VectorXd c_now(n_all), s_now(n_all), c_before(n_all), s_before(n_all);
  Eigen::VectorXd integrals = Eigen::VectorXd::Zero(model.rawY());
  const double a = 0.3, b = 0.4, w = 0.05, h = 1e-4;
  auto evaluate = [&](double t, Eigen::VectorXd* c, Eigen::VectorXd* s) {
    basis.evaluate(a + b * t);
    for (int u = 0; u < n_all; ++u) {
      (*c)(u) = basis.cosOf(model.allOrders()[u]);
      (*s)(u) = basis.sinOf(model.allOrders()[u]);
    }
  };
  evaluate(0.0, &c_before, &s_before);
  for (int i = 1; i <= 20000; ++i) {
    const double t = i * h;
    evaluate(t, &c_now, &s_now);
    IncrementStep step{&c_now, &s_now, &c_before, &s_before};
    step.dt = h;
    step.dphi = w * h;
    step.has_rate = true;
    step.drate = 2.0 * w * h;
    step.t_session = t;
    step.t_session_before = t - h;
    model.integrate(step, &integrals);
    model.integrateHorizontal(0, 0.5, 0.5, h, &integrals);
    c_before = c_now;
    s_before = s_now;
  }
  const double theta1 = a + 2.0 * b;
  // Columns: K0, K cos 2, K sin 2, T, T cos 2, T cos 4, T sin 2, T sin 4, t dt, t^2 dt, slot cos, sin.
  EXPECT_NEAR(integrals(0), 2.0 * w, 1e-12);  // 20000 steps summed
  EXPECT_NEAR(integrals(1), w / (2.0 * b) * (std::sin(2.0 * theta1) - std::sin(2.0 * a)), 1e-9);
  EXPECT_NEAR(integrals(3), 2.0, 1e-12);
  EXPECT_NEAR(integrals(5), 1.0 / (4.0 * b) * (std::sin(4.0 * theta1) - std::sin(4.0 * a)), 1e-8);
  EXPECT_NEAR(integrals(8), 2.0, 1e-12);
  EXPECT_NEAR(integrals(9), 8.0 / 3.0, 1e-12);
  EXPECT_NEAR(integrals(10), 2.0 * std::cos(0.5), 1e-12);
  EXPECT_NEAR(integrals(model.rateK0()), 4.0 * w, 1e-12);  // the K block along the rate integral
  EXPECT_EQ(model.timeColumnOfK(1), 4);                    // K cos 2's T column is T cos 2
}

TEST(IncrementModelTest, MapAddsTheEarthRateAndCentresTheTrend) {
  const IncrementModel model({2}, {2}, 2, 0);
  const double earth = 7e-5, t_ref = 30.0;
  const Eigen::MatrixXd map = model.regressorMap(earth, t_ref);
  // Raw sums of one increment over [t0, t1]: T, integral t dt, integral t^2 dt.
  const double t0 = 20.0, t1 = 50.0;
  Eigen::VectorXd raw = Eigen::VectorXd::Zero(model.columns() + 1);
  raw(0) = 0.1;  // Phi0
  raw(3) = t1 - t0;
  raw(6) = (t1 * t1 - t0 * t0) / 2.0;
  raw(7) = (t1 * t1 * t1 - t0 * t0 * t0) / 3.0;
  const Eigen::VectorXd mapped = map * raw;
  EXPECT_NEAR(mapped(0), 0.1 + earth * (t1 - t0), 1e-15);
  EXPECT_NEAR(mapped(6), (std::pow(t1 - t_ref, 2) - std::pow(t0 - t_ref, 2)) / 2.0, 1e-9);
  EXPECT_NEAR(mapped(7), (std::pow(t1 - t_ref, 3) - std::pow(t0 - t_ref, 3)) / 3.0, 1e-8);
}

TEST(IncrementModelTest, FitsOnlyTheSlotsWithDataAndSolvesExactSums) {
  const IncrementModel model({2}, {2}, 1, 3);
  const IncrementColumns columns = model.fittedColumns({false, true, false});
  ASSERT_EQ(columns.horizontal.size(), 1u);
  EXPECT_EQ(columns.horizontal[0], 1);
  EXPECT_EQ(columns.sel.size(), 3u + 3u + 1u + 2u);
  EXPECT_EQ(columns.without_trend.size(), columns.sel.size() - 1);
  EXPECT_EQ(columns.sel[columns.trend_at], 1 + 2 + 1 + 2);
  // Sums of increments whose y is exactly X beta: the solution is beta.
  std::mt19937_64 random(3);
  std::normal_distribution<double> normal(0.0, 1.0);
  const int p = static_cast<int>(columns.sel.size()), m = model.columns();
  Eigen::VectorXd beta(p);
  for (int i = 0; i < p; ++i) beta(i) = 0.1 * (i + 1) * (i % 2 ? -1.0 : 1.0);
  Eigen::MatrixXd total = Eigen::MatrixXd::Zero(m + 1, m + 1);
  for (int n = 0; n < 200; ++n) {
    Eigen::VectorXd w = Eigen::VectorXd::Zero(m + 1);
    for (int i = 0; i < p; ++i) w(columns.sel[i]) = normal(random);
    for (int i = 0; i < p; ++i) w(m) += w(columns.sel[i]) * beta(i);
    total += w * w.transpose();
  }
  const LeastSquaresSolution solution = model.solve(columns.sel, Eigen::MatrixXd::Identity(m + 1, m + 1), total, 1e8);
  ASSERT_TRUE(solution.ok);
  EXPECT_LT((solution.coefficients - beta).cwiseAbs().maxCoeff(), 1e-12);
  EXPECT_THROW(IncrementModel({2}, {2}, 3, 0), std::invalid_argument);
  EXPECT_THROW(IncrementModel({2}, {-2}, 0, 0), std::invalid_argument);
}

}  // namespace
}  // namespace core
}  // namespace hrg_gyro

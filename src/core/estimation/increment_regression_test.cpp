// The increment regression on noiseless sweeps: exact for any window and any non-uniform sweep, and
// its refusals.
#include "hrg_gyro/core/estimation/increment_regression.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <functional>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include "hrg_gyro/core/model/earth_rate.h"
#include "hrg_gyro/core/model/harmonic_model.h"

namespace hrg_gyro {
namespace core {
namespace {

// K with a 3 % cos 4theta and a 0.3 % cos 8theta term: theta sweeps far from uniformly.
const HarmonicModel kStrongK({2, 4, 8}, -0.56, {-6e-4, -0.56 * 0.03, 0.56 * 0.003}, {4e-4, 2e-4, 0.0});
const HarmonicModel kDrift({2}, 1e-5, {2e-5}, {-1e-5});

/// An axis leaning off the table's axis: its horizontal component in the platter frame, and the
/// horizontal Earth rate it senses (heading psi = -phi, a zero azimuth), fitted in `slot` (-1: not).
struct Lean {
  double x = 0.0, y = 0.0, horizontal_rate = 0.0;
  int slot = -1;
  double rate(double phi) const { return horizontal_rate * (x * std::cos(-phi) + y * std::sin(-phi)); }
};

/// Two plateaus (table rates w1 and w2), RK4 at 1 kHz; table angle logged exactly; white noise of
/// `noise` rad on the measured theta.
void sweep(IncrementRegression* r, double w1, double w2, double seconds, double window, double earth,
           const HarmonicModel& k_model = kStrongK, double noise = 0.0, const Lean& lean = Lean()) {
  double theta = 0.2, phi = 0.0, t = 0.0;
  std::mt19937_64 random(11);
  std::normal_distribution<double> normal(0.0, 1.0);
  const double h = 1e-3;
  int group = 0;
  for (double w : {w1, w2}) {
    r->startChain(group++, window);
    auto rate = [&](double th, double ph) { return k_model(th) * (w + earth + lean.rate(ph)) + kDrift(th); };
    for (long i = 0; i < static_cast<long>(seconds / h); ++i) {
      r->add(toNanoseconds(1.0 + t), theta + noise * normal(random), phi, NAN, lean.slot, -phi);
      const double k1 = rate(theta, phi), k2 = rate(theta + h / 2 * k1, phi + w * h / 2),
                   k3 = rate(theta + h / 2 * k2, phi + w * h / 2), k4 = rate(theta + h * k3, phi + w * h);
      theta += h / 6 * (k1 + 2 * k2 + 2 * k3 + k4);
      phi += w * h;
      t += h;
    }
    r->endChain();
  }
}

TEST(IncrementRegressionTest, ExactForAnyWindowUnderStrongNonlinearity) {
  for (double window : {0.5, 2.0, 8.0}) {
    IncrementRegression r({2, 4, 8}, {2}, 64);
    sweep(&r, 0.05, -0.05, 130.0, window, 5e-5);
    const IncrementFit fit = r.solve(5e-5, 0.0, 0.1, 1e8);
    ASSERT_TRUE(fit.ok) << fit.reason;
    const double true_cos[] = {-6e-4, -0.56 * 0.03, 0.56 * 0.003}, true_sin[] = {4e-4, 2e-4, 0.0};
    double worst = std::abs(fit.k.mean + 0.56);
    for (std::size_t j = 0; j < 3; ++j) {
      worst = std::max(worst, std::abs(fit.k.cos[j] - true_cos[j]));
      worst = std::max(worst, std::abs(fit.k.sin[j] - true_sin[j]));
    }
    std::printf("window %.1f s: largest K coefficient error %.3g ppm of |K0|, mean window %.3f s\n", window,
                1e6 * worst / 0.56, fit.mean_window);
    EXPECT_LT(worst / 0.56, 2e-8) << "window " << window;
    EXPECT_NEAR(fit.d.mean, 1e-5, 1e-10);
    EXPECT_NEAR(fit.d.cos[0], 2e-5, 1e-10);
    if (window <= 2.0) {  // long windows leave bins empty
      EXPECT_GT(fit.binned.size(), 32u) << "window " << window;
    }
    EXPECT_LT(fit.k.residual_rms / 0.56, 1e-6);
  }
}

TEST(IncrementRegressionTest, FitsTheHorizontalEarthRateOfALeaningAxisInsteadOfD) {
  // An axis 3 mrad off the table's axis at latitude 0.9 rad: the horizontal Earth rate it senses
  // turns with the table and, unmodelled, lands in D's order 2 (theta moves with about 1.8 phi).
  const HarmonicModel k({2}, -0.56, {-6e-4}, {4e-4});
  Lean lean;
  lean.x = 3e-3;
  lean.y = -2e-3;
  lean.horizontal_rate = kEarthRotationRate * std::cos(0.9);
  IncrementRegression without({2}, {2}, 64);
  sweep(&without, 0.05, -0.05, 260.0, 2.0, 5e-5, k, 0.0, lean);
  lean.slot = 1;  // slot 0 unused: no columns for it
  IncrementRegression with({2}, {2}, 64, 0, 2);
  sweep(&with, 0.05, -0.05, 260.0, 2.0, 5e-5, k, 0.0, lean);
  const IncrementFit a = without.solve(5e-5, 0.0, 0.1, 1e8), b = with.solve(5e-5, 0.0, 0.1, 1e8);
  ASSERT_TRUE(a.ok) << a.reason;
  ASSERT_TRUE(b.ok) << b.reason;
  const double leak = std::hypot(a.d.cos[0] - 2e-5, a.d.sin[0] + 1e-5);
  const double left = std::hypot(b.d.cos[0] - 2e-5, b.d.sin[0] + 1e-5);
  ASSERT_EQ(b.horizontal.size(), 1u);
  const double expected_cos = -0.56 * lean.horizontal_rate * lean.x,
               expected_sin = -0.56 * lean.horizontal_rate * lean.y;
  std::printf(
      "D order 2 off by %.3g rad/s unmodelled, %.3g rad/s with the lean fitted; lean's rate %.4g %.4g rad/s "
      "(expected %.4g %.4g)\n",
      leak, left, b.horizontal[0].cos, b.horizontal[0].sin, expected_cos, expected_sin);
  EXPECT_GT(leak, 1e-9);
  EXPECT_LT(left, 2e-10);
  EXPECT_NEAR(b.d.mean, 1e-5, 2e-10);
  EXPECT_EQ(b.horizontal[0].slot, 1);
  EXPECT_NEAR(b.horizontal[0].cos, expected_cos, 1e-3 * std::abs(expected_cos));
  EXPECT_NEAR(b.horizontal[0].sin, expected_sin, 1e-3 * std::abs(expected_sin));
  without.startChain(0, 2.0);  // a slot it was not made with
  EXPECT_THROW(without.add(toNanoseconds(999.0), 0.0, 0.0, NAN, 0, 0.0), std::invalid_argument);
}

TEST(IncrementRegressionTest, CorrectsTheBasisForNoiseInTheta) {
  // Noise s in theta makes cos(k theta) average exp(-k^2 s^2 / 2) cos(k theta): at s = 0.2 rad that
  // is 27 % for order 4, far above the statistical error at this noise. (Realistic noise, 1e-4 rad,
  // attenuates by 1e-7; this shows the correction where it can be seen.)
  const double noise = 0.2, a4 = -0.056;
  const HarmonicModel k({4}, -0.56, {a4}, {0.0});
  IncrementRegression r({4}, {2}, 64);
  sweep(&r, 0.05, -0.05, 300.0, 2.0, 0.0, k, noise);
  const IncrementFit fit = r.solve(0.0, 0.0, 0.1, 1e8);
  ASSERT_TRUE(fit.ok) << fit.reason;
  const double attenuation = std::exp(-0.5 * 16 * noise * noise);
  const double uncorrected = fit.k.cos[0] / attenuation;
  std::printf("estimated angle noise %.4f rad; cos 4theta: true %.5f, corrected %.5f +- %.5f, uncorrected %.5f\n",
              fit.angle_noise, a4, fit.k.cos[0], fit.k.cos_std[0], uncorrected);
  EXPECT_NEAR(fit.angle_noise, noise, 0.01 * noise);
  EXPECT_LT(std::abs(fit.k.cos[0] - a4), 4.0 * fit.k.cos_std[0]);
  EXPECT_GT(std::abs(uncorrected - a4), 5.0 * fit.k.cos_std[0]);
}

TEST(IncrementRegressionTest, RefusesBadArgumentsAndTooLittleData) {
  EXPECT_THROW(IncrementRegression({0, 2}, {2}, 64), std::invalid_argument);
  EXPECT_THROW(IncrementRegression({2}, {2}, 0), std::invalid_argument);
  IncrementRegression r({2, 4}, {2}, 64);
  EXPECT_THROW(r.add(1, 0.0, 0.0), std::logic_error);
  EXPECT_THROW(r.startChain(0, 0.0), std::invalid_argument);
  r.startChain(0, 1.0);
  for (int i = 0; i < 3000; ++i) r.add(toNanoseconds(1.0 + i * 1e-3), 0.2 - 0.028 * i * 1e-3, 0.05 * i * 1e-3);
  const IncrementFit fit = r.solve(0.0, 0.0, 0.1, 1e8);
  EXPECT_FALSE(fit.ok);
  EXPECT_NE(fit.reason.find("window increments"), std::string::npos) << fit.reason;
}

// ---- Golden: every figure of the fit, bit for bit ----------------------------------------------
// A deterministic session that runs every path of the regression (rate integrals weighed against
// the angle, a trend, a bias walk, two horizontal slots, block merges, an open chain at solve) and
// the fit's every number as it was when the class was split into its parts: the split, and any
// later change that means to keep the figures, must reproduce them to the bit. They are kept in
// test/data/increment_regression_golden.txt (HRG_GOLDEN_PRINT=1 prints them in its format).

void put(std::vector<std::pair<std::string, double>>* out, const std::string& name, double value) {
  out->emplace_back(name, value);
}

void putHarmonic(std::vector<std::pair<std::string, double>>* out, const std::string& name,
                 const HarmonicFitResult& f) {
  put(out, name + ".ok", f.ok ? 1.0 : 0.0);
  put(out, name + ".mean", f.mean);
  put(out, name + ".mean_std", f.mean_std);
  for (std::size_t j = 0; j < f.cos.size(); ++j) {
    const std::string at = "[" + std::to_string(f.orders[j]) + "]";
    put(out, name + ".cos" + at, f.cos[j]);
    put(out, name + ".sin" + at, f.sin[j]);
    put(out, name + ".cos_std" + at, f.cos_std[j]);
    put(out, name + ".sin_std" + at, f.sin_std[j]);
  }
  put(out, name + ".residual_rms", f.residual_rms);
  put(out, name + ".condition_number", f.condition_number);
  put(out, name + ".points", static_cast<double>(f.points));
  put(out, name + ".smallest_attenuation", f.smallest_attenuation);
}

void putBudget(std::vector<std::pair<std::string, double>>* out, const std::string& name,
               const IncrementErrorBudget& b) {
  const std::pair<const char*, const std::vector<double>*> parts[] = {
      {"statistical", &b.statistical}, {"angle_noise", &b.angle_noise}, {"beyond_noise", &b.beyond_noise},
      {"earth_rate", &b.earth_rate},   {"basis_noise", &b.basis_noise}, {"bias_walk", &b.bias_walk}};
  for (const auto& part : parts) {
    put(out, name + "." + part.first + ".size", static_cast<double>(part.second->size()));
    for (std::size_t i = 0; i < part.second->size(); ++i)
      put(out, name + "." + part.first + "[" + std::to_string(i) + "]", (*part.second)[i]);
  }
}

/// Each item's fields, named name[i].field.
template <typename T>
void putEach(std::vector<std::pair<std::string, double>>* out, const std::string& name, const std::vector<T>& items,
             const std::vector<std::pair<std::string, std::function<double(const T&)>>>& fields) {
  for (std::size_t i = 0; i < items.size(); ++i) {
    for (const auto& field : fields)
      put(out, name + "[" + std::to_string(i) + "]." + field.first, field.second(items[i]));
  }
}

/// Every number of the fit, named.
std::vector<std::pair<std::string, double>> figuresOf(const IncrementFit& fit) {
  std::vector<std::pair<std::string, double>> out;
  put(&out, "ok", fit.ok ? 1.0 : 0.0);
  putHarmonic(&out, "k", fit.k);
  putHarmonic(&out, "d", fit.d);
  putBudget(&out, "budget", fit.budget);
  putBudget(&out, "drift_budget", fit.drift_budget);
  put(&out, "binned.size", static_cast<double>(fit.binned.size()));
  putEach<BinnedCurvePoint>(&out, "binned", fit.binned,
                            {{"theta", [](const BinnedCurvePoint& p) { return p.theta; }},
                             {"k", [](const BinnedCurvePoint& p) { return p.k; }},
                             {"d", [](const BinnedCurvePoint& p) { return p.d; }},
                             {"weight", [](const BinnedCurvePoint& p) { return p.weight; }}});
  put(&out, "angle_noise", fit.angle_noise);
  put(&out, "mean_window", fit.mean_window);
  put(&out, "increments", static_cast<double>(fit.increments));
  put(&out, "blocks", static_cast<double>(fit.blocks));
  put(&out, "trend.order", fit.trend.order);
  for (std::size_t j = 0; j < fit.trend.coefficients.size(); ++j) {
    put(&out, "trend.coefficients[" + std::to_string(j) + "]", fit.trend.coefficients[j]);
    put(&out, "trend.stds[" + std::to_string(j) + "]", fit.trend.stds[j]);
  }
  put(&out, "trend.reference_time", fit.trend.reference_time);
  put(&out, "trend.reference_stamp", static_cast<double>(fit.trend.reference_stamp));
  put(&out, "trend.span", fit.trend.span);
  put(&out, "trend.k0_inflation", fit.trend.k0_inflation);
  put(&out, "trend.k0_correlation", fit.trend.k0_correlation);
  put(&out, "walk.rate_random_walk", fit.walk.rate_random_walk);
  put(&out, "walk.rate_random_walk_std", fit.walk.rate_random_walk_std);
  put(&out, "walk.angle_random_walk", fit.walk.angle_random_walk);
  put(&out, "walk.carried", fit.walk.carried ? 1.0 : 0.0);
  put(&out, "horizontal.size", static_cast<double>(fit.horizontal.size()));
  putEach<HorizontalEarthFit>(&out, "horizontal", fit.horizontal,
                              {{"slot", [](const HorizontalEarthFit& h) { return static_cast<double>(h.slot); }},
                               {"cos", [](const HorizontalEarthFit& h) { return h.cos; }},
                               {"sin", [](const HorizontalEarthFit& h) { return h.sin; }},
                               {"cos_std", [](const HorizontalEarthFit& h) { return h.cos_std; }},
                               {"sin_std", [](const HorizontalEarthFit& h) { return h.sin_std; }}});
  put(&out, "angle_weight", fit.angle_weight);
  return out;
}

/// A session of four plateaus, each in two chains with a gap between them, at 200 Hz: K and D with
/// harmonics, a quadratic bias trend and a bias random walk, white noise on the wave angle, the
/// table angle logged with white noise and its rate integral with a wander, the horizontal Earth
/// rate of two fixture positions (the first plateau's first second in none). The last chain is
/// left open: solve() closes it on a copy.
void goldenSession(IncrementRegression* r, bool with_rate) {
  const HarmonicModel k({2, 4}, -0.56, {-6e-4, 3e-4}, {4e-4, -1e-4});
  const HarmonicModel d({2}, 1e-5, {2e-5}, {-1e-5});
  std::mt19937_64 random(20261202);
  std::normal_distribution<double> normal(0.0, 1.0);
  const double h = 5e-3, earth = 5e-5, walk_q = 2e-6;
  double theta = 0.3, phi = 0.0, t = 0.0, walk = 0.0, wander = 0.0;
  const double rates[] = {0.05, -0.05, 0.08, -0.03};
  for (int plateau = 0; plateau < 4; ++plateau) {
    const double w = rates[plateau];
    for (int chain = 0; chain < 2; ++chain) {
      r->startChain(plateau, 0.5);
      for (int i = 0; i < 16000; ++i) {
        const double bias = d(theta) + 3e-7 * (t / 100.0) - 2e-7 * (t / 100.0) * (t / 100.0) + walk;
        const int slot = plateau == 0 && chain == 0 && i < 200 ? -1 : plateau / 2;
        const double psi = 0.7 - phi;
        const double horizontal = 1e-6 * (plateau < 2 ? std::cos(psi) : std::sin(psi));
        const double logged_phi = phi + 2e-6 * normal(random);
        const double rate_integral = with_rate ? phi + wander : NAN;
        r->add(toNanoseconds(2.0 + t), theta + 1e-4 * normal(random), logged_phi, rate_integral, slot, psi);
        theta += h * (k(theta) * (w + earth + horizontal) + bias);
        phi += h * w;
        t += h;
        walk += walk_q * std::sqrt(h) * normal(random);
        wander += 3e-7 * normal(random);
      }
      if (plateau < 3 || chain == 0) r->endChain();
      t += 1.5;  // the gap between chains
    }
  }
}

/// The golden figures of one fit, `label` a section of test/data/increment_regression_golden.txt.
std::vector<std::pair<std::string, double>> goldenFigures(const std::string& label) {
  std::ifstream in(std::string(HRG_GYRO_SOURCE_DIR) + "/test/data/increment_regression_golden.txt");
  std::vector<std::pair<std::string, double>> out;
  bool inside = false;
  for (std::string line; std::getline(in, line);) {
    if (line.empty() || line[0] == '#') continue;
    if (line[0] == '[') {
      inside = line == "[" + label + "]";
      continue;
    }
    const std::size_t space = line.find(' ');
    if (inside && space != std::string::npos)
      out.emplace_back(line.substr(0, space), std::strtod(line.c_str() + space + 1, nullptr));
  }
  return out;
}

void expectFigures(const IncrementFit& fit, const std::string& label) {
  const std::vector<std::pair<std::string, double>> figures = figuresOf(fit);
  if (std::getenv("HRG_GOLDEN_PRINT")) {
    std::printf("[%s]\n", label.c_str());
    for (const auto& f : figures) std::printf("%s %a\n", f.first.c_str(), f.second);
  }
  const std::vector<std::pair<std::string, double>> golden = goldenFigures(label);
  ASSERT_EQ(figures.size(), golden.size()) << label;
  int differing = 0;
  for (std::size_t i = 0; i < golden.size(); ++i) {
    EXPECT_EQ(figures[i].first, golden[i].first) << label;
    const bool same = std::memcmp(&figures[i].second, &golden[i].second, sizeof(double)) == 0;
    if (!same) ++differing;
    EXPECT_TRUE(same) << label << " " << golden[i].first << ": " << std::hexfloat << figures[i].second << " ("
                      << std::defaultfloat << figures[i].second << "), golden " << std::hexfloat << golden[i].second;
  }
  std::printf("%s: %zu figures, %d differ from the golden ones\n", label.c_str(), golden.size(), differing);
}

TEST(IncrementRegressionGoldenTest, EveryFigureOfTheFitStaysBitForBit) {
  IncrementRegression with_rate({2, 4}, {2}, 32, 2, 2);
  with_rate.setAngleSmoothError(1e-12);
  goldenSession(&with_rate, true);
  ASSERT_TRUE(with_rate.inChain());
  const IncrementFit a = with_rate.solve(5e-5, 1e-7, 0.1, 1e8);
  ASSERT_TRUE(a.ok) << a.reason;
  EXPECT_TRUE(a.walk.carried);
  EXPECT_LT(a.angle_weight, 1.0);
  EXPECT_GT(a.angle_weight, 0.0);
  expectFigures(a, "rate, trend and slots");

  IncrementRegression angle_only({2}, {2, 4}, 24, 0, 2);
  goldenSession(&angle_only, false);
  angle_only.endChain();
  const IncrementFit b = angle_only.solve(5e-5, 0.0, 0.2, 1e8);
  ASSERT_TRUE(b.ok) << b.reason;
  expectFigures(b, "angle only");
}

}  // namespace
}  // namespace core
}  // namespace hrg_gyro

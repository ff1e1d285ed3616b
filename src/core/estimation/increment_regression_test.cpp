// The increment regression on noiseless sweeps: exact for any window and any non-uniform sweep, and
// its refusals.
#include "hrg_gyro/core/estimation/increment_regression.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <cstring>
#include <random>
#include <string>
#include <utility>
#include <vector>

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
// later change that means to keep the figures, must reproduce them to the bit.

/// One named number of a fit, in the order the fit is read.
struct GoldenFigure {
  const char* name;
  double value;
};

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

/// Every number of the fit, named.
std::vector<std::pair<std::string, double>> figuresOf(const IncrementFit& fit) {
  std::vector<std::pair<std::string, double>> out;
  put(&out, "ok", fit.ok ? 1.0 : 0.0);
  putHarmonic(&out, "k", fit.k);
  putHarmonic(&out, "d", fit.d);
  putBudget(&out, "budget", fit.budget);
  putBudget(&out, "drift_budget", fit.drift_budget);
  put(&out, "binned.size", static_cast<double>(fit.binned.size()));
  for (std::size_t i = 0; i < fit.binned.size(); ++i) {
    const std::string at = "binned[" + std::to_string(i) + "].";
    put(&out, at + "theta", fit.binned[i].theta);
    put(&out, at + "k", fit.binned[i].k);
    put(&out, at + "d", fit.binned[i].d);
    put(&out, at + "weight", fit.binned[i].weight);
  }
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
  for (std::size_t j = 0; j < fit.horizontal.size(); ++j) {
    const std::string at = "horizontal[" + std::to_string(j) + "].";
    put(&out, at + "slot", fit.horizontal[j].slot);
    put(&out, at + "cos", fit.horizontal[j].cos);
    put(&out, at + "sin", fit.horizontal[j].sin);
    put(&out, at + "cos_std", fit.horizontal[j].cos_std);
    put(&out, at + "sin_std", fit.horizontal[j].sin_std);
  }
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

void expectFigures(const IncrementFit& fit, const GoldenFigure* golden, std::size_t count, const char* label) {
  const std::vector<std::pair<std::string, double>> figures = figuresOf(fit);
  if (std::getenv("HRG_GOLDEN_PRINT")) {
    for (const auto& f : figures) std::printf("    {\"%s\", %a},\n", f.first.c_str(), f.second);
  }
  ASSERT_EQ(figures.size(), count) << label;
  int differing = 0;
  for (std::size_t i = 0; i < count; ++i) {
    EXPECT_EQ(figures[i].first, golden[i].name) << label;
    const bool same = std::memcmp(&figures[i].second, &golden[i].value, sizeof(double)) == 0;
    if (!same) ++differing;
    EXPECT_TRUE(same) << label << " " << golden[i].name << ": " << std::hexfloat << figures[i].second << " ("
                      << std::defaultfloat << figures[i].second << "), golden " << std::hexfloat << golden[i].value;
  }
  std::printf("%s: %zu figures, %d differ from the golden ones\n", label, count, differing);
}

// Filled from the run that printed them (HRG_GOLDEN_PRINT=1) on the code before the split.
const GoldenFigure kGoldenWithRateTrendAndSlots[] = {
    {"ok", 0x1p+0},
    {"k.ok", 0x1p+0},
    {"k.mean", -0x1.1eae48e31641ep-1},
    {"k.mean_std", 0x1.0abcb5b0dc60bp-13},
    {"k.cos[2]", -0x1.2aeacd9a7811bp-11},
    {"k.sin[2]", 0x1.dc002ec917de6p-12},
    {"k.cos_std[2]", 0x1.745f61c32d848p-14},
    {"k.sin_std[2]", 0x1.0df4ad99196a3p-14},
    {"k.cos[4]", 0x1.112c34daaa14p-12},
    {"k.sin[4]", -0x1.b9ab6b555611dp-14},
    {"k.cos_std[4]", 0x1.959ac7fcaec9bp-16},
    {"k.sin_std[4]", 0x1.a4397b7c75a38p-16},
    {"k.residual_rms", 0x1.c6c9c7fb186c7p-14},
    {"k.condition_number", 0x1.0447c2252f797p+3},
    {"k.points", 0x1.3cp+10},
    {"k.smallest_attenuation", 0x1p+0},
    {"d.ok", 0x1p+0},
    {"d.mean", 0x1.e967238d385bcp-15},
    {"d.mean_std", 0x1.85a7ad0cf340cp-15},
    {"d.cos[2]", 0x1.19c019f059b9dp-20},
    {"d.sin[2]", -0x1.23667d452d92ap-17},
    {"d.cos_std[2]", 0x1.c4e62bb31995dp-17},
    {"d.sin_std[2]", 0x1.a581a2631929ap-17},
    {"d.residual_rms", 0x1.58a11656289bp-18},
    {"d.condition_number", 0x1.0447c2252f797p+3},
    {"d.points", 0x1.3cp+10},
    {"d.smallest_attenuation", 0x1p+0},
    {"budget.statistical.size", 0x1.4p+2},
    {"budget.statistical[0]", 0x1.0abcb5b0dc609p-13},
    {"budget.statistical[1]", 0x1.745f61c32d732p-14},
    {"budget.statistical[2]", 0x1.959ac7fcaa38dp-16},
    {"budget.statistical[3]", 0x1.0df4ad991936ap-14},
    {"budget.statistical[4]", 0x1.a4397b7c620b1p-16},
    {"budget.angle_noise.size", 0x1.4p+2},
    {"budget.angle_noise[0]", 0x1.48392310ccbp-20},
    {"budget.angle_noise[1]", 0x1.ed676a4db3a7ep-20},
    {"budget.angle_noise[2]", 0x1.bc3a3e10cd47fp-20},
    {"budget.angle_noise[3]", 0x1.5b18b071579bdp-19},
    {"budget.angle_noise[4]", 0x1.216db532fd7b1p-19},
    {"budget.beyond_noise.size", 0x1.4p+2},
    {"budget.beyond_noise[0]", 0x1.420093c116959p-15},
    {"budget.beyond_noise[1]", 0x1.a525430fbaef7p-15},
    {"budget.beyond_noise[2]", 0x1.35b23372ecac7p-16},
    {"budget.beyond_noise[3]", 0x1.c1e62c6c1a38dp-15},
    {"budget.beyond_noise[4]", 0x1.a2aa0df698b3cp-16},
    {"budget.earth_rate.size", 0x1.4p+2},
    {"budget.earth_rate[0]", 0x1.e9b4p-39},
    {"budget.earth_rate[1]", 0x1.c6caecp-36},
    {"budget.earth_rate[2]", 0x1.e687afbp-35},
    {"budget.earth_rate[3]", 0x1.4dac43p-35},
    {"budget.earth_rate[4]", 0x1.00a7fd9ep-33},
    {"budget.basis_noise.size", 0x1.4p+2},
    {"budget.basis_noise[0]", 0x0p+0},
    {"budget.basis_noise[1]", 0x1.3ff40dc736d79p-40},
    {"budget.basis_noise[2]", 0x1.2465a650bed87p-39},
    {"budget.basis_noise[3]", 0x1.fd7fbed1ff6cfp-41},
    {"budget.basis_noise[4]", 0x1.d8c07b21d549ep-41},
    {"budget.bias_walk.size", 0x1.4p+2},
    {"budget.bias_walk[0]", 0x1.0ab98de83f7b1p-13},
    {"budget.bias_walk[1]", 0x1.744af302be27dp-14},
    {"budget.bias_walk[2]", 0x1.94a73b41d33f4p-16},
    {"budget.bias_walk[3]", 0x1.0dbcdedc3fb03p-14},
    {"budget.bias_walk[4]", 0x1.98fc897c79e0bp-16},
    {"drift_budget.statistical.size", 0x1.8p+1},
    {"drift_budget.statistical[0]", 0x1.85a79a7f8d41ap-15},
    {"drift_budget.statistical[1]", 0x1.c4e62bb3056bdp-17},
    {"drift_budget.statistical[2]", 0x1.a581a2630c938p-17},
    {"drift_budget.angle_noise.size", 0x1.8p+1},
    {"drift_budget.angle_noise[0]", 0x1.2bab0bdb06f4cp-23},
    {"drift_budget.angle_noise[1]", 0x1.2e562a98fbfecp-21},
    {"drift_budget.angle_noise[2]", 0x1.c8ec47a4459fbp-22},
    {"drift_budget.beyond_noise.size", 0x1.8p+1},
    {"drift_budget.beyond_noise[0]", 0x1.bf1e3861236p-19},
    {"drift_budget.beyond_noise[1]", 0x1.0bd25117a16cfp-17},
    {"drift_budget.beyond_noise[2]", 0x1.1a5bf73836003p-17},
    {"drift_budget.earth_rate.size", 0x1.8p+1},
    {"drift_budget.earth_rate[0]", 0x1.e0f749a711p-25},
    {"drift_budget.earth_rate[1]", 0x1.0e4b1b4p-34},
    {"drift_budget.earth_rate[2]", 0x1.9c079d8p-35},
    {"drift_budget.basis_noise.size", 0x1.8p+1},
    {"drift_budget.basis_noise[0]", 0x0p+0},
    {"drift_budget.basis_noise[1]", 0x1.2d9413c6f6447p-49},
    {"drift_budget.basis_noise[2]", 0x1.37e8514679abep-46},
    {"drift_budget.bias_walk.size", 0x1.8p+1},
    {"drift_budget.bias_walk[0]", 0x1.85a7274437ebp-15},
    {"drift_budget.bias_walk[1]", 0x1.c481368ccc394p-17},
    {"drift_budget.bias_walk[2]", 0x1.a543b3be9c8a3p-17},
    {"binned.size", 0x1.cp+4},
    {"binned[0].theta", 0x1.921fb54442d18p-5},
    {"binned[0].k", -0x1.1ed612cc2fa6p-1},
    {"binned[0].d", 0x1.df20861f6f1bbp-15},
    {"binned[0].weight", 0x1.6p+2},
    {"binned[1].theta", 0x1.2d97c7f3321d2p-3},
    {"binned[1].k", -0x1.1ec7f03960ba9p-1},
    {"binned[1].d", 0x1.baf6b895aadabp-15},
    {"binned[1].weight", 0x1.8p+2},
    {"binned[2].theta", 0x1.f6a7a2955385ep-3},
    {"binned[2].k", -0x1.1ebe8375f08c5p-1},
    {"binned[2].d", 0x1.a3c4a47c05dc4p-15},
    {"binned[2].weight", 0x1.7fffffffffffp+2},
    {"binned[3].theta", 0x1.5fdbbe9bba775p-2},
    {"binned[3].k", -0x1.1eaa00a7fe31dp-1},
    {"binned[3].d", 0x1.ac75a3d031206p-15},
    {"binned[3].weight", 0x1.200000000001p+2},
    {"binned[4].theta", 0x1.c463abeccb2bbp-2},
    {"binned[4].k", -0x1.1eb15508a2708p-1},
    {"binned[4].d", 0x1.9369a7a5c5488p-15},
    {"binned[4].weight", 0x1.fffffffffffep+1},
    {"binned[5].theta", 0x1.1475cc9eedfp-1},
    {"binned[5].k", -0x1.1ea63e5d35d84p-1},
    {"binned[5].d", 0x1.bf81c31bcf646p-15},
    {"binned[5].weight", 0x1.2p+2},
    {"binned[6].theta", 0x1.46b9c347764a4p-1},
    {"binned[6].k", -0x1.1e99ca4bc39b2p-1},
    {"binned[6].d", 0x1.d47cb6df7f052p-15},
    {"binned[6].weight", 0x1.200000000001p+2},
    {"binned[7].theta", 0x1.78fdb9effea46p-1},
    {"binned[7].k", -0x1.1e9448a809e8ep-1},
    {"binned[7].d", 0x1.5daea92dc2b8fp-15},
    {"binned[7].weight", 0x1.1ffffffffffe8p+2},
    {"binned[8].theta", 0x1.ab41b09886feap-1},
    {"binned[8].k", -0x1.1e6c132d8871bp-1},
    {"binned[8].d", 0x1.7cd99fe793d8cp-15},
    {"binned[8].weight", 0x1.2000000000018p+2},
    {"binned[9].theta", 0x1.dd85a7410f58cp-1},
    {"binned[9].k", -0x1.1e634e20feaffp-1},
    {"binned[9].d", 0x1.700b0b90bc753p-15},
    {"binned[9].weight", 0x1.fffffffffffdp+1},
    {"binned[10].theta", 0x1.07e4cef4cbd98p+0},
    {"binned[10].k", -0x1.1e4edda6991acp-1},
    {"binned[10].d", 0x1.72fece60999fcp-15},
    {"binned[10].weight", 0x1.2000000000008p+2},
    {"binned[11].theta", 0x1.2106ca4910069p+0},
    {"binned[11].k", -0x1.1e3af8ff11c33p-1},
    {"binned[11].d", 0x1.78d12f3f4b0aap-15},
    {"binned[11].weight", 0x1.2p+2},
    {"binned[12].theta", 0x1.3a28c59d5433bp+0},
    {"binned[12].k", -0x1.1e34ba621242ep-1},
    {"binned[12].d", 0x1.b478052aad063p-15},
    {"binned[12].weight", 0x1.2p+2},
    {"binned[13].theta", 0x1.534ac0f19860cp+0},
    {"binned[13].k", -0x1.1e2cf1cbd7bd7p-1},
    {"binned[13].d", 0x1.ebfbd33463025p-15},
    {"binned[13].weight", 0x1.2p+2},
    {"binned[14].theta", 0x1.6c6cbc45dc8dep+0},
    {"binned[14].k", -0x1.1e2b0eac49274p-1},
    {"binned[14].d", 0x1.bb9218be250fdp-15},
    {"binned[14].weight", 0x1p+2},
    {"binned[15].theta", 0x1.858eb79a20bafp+0},
    {"binned[15].k", -0x1.1e37ede4ccfcap-1},
    {"binned[15].d", 0x1.01bb615179895p-14},
    {"binned[15].weight", 0x1.1fffffffffff8p+2},
    {"binned[16].theta", 0x1.9eb0b2ee64e81p+0},
    {"binned[16].k", -0x1.1e451adfb9849p-1},
    {"binned[16].d", 0x1.06ab136bc868fp-14},
    {"binned[16].weight", 0x1.200000000001p+2},
    {"binned[17].theta", 0x1.b7d2ae42a9152p+0},
    {"binned[17].k", -0x1.1e66745894d68p-1},
    {"binned[17].d", 0x1.e56b7469011efp-15},
    {"binned[17].weight", 0x1.2p+2},
    {"binned[18].theta", 0x1.d0f4a996ed424p+0},
    {"binned[18].k", -0x1.1e8ca02687962p-1},
    {"binned[18].d", 0x1.102a788ccd277p-14},
    {"binned[18].weight", 0x1.2000000000004p+2},
    {"binned[19].theta", 0x1.ea16a4eb316f5p+0},
    {"binned[19].k", -0x1.1e9ce3df4629ap-1},
    {"binned[19].d", 0x1.0a280c15dcc8p-14},
    {"binned[19].weight", 0x1.ffffffffffff8p+1},
    {"binned[20].theta", 0x1.019c501fbace3p+1},
    {"binned[20].k", -0x1.1ece8a5a9f1fbp-1},
    {"binned[20].d", 0x1.3e81cc0678d74p-14},
    {"binned[20].weight", 0x1.2000000000004p+2},
    {"binned[21].theta", 0x1.0e2d4dc9dce4cp+1},
    {"binned[21].k", -0x1.1eeff11607812p-1},
    {"binned[21].d", 0x1.28fe955a76c47p-14},
    {"binned[21].weight", 0x1.4p+1},
    {"binned[22].theta", 0x1.4d02421c87558p+1},
    {"binned[22].k", -0x1.1f08cb8e7023p-1},
    {"binned[22].d", 0x1.00125b8b79da5p-14},
    {"binned[22].weight", 0x1.2000000000002p+2},
    {"binned[23].theta", 0x1.59933fc6a96c1p+1},
    {"binned[23].k", -0x1.1ef1e8c835c52p-1},
    {"binned[23].d", 0x1.e75d3761ef914p-15},
    {"binned[23].weight", 0x1.7fffffffffffbp+2},
    {"binned[24].theta", 0x1.66243d70cb829p+1},
    {"binned[24].k", -0x1.1efa1fe5b1af2p-1},
    {"binned[24].d", 0x1.e1137a118fd22p-15},
    {"binned[24].weight", 0x1.7fffffffffffep+2},
    {"binned[25].theta", 0x1.72b53b1aed992p+1},
    {"binned[25].k", -0x1.1eeab8f4e6f51p-1},
    {"binned[25].d", 0x1.1aeecef39111ep-14},
    {"binned[25].weight", 0x1.6p+2},
    {"binned[26].theta", 0x1.7f4638c50fafbp+1},
    {"binned[26].k", -0x1.1ed53dbbab169p-1},
    {"binned[26].d", 0x1.efb5e6bc4e0a4p-15},
    {"binned[26].weight", 0x1.7fffffffffff8p+2},
    {"binned[27].theta", 0x1.8bd7366f31c64p+1},
    {"binned[27].k", -0x1.1eda32dcc3b52p-1},
    {"binned[27].d", 0x1.118d91334dc37p-14},
    {"binned[27].weight", 0x1.8000000000008p+2},
    {"angle_noise", 0x1.a2c5ae6638c78p-14},
    {"mean_window", 0x1.000084bb2a33ap-1},
    {"increments", 0x1.3cp+10},
    {"blocks", 0x1.4p+5},
    {"trend.order", 0x1p+1},
    {"trend.coefficients[0]", 0x1.4a1ab46b0feaap-24},
    {"trend.stds[0]", 0x1.ff9f75c92e162p-24},
    {"trend.coefficients[1]", -0x1.542f102c6994p-32},
    {"trend.stds[1]", 0x1.825783c6afb5cp-32},
    {"trend.reference_time", 0x1.45000489613p+8},
    {"trend.reference_stamp", 0x1.308ae451ap+38},
    {"trend.span", 0x1.453f5c28f39cdp+9},
    {"trend.k0_inflation", 0x1.078e30bc2a39ap+0},
    {"trend.k0_correlation", 0x1.d67f912d4348ap-3},
    {"walk.rate_random_walk", 0x1.6c1c4ceddf64bp-19},
    {"walk.rate_random_walk_std", 0x1.f7450fae225d4p-23},
    {"walk.angle_random_walk", 0x0p+0},
    {"walk.carried", 0x1p+0},
    {"horizontal.size", 0x1p+1},
    {"horizontal[0].slot", 0x0p+0},
    {"horizontal[0].cos", 0x1.488fd8f1641p-16},
    {"horizontal[0].sin", 0x1.081ade7ba44p-17},
    {"horizontal[0].cos_std", 0x1.8fd5deffa0cc9p-17},
    {"horizontal[0].sin_std", 0x1.48053b62356acp-16},
    {"horizontal[1].slot", 0x1p+0},
    {"horizontal[1].cos", 0x1.0561fa9574bp-16},
    {"horizontal[1].sin", 0x1.06d5bb9d00cp-18},
    {"horizontal[1].cos_std", 0x1.73cb6a0eebb9cp-17},
    {"horizontal[1].sin_std", 0x1.0f2dbfceb721bp-16},
    {"angle_weight", 0x1.7689e11a5c2cp-1},
};
const GoldenFigure kGoldenAngleOnly[] = {
    {"ok", 0x1p+0},
    {"k.ok", 0x1p+0},
    {"k.mean", -0x1.1eb2b8d000ea5p-1},
    {"k.mean_std", 0x1.e138806d1dc94p-14},
    {"k.cos[2]", -0x1.1f48a53a4e603p-11},
    {"k.sin[2]", 0x1.ec0e5f5826cfp-12},
    {"k.cos_std[2]", 0x1.051c4f1ce7ad5p-13},
    {"k.sin_std[2]", 0x1.1fc3fbb1ce015p-13},
    {"k.residual_rms", 0x1.f86e0c6a46981p-13},
    {"k.condition_number", 0x1.fc3990a2cc684p+2},
    {"k.points", 0x1.3cp+10},
    {"k.smallest_attenuation", 0x1p+0},
    {"d.ok", 0x1p+0},
    {"d.mean", 0x1.8c3bf82a95964p-15},
    {"d.mean_std", 0x1.1a3807d829405p-15},
    {"d.cos[2]", 0x1.79655524cd9c8p-18},
    {"d.sin[2]", -0x1.d75f4425c380cp-17},
    {"d.cos_std[2]", 0x1.072dd436d6ap-16},
    {"d.sin_std[2]", 0x1.fe4f84ee5b707p-17},
    {"d.cos[4]", 0x1.8ce6946800e6ap-18},
    {"d.sin[4]", 0x1.4ce1a3343644cp-22},
    {"d.cos_std[4]", 0x1.31943be5c2a92p-18},
    {"d.sin_std[4]", 0x1.7071d0ad3b52fp-19},
    {"d.residual_rms", 0x1.3d11b66f797abp-17},
    {"d.condition_number", 0x1.fc3990a2cc684p+2},
    {"d.points", 0x1.3cp+10},
    {"d.smallest_attenuation", 0x1p+0},
    {"budget.statistical.size", 0x1.8p+1},
    {"budget.statistical[0]", 0x1.e138806d1dc94p-14},
    {"budget.statistical[1]", 0x1.051c4f1ce7ad5p-13},
    {"budget.statistical[2]", 0x1.1fc3fbb1ce015p-13},
    {"budget.angle_noise.size", 0x1.8p+1},
    {"budget.angle_noise[0]", 0x1.3552cb6cfccbep-20},
    {"budget.angle_noise[1]", 0x1.bcca6e149169cp-20},
    {"budget.angle_noise[2]", 0x1.447d07cffa0dep-19},
    {"budget.beyond_noise.size", 0x1.8p+1},
    {"budget.beyond_noise[0]", 0x1.7a6a3c7d834dbp-14},
    {"budget.beyond_noise[1]", 0x1.051663ae82ce7p-13},
    {"budget.beyond_noise[2]", 0x1.1fb88c4964facp-13},
    {"budget.earth_rate.size", 0x1.8p+1},
    {"budget.earth_rate[0]", 0x0p+0},
    {"budget.earth_rate[1]", 0x0p+0},
    {"budget.earth_rate[2]", 0x0p+0},
    {"budget.basis_noise.size", 0x1.8p+1},
    {"budget.basis_noise[0]", 0x0p+0},
    {"budget.basis_noise[1]", 0x1.33804f53d4422p-40},
    {"budget.basis_noise[2]", 0x1.075797fe078cp-40},
    {"budget.bias_walk.size", 0x1.8p+1},
    {"budget.bias_walk[0]", 0x1.e13249bf97c09p-14},
    {"budget.bias_walk[1]", 0x1.bcba0ba6f73ccp-14},
    {"budget.bias_walk[2]", 0x1.50480b6e7f6fcp-14},
    {"drift_budget.statistical.size", 0x1.4p+2},
    {"drift_budget.statistical[0]", 0x1.1a3807d829405p-15},
    {"drift_budget.statistical[1]", 0x1.072dd436d6ap-16},
    {"drift_budget.statistical[2]", 0x1.31943be5c2a92p-18},
    {"drift_budget.statistical[3]", 0x1.fe4f84ee5b707p-17},
    {"drift_budget.statistical[4]", 0x1.7071d0ad3b52fp-19},
    {"drift_budget.angle_noise.size", 0x1.4p+2},
    {"drift_budget.angle_noise[0]", 0x1.b9506449d7ce9p-24},
    {"drift_budget.angle_noise[1]", 0x1.2afc51587b05fp-21},
    {"drift_budget.angle_noise[2]", 0x1.825f1ea242f3ap-24},
    {"drift_budget.angle_noise[3]", 0x1.caab448b96106p-22},
    {"drift_budget.angle_noise[4]", 0x1.0b4044e4e2943p-23},
    {"drift_budget.beyond_noise.size", 0x1.4p+2},
    {"drift_budget.beyond_noise[0]", 0x1.5eaaabbb7b75cp-18},
    {"drift_budget.beyond_noise[1]", 0x1.c7401e1c68a6ap-17},
    {"drift_budget.beyond_noise[2]", 0x1.3184f7510753cp-18},
    {"drift_budget.beyond_noise[3]", 0x1.fe1bfa388d092p-17},
    {"drift_budget.beyond_noise[4]", 0x1.6007afcfcc099p-19},
    {"drift_budget.earth_rate.size", 0x1.4p+2},
    {"drift_budget.earth_rate[0]", 0x0p+0},
    {"drift_budget.earth_rate[1]", 0x0p+0},
    {"drift_budget.earth_rate[2]", 0x0p+0},
    {"drift_budget.earth_rate[3]", 0x0p+0},
    {"drift_budget.earth_rate[4]", 0x0p+0},
    {"drift_budget.basis_noise.size", 0x1.4p+2},
    {"drift_budget.basis_noise[0]", 0x0p+0},
    {"drift_budget.basis_noise[1]", 0x1.93f47180849a1p-47},
    {"drift_budget.basis_noise[2]", 0x1.a8d51738f3d4ep-45},
    {"drift_budget.basis_noise[3]", 0x1.f88b70e3f8191p-46},
    {"drift_budget.basis_noise[4]", 0x1.644ec8fc95fd7p-49},
    {"drift_budget.bias_walk.size", 0x1.4p+2},
    {"drift_budget.bias_walk[0]", 0x1.1a37b1950aca6p-15},
    {"drift_budget.bias_walk[1]", 0x1.07035b8b47d8dp-16},
    {"drift_budget.bias_walk[2]", 0x1.273d33a3f0f3cp-18},
    {"drift_budget.bias_walk[3]", 0x1.dcc872f8c81bcp-17},
    {"drift_budget.bias_walk[4]", 0x1.7010d710de34ep-19},
    {"binned.size", 0x1.6p+4},
    {"binned[0].theta", 0x1.0c152382d7365p-4},
    {"binned[0].k", -0x1.1ec8a9462521fp-1},
    {"binned[0].d", 0x1.e2e4ac0621ca1p-15},
    {"binned[0].weight", 0x1.e000000000008p+2},
    {"binned[1].theta", 0x1.921fb54442d18p-3},
    {"binned[1].k", -0x1.1eb976a5259c1p-1},
    {"binned[1].d", 0x1.bd606e106f3a3p-15},
    {"binned[1].weight", 0x1p+3},
    {"binned[2].theta", 0x1.4f1a6c638d03fp-2},
    {"binned[2].k", -0x1.1eaf40d83f37dp-1},
    {"binned[2].d", 0x1.808859fecb78ap-15},
    {"binned[2].weight", 0x1.a00000000001p+2},
    {"binned[3].theta", 0x1.d524fe24f89f1p-2},
    {"binned[3].k", -0x1.1ea8f1e1e435dp-1},
    {"binned[3].d", 0x1.8b53f4a28ef72p-15},
    {"binned[3].weight", 0x1.8p+2},
    {"binned[4].theta", 0x1.2d97c7f3321d2p-1},
    {"binned[4].k", -0x1.1e9ae76e86e2dp-1},
    {"binned[4].d", 0x1.690c47e681cb2p-15},
    {"binned[4].weight", 0x1.5fffffffffffp+2},
    {"binned[5].theta", 0x1.709d10d3e7eabp-1},
    {"binned[5].k", -0x1.1e8d5bef7b37fp-1},
    {"binned[5].d", 0x1.4ab9918ce4922p-15},
    {"binned[5].weight", 0x1.7fffffffffff8p+2},
    {"binned[6].theta", 0x1.b3a259b49db85p-1},
    {"binned[6].k", -0x1.1e62dd02ec01ap-1},
    {"binned[6].d", 0x1.2b12c8ab46abap-15},
    {"binned[6].weight", 0x1.8000000000008p+2},
    {"binned[7].theta", 0x1.f6a7a2955385dp-1},
    {"binned[7].k", -0x1.1e56b42c1f07cp-1},
    {"binned[7].d", 0x1.1bfb1fdb1dd9fp-15},
    {"binned[7].weight", 0x1.6p+2},
    {"binned[8].theta", 0x1.1cd675bb04a9cp+0},
    {"binned[8].k", -0x1.1e38178afd0a2p-1},
    {"binned[8].d", 0x1.3982544a1cdd8p-15},
    {"binned[8].weight", 0x1.8p+2},
    {"binned[9].theta", 0x1.3e591a2b5f908p+0},
    {"binned[9].k", -0x1.1e321e4f791d6p-1},
    {"binned[9].d", 0x1.8ad5462c4ddb9p-15},
    {"binned[9].weight", 0x1.8p+2},
    {"binned[10].theta", 0x1.5fdbbe9bba775p+0},
    {"binned[10].k", -0x1.1e20e9414e611p-1},
    {"binned[10].d", 0x1.8381c180d60e2p-15},
    {"binned[10].weight", 0x1.7fffffffffff8p+2},
    {"binned[11].theta", 0x1.815e630c155e1p+0},
    {"binned[11].k", -0x1.1e2e1e84bc688p-1},
    {"binned[11].d", 0x1.cf1d51f6674f2p-15},
    {"binned[11].weight", 0x1.6p+2},
    {"binned[12].theta", 0x1.a2e1077c7044fp+0},
    {"binned[12].k", -0x1.1e4a01f884493p-1},
    {"binned[12].d", 0x1.e736fa5261647p-15},
    {"binned[12].weight", 0x1.800000000001p+2},
    {"binned[13].theta", 0x1.c463abeccb2bbp+0},
    {"binned[13].k", -0x1.1e6778a27a7a5p-1},
    {"binned[13].d", 0x1.edac144e4bddfp-15},
    {"binned[13].weight", 0x1.6000000000004p+2},
    {"binned[14].theta", 0x1.e5e6505d26128p+0},
    {"binned[14].k", -0x1.1e99998271bdbp-1},
    {"binned[14].d", 0x1.0b59aa8428edap-14},
    {"binned[14].weight", 0x1.7fffffffffffcp+2},
    {"binned[15].theta", 0x1.03b47a66c07cap+1},
    {"binned[15].k", -0x1.1ed100af4288ap-1},
    {"binned[15].d", 0x1.3a3bbdd5deef8p-14},
    {"binned[15].weight", 0x1.8000000000004p+2},
    {"binned[16].theta", 0x1.1475cc9eedf01p+1},
    {"binned[16].k", -0x1.1ede5ea225e74p-1},
    {"binned[16].d", 0x1.0f8545f99a102p-14},
    {"binned[16].weight", 0x1p-1},
    {"binned[17].theta", 0x1.46b9c347764a3p+1},
    {"binned[17].k", -0x1.1f0052d96bc1dp-1},
    {"binned[17].d", 0x1.25eb30a8b06cp-14},
    {"binned[17].weight", 0x1.8000000000002p+1},
    {"binned[18].theta", 0x1.577b157fa3bd9p+1},
    {"binned[18].k", -0x1.1ef5c02c8635dp-1},
    {"binned[18].d", 0x1.27acbb2aac7fap-14},
    {"binned[18].weight", 0x1.dfffffffffffcp+2},
    {"binned[19].theta", 0x1.683c67b7d131p+1},
    {"binned[19].k", -0x1.1ef15357e8748p-1},
    {"binned[19].d", 0x1.23bc8d676b679p-14},
    {"binned[19].weight", 0x1.0000000000001p+3},
    {"binned[20].theta", 0x1.78fdb9effea47p+1},
    {"binned[20].k", -0x1.1edd709ae1781p-1},
    {"binned[20].d", 0x1.1f195dd66bddap-14},
    {"binned[20].weight", 0x1.dfffffffffff8p+2},
    {"binned[21].theta", 0x1.89bf0c282c17dp+1},
    {"binned[21].k", -0x1.1ed201d353ef8p-1},
    {"binned[21].d", 0x1.1d40441dbf8f6p-14},
    {"binned[21].weight", 0x1.0000000000006p+3},
    {"angle_noise", 0x1.a2c5ae6638c78p-14},
    {"mean_window", 0x1.000084bb2a33ap-1},
    {"increments", 0x1.3cp+10},
    {"blocks", 0x1.4p+5},
    {"trend.order", 0x0p+0},
    {"trend.reference_time", 0x0p+0},
    {"trend.reference_stamp", 0x0p+0},
    {"trend.span", 0x0p+0},
    {"trend.k0_inflation", 0x1p+0},
    {"trend.k0_correlation", 0x0p+0},
    {"walk.rate_random_walk", 0x1.324405cf6a154p-19},
    {"walk.rate_random_walk_std", 0x1.0c67d8256dbf2p-21},
    {"walk.angle_random_walk", 0x1.3f359a162d8eap-15},
    {"walk.carried", 0x1p+0},
    {"horizontal.size", 0x1p+1},
    {"horizontal[0].slot", 0x0p+0},
    {"horizontal[0].cos", 0x1.1689cf78bdp-17},
    {"horizontal[0].sin", 0x1.5999f527366p-17},
    {"horizontal[0].cos_std", 0x1.4af443ef85e96p-16},
    {"horizontal[0].sin_std", 0x1.51feb1cd53d7ep-16},
    {"horizontal[1].slot", 0x1p+0},
    {"horizontal[1].cos", 0x1.879f3160a79p-18},
    {"horizontal[1].sin", 0x1.9e95355a348p-18},
    {"horizontal[1].cos_std", 0x1.90d6f482508bdp-16},
    {"horizontal[1].sin_std", 0x1.f8f19039cba85p-17},
    {"angle_weight", 0x1p+0},
};

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
  expectFigures(a, kGoldenWithRateTrendAndSlots, sizeof(kGoldenWithRateTrendAndSlots) / sizeof(GoldenFigure),
                "rate, trend and slots");

  IncrementRegression angle_only({2}, {2, 4}, 24, 0, 2);
  goldenSession(&angle_only, false);
  angle_only.endChain();
  const IncrementFit b = angle_only.solve(5e-5, 0.0, 0.2, 1e8);
  ASSERT_TRUE(b.ok) << b.reason;
  expectFigures(b, kGoldenAngleOnly, sizeof(kGoldenAngleOnly) / sizeof(GoldenFigure), "angle only");
}

}  // namespace
}  // namespace core
}  // namespace hrg_gyro

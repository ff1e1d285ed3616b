// The statistics of the integrated-angle fit: the propagated covariances are the closed-form laws
// (12 s^2 / (f T^3) for white angle noise, 6/5 N^2 / T for an angle random walk, 13/35 K^2 T for a rate
// random walk) and match the scatter of repeated fits; the white angle noise is measured from the data
// and a change of rate does not disturb it; intercepts per segment free the segments' offsets; a
// parameter the data cannot reach is refused.
#include "hrg_gyro/core/alignment/integrated_angle_fit.h"

#include <gtest/gtest.h>

#include <cmath>

#include "hrg_gyro/core/common/units.h"
#include "hrg_gyro/core/simulation/gaussian_noise.h"

namespace hrg_gyro {
namespace core {
namespace {

struct LineNoise {
  double white = 0.0, arw = 0.0, rrw = 0.0, rate = 1e-5;
};

// One channel, one segment: y = rate t + noise at f Hz over T s.
AngleSeries line(double f, double length, const LineNoise& n, GaussianNoise* g) {
  AngleSeries s;
  s.columns = {0};
  s.regressors.assign(1, {});
  const long points = static_cast<long>(std::llround(f * length)) + 1;
  double walk = 0.0, bias = 0.0, angle = 0.0;
  const double h = 1.0 / f;
  for (long i = 0; i < points; ++i) {
    const double t = i * h;
    if (i > 0) {
      bias += n.rrw * std::sqrt(h) * g->next();
      angle += (n.rate + bias) * h;
      walk += n.arw * std::sqrt(h) * g->next();
    }
    const double y = angle + walk + n.white * g->next();
    s.push(t, 0, y, &t);
  }
  return s;
}

TEST(IntegratedAngleFitTest, PropagatedVariancesAreTheClosedFormLaws) {
  GaussianNoise g(3);
  const double f = 200.0, length = 100.0, white = 8.8e-6, n = 2e-6, k = 1e-9;
  AngleSeries s = line(f, length, LineNoise{white, 0.0, 0.0}, &g);
  s.white_noise = white;
  s.angle_random_walk = n;
  s.rate_random_walk = k;
  IntegratedAngleFit fit(1, {s});
  const AngleFitResult& r = fit.solve(1e8);
  ASSERT_TRUE(r.ok) << r.problem;
  const double points = f * length + 1;
  // White: s^2 / sum (t - tbar)^2 exactly, 12 s^2 / (f T^3) in the limit.
  const double exact_white = white * white * 12.0 / (points * (points * points - 1.0)) * f * f;
  EXPECT_NEAR(r.white(0, 0) / exact_white, 1.0, 1e-9);
  EXPECT_NEAR(r.white(0, 0) / (12.0 * white * white / (f * length * length * length)), 1.0, 1e-3);
  EXPECT_NEAR(r.angle_random_walk(0, 0) / (1.2 * n * n / length), 1.0, 1e-3);
  EXPECT_NEAR(r.rate_random_walk(0, 0) / (13.0 / 35.0 * k * k * length), 1.0, 1e-3);
  // A constant rate goes into the slope in full.
  EXPECT_NEAR(r.constant_rate[0](0), 1.0, 1e-12);
  std::printf("[ measured ] slope sigma over %.0f s at %.0f Hz: white %.3e, arw %.3e, rrw %.3e rad/s\n", length, f,
              std::sqrt(r.white(0, 0)), std::sqrt(r.angle_random_walk(0, 0)), std::sqrt(r.rate_random_walk(0, 0)));
}

TEST(IntegratedAngleFitTest, RepeatedFitsScatterAsPredicted) {
  // Each noise alone, 300 repetitions: the rms of (slope - truth) over the predicted sigma near 1.
  const double f = 50.0, length = 60.0;
  const LineNoise cases[] = {{8.8e-6, 0.0, 0.0}, {0.0, 3e-6, 0.0}, {1e-9, 0.0, 2e-9}};
  for (const LineNoise& n : cases) {
    GaussianNoise g(11);
    double z2 = 0.0, measured_white = 0.0;
    const int trials = 300;
    for (int trial = 0; trial < trials; ++trial) {
      AngleSeries s = line(f, length, n, &g);
      s.white_noise = n.white > 0.0 ? -1.0 : 1e-12;  // measured when there is some
      s.angle_random_walk = n.arw;
      s.rate_random_walk = n.rrw;
      IntegratedAngleFit fit(1, {s});
      const AngleFitResult& r = fit.solve(1e8);
      ASSERT_TRUE(r.ok) << r.problem;
      const double e = r.parameters(0) - n.rate;
      z2 += e * e / r.covariance()(0, 0);
      measured_white += r.white_noise[0] / trials;
    }
    const double rms_z = std::sqrt(z2 / trials);
    std::printf("[ measured ] white %.1e arw %.1e rrw %.1e: rms z %.3f over %d fits; measured white noise %.3e\n",
                n.white, n.arw, n.rrw, rms_z, trials, measured_white);
    // 300 trials: the rms of a unit normal is within 1 +- 0.04 (1 sigma); 0.85..1.15 is 3.7 of them.
    EXPECT_GT(rms_z, 0.85);
    EXPECT_LT(rms_z, 1.15);
    if (n.white > 1e-7) EXPECT_NEAR(measured_white / n.white, 1.0, 0.02);
  }
}

TEST(IntegratedAngleFitTest, SegmentsHaveTheirOwnInterceptsAndAChangeOfRateLeavesTheNoiseEstimate) {
  // Two channels sharing a slope beta0 and a gain beta1 on a turn that only one channel makes (0.36
  // rad/s in its second segment), each with a jump between its segments.
  GaussianNoise g(5);
  const double f = 200.0, white = 8.8e-6;
  std::vector<AngleSeries> channels(2);
  for (int c = 0; c < 2; ++c) {
    AngleSeries& s = channels[c];
    s.columns = {0, 1};
    s.regressors.assign(2, {});
    s.white_noise = -1.0;
    double angle = 0.0, turn = 0.0;
    for (int seg = 0; seg < 2; ++seg) {
      angle += 0.37 * (seg + 1) * (c + 1);  // the jump a gap leaves
      for (int i = 0; i <= 4000; ++i) {
        const double t = seg * 30.0 + i / f;
        const double w = (c == 1 && seg == 1) ? 0.36 : 0.0;
        if (i > 0) turn += w / f;
        const double x[2] = {t, turn};
        s.push(t, seg, angle + 2e-5 * t + 1.5 * turn + white * g.next(), x);
      }
    }
  }
  IntegratedAngleFit fit(2, channels);
  const AngleFitResult& r = fit.solve(1e8);
  ASSERT_TRUE(r.ok) << r.problem;
  const double sigma = std::sqrt(r.covariance()(0, 0));
  EXPECT_LT(std::abs(r.parameters(0) - 2e-5), 4.0 * sigma);
  EXPECT_LT(std::abs(r.parameters(1) - 1.5), 4.0 * std::sqrt(r.covariance()(1, 1)));
  for (double w : r.white_noise) EXPECT_NEAR(w / white, 1.0, 0.03);
  for (double s : r.scatter) EXPECT_LT(s, 1.2);
  EXPECT_EQ(r.segments.size(), 4u);
}

TEST(IntegratedAngleFitTest, AQuantisedAngleIsCoveredByItsQuantum) {
  // An IMU counting its angle in 0.1 arcsec: 100 Hz at an Earth-rate-sized 4.4e-5 rad/s, the
  // increments 0 or one count (most neighbours' departures 0), a white noise far below the count.
  const double q = 0.1 / 3600.0 * kPi / 180.0, f = 100.0, length = 60.0;
  GaussianNoise g(5);
  double z2_blind = 0.0, z2_quantum = 0.0, white_blind = 0.0, white_quantum = 0.0;
  const int trials = 60;
  for (int trial = 0; trial < trials; ++trial) {
    const double rate = 4.4e-5 * (1.0 + 0.01 * g.next()), phase = 0.5 + 0.3 * g.next();
    AngleSeries s;
    s.columns = {0};
    s.regressors.assign(1, {});
    for (long i = 0; i <= static_cast<long>(f * length); ++i) {
      const double t = i / f;
      const double y = q * std::round((rate * t + 2e-8 * g.next()) / q + phase);
      s.push(t, 0, y, &t);
    }
    for (double quantum : {0.0, q}) {
      AngleSeries c = s;
      c.white_noise = -1.0;
      c.angle_quantum = quantum;
      IntegratedAngleFit fit(1, {c});
      const AngleFitResult& r = fit.solve(1e8);
      ASSERT_TRUE(r.ok) << r.problem;
      const double z = (r.parameters(0) - rate) / std::sqrt(r.covariance()(0, 0));
      (quantum > 0.0 ? z2_quantum : z2_blind) += z * z / trials;
      (quantum > 0.0 ? white_quantum : white_blind) += r.white_noise[0] / trials;
    }
  }
  std::printf(
      "[ measured ] 0.1 arcsec counts at 100 Hz, %d windows of %.0f s: white noise measured %.3g rad "
      "(rms z %.2f); with the quantum's q^2/12 %.3g rad (rms z %.2f)\n",
      trials, length, white_blind, std::sqrt(z2_blind), white_quantum, std::sqrt(z2_quantum));
  EXPECT_LT(white_blind, 0.2 * q) << "the measurement alone cannot see the rounding";
  EXPECT_NEAR(white_quantum, q / std::sqrt(12.0), 0.05 * q);
  EXPECT_GT(std::sqrt(z2_blind), 2.0) << "without the quantum the sigma claims too much";
  EXPECT_LT(std::sqrt(z2_quantum), 1.3) << "with it the sigma covers the error";
}

TEST(IntegratedAngleFitTest, RefusesWhatItCannotSolve) {
  GaussianNoise g(1);
  AngleSeries s = line(100.0, 10.0, LineNoise{1e-6}, &g);
  // A parameter no channel reaches.
  {
    IntegratedAngleFit fit(2, {s});
    const AngleFitResult& r = fit.solve(1e8);
    EXPECT_FALSE(r.ok);
    EXPECT_NE(r.problem.find("cannot separate"), std::string::npos) << r.problem;
  }
  // Times that go back.
  {
    AngleSeries bad = s;
    bad.time[5] = bad.time[3];
    IntegratedAngleFit fit(1, {bad});
    EXPECT_FALSE(fit.solve(1e8).ok);
  }
  // A regressor collinear with the intercept (a constant): nothing to fit it from.
  {
    AngleSeries flat = s;
    flat.columns.push_back(1);
    flat.regressors.push_back(std::vector<double>(s.size(), 3.0));
    IntegratedAngleFit fit(2, {flat});
    EXPECT_FALSE(fit.solve(1e8).ok);
  }
}

}  // namespace
}  // namespace core
}  // namespace hrg_gyro

// The correction matrix P (docs/math.md, 'Correction matrix'): exact recovery on linear defects,
// removal of the 2 theta harmonics, the paper's Z_m typo, and refusal of a sweep that cannot determine P.
#include <gtest/gtest.h>

#include <Eigen/LU>

#include "core/testing/angle_sweep.h"

namespace hrg_gyro {
namespace core {
namespace {

PickoffDefects linearDefects() {
  PickoffDefects d;
  d.misplacement = {1.2e-3, -4e-4, 9e-4, 3e-4, 1.1e-3, -8e-4, 6e-4, -2e-4};
  d.gain_error = {2e-3, -1e-3, 1.5e-3, 4e-4, 1.8e-3, -2e-3, 2.2e-3, -6e-4};
  return d;
}

// Generator sweep: theta evenly over [0, pi), several quadratures and phases.
template <typename ReferenceFn>
CorrectionMatrixEstimator::Result fitFromGenerator(const PickoffDefects& d, ReferenceFn reference,
                                                   std::vector<double> quadratures = {0.0, 0.05, -0.1}) {
  SignalSynthesizer synth(d, 32, 5);
  CorrectionMatrixEstimator est;
  for (int i = 0; i < 24; ++i) {
    for (double b : quadratures) {
      for (double tau : {0.0, 0.7, -1.9}) {
        const WaveParameters w{1.0, b, kPi * i / 24.0, tau};
        est.add(synth.period(w, w.theta), reference(w));
      }
    }
  }
  return est.solve();
}

TEST(CorrectionMatrixTest, RecoversTheExactInverseOfLinearDefects) {
  const PickoffDefects d = linearDefects();
  const auto result = fitFromGenerator(d, [](const WaveParameters& w) { return idealChannels(w); });
  ASSERT_TRUE(result.ok) << result.reason;
  const Eigen::Matrix4d m = PickoffArray(d).linearChannelMap();
  const Eigen::Matrix4d e_minus_p = Eigen::Matrix4d::Identity() - result.correction.matrix();
  EXPECT_LT((e_minus_p - m.inverse()).cwiseAbs().maxCoeff(), 1e-12);
  // Exact fit; the residual from the streamed normal equations carries ~1e-11 of cancellation.
  EXPECT_LT(result.residual_rms, 1e-9);
  // First order: p1, p2 ~ gc, gs and p3, p4 ~ dc, ds.
  const PickoffSignature sig = PickoffArray(d).signature();
  EXPECT_NEAR(result.correction.p[0], sig.gc, 5e-5);
  EXPECT_NEAR(result.correction.p[1], sig.gs, 5e-5);
  EXPECT_NEAR(result.correction.p[2], sig.dc, 5e-5);
  EXPECT_NEAR(result.correction.p[3], sig.ds, 5e-5);
}

TEST(CorrectionMatrixTest, CorrectedChannelsHaveNo2ThetaHarmonics) {
  const PickoffDefects d = linearDefects();
  const auto fit = fitFromGenerator(d, [](const WaveParameters& w) { return idealChannels(w); });
  const WaveParameters wave{1.0, 0.05, 0.0, 0.4};
  const auto raw = testing::sweepAngleError(d, wave);
  const auto corrected = testing::sweepAngleError(d, wave, fit.correction);
  EXPECT_GT(std::hypot(raw.c[2], raw.s[2]), 5e-4);
  EXPECT_LT(std::hypot(corrected.c[2], corrected.s[2]), 1e-12);
  EXPECT_LT(std::abs(corrected.c0), 1e-12);
}

TEST(CorrectionMatrixTest, Stage2KeepsThe4ThetaTermOfThePickoffNonlinearity) {
  PickoffDefects d = linearDefects();
  d.gap = 12.5;  // a = 0.08
  const auto fit = fitFromGenerator(d, [](const WaveParameters& w) { return idealChannels(w); });
  ASSERT_TRUE(fit.ok);
  const WaveParameters wave{1.0, 0.0, 0.0, 0.4};
  const auto corrected = testing::sweepAngleError(d, wave, fit.correction);
  const double cap = 3.0 * 0.08 * 0.08 / 16.0;  // amplitude of the sin 4th angle error
  EXPECT_LT(std::hypot(corrected.c[2], corrected.s[2]), 0.02 * cap);
  EXPECT_NEAR(std::abs(corrected.s[4]), cap, 0.02 * cap);
}

TEST(CorrectionMatrixTest, PaperZmTypoMakesThe2ThetaErrorWorse) {
  // The paper's row 4 of Z_m reads -A sin th sin tau + B sin th cos tau; the right one has B cos th.
  // With quadrature in the generator sweep the typo leaves a 2 theta error larger than the raw one
  // (measured: 2.2x at B = 0.1, 8.5x at B = 0.2) where the right Z_m removes it completely.
  const PickoffDefects d = linearDefects();
  const double b = 0.2;
  const auto typo = fitFromGenerator(d,
                                     [](const WaveParameters& w) {
                                       ChannelVector z = idealChannels(w);
                                       z[kBs] = -w.amplitude * std::sin(w.theta) * std::sin(w.phase) +
                                                w.quadrature * std::sin(w.theta) * std::cos(w.phase);
                                       return z;
                                     },
                                     {b, -b});
  const auto right = fitFromGenerator(d, [](const WaveParameters& w) { return idealChannels(w); }, {b, -b});
  const WaveParameters wave{1.0, b, 0.0, 0.4};
  const double raw = [&] {
    const auto h = testing::sweepAngleError(d, wave);
    return std::hypot(h.c[2], h.s[2]);
  }();
  const auto with_typo = testing::sweepAngleError(d, wave, typo.correction);
  const auto with_right = testing::sweepAngleError(d, wave, right.correction);
  EXPECT_GT(std::hypot(with_typo.c[2], with_typo.s[2]), 5.0 * raw);
  EXPECT_LT(std::hypot(with_right.c[2], with_right.s[2]), 1e-12);
}

TEST(CorrectionMatrixTest, RefusesASweepAtOneAngle) {
  SignalSynthesizer synth(linearDefects(), 32, 5);
  CorrectionMatrixEstimator est;
  for (int i = 0; i < 10; ++i) {
    const WaveParameters w{1.0, 0.0, 0.3, 0.0};
    est.add(synth.period(w, w.theta), idealChannels(w));
  }
  const auto r = est.solve();
  EXPECT_FALSE(r.ok);
  EXPECT_NE(r.reason.find("spread theta"), std::string::npos) << r.reason;
  EXPECT_FALSE(CorrectionMatrixEstimator().solve().ok);
}

TEST(CorrectionMatrixTest, ApplyMatchesMatrixForm) {
  CorrectionMatrix p;
  p.p = {1e-3, -2e-3, 5e-4, 7e-4};
  const ChannelVector z(0.3, -0.2, 0.9, 0.1);
  const ChannelVector expected = (Eigen::Matrix4d::Identity() - p.matrix()) * z;
  EXPECT_LT((p.apply(z) - expected).norm(), 1e-16);
  EXPECT_TRUE(CorrectionMatrix().isIdentity());
}

}  // namespace
}  // namespace core
}  // namespace hrg_gyro

// Block means of dense fit windows (fit/block_mean.h, issue 9 item 12): when they apply, that they
// never span a gap, that the noise of a fitted point is measured at rest, and that a fit on block
// means finds the I of the fit on every sample (known truth: fit/trace_synth.h).
#include <cmath>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "fit/block_mean.h"
#include "fit/trace_fit.h"
#include "fit/trace_synth.h"

namespace bifilar {
namespace {

TEST(BlockMean, OnlyDenseLongWindowsAreAveraged) {
  const BlockMeanOptions o;  // 65536 points, T / 1000
  std::string why;
  EXPECT_TRUE(o.Check(&why)) << why;
  // The sample campaign's logs (50 Hz, 60 s) and a long 100 Hz log (1 M samples, period 2.5 s:
  // 250 samples per period) are fitted on their samples.
  EXPECT_EQ(BlockMeanSpan(3000, 60.0, 2.5, o), 0.0);
  EXPECT_EQ(BlockMeanSpan(1000000, 10000.0, 2.5, o), 0.0);
  // 16 kHz for 170 s, T = 2.64 s: k = min(ceil(2.72 M / 65536) = 42, floor(42240 / 1000) = 42).
  const double step = 1.0 / 16000.0;
  EXPECT_NEAR(BlockMeanSpan(2720000, 2719999 * step, 2.64, o), 41.5 * step, 1e-12);
  // 46.7 kHz for 60 s, T = 2.46 s: the point budget decides (k = ceil(2.8 M / 65536) = 43).
  const double step2 = 60.0 / 2799999.0;
  EXPECT_NEAR(BlockMeanSpan(2800000, 60.0, 2.46, o), 42.5 * step2, 1e-12);
  // Unknown period or bad input: no averaging.
  EXPECT_EQ(BlockMeanSpan(2800000, 60.0, 0.0, o), 0.0);
  EXPECT_EQ(BlockMeanSpan(2800000, NAN, 2.46, o), 0.0);
}

TEST(BlockMean, MeansAreExactForALineAndNeverSpanAGap) {
  // 1 kHz samples 0..0.999 s, a 0.5 s gap, then 1.5..2.499 s; v = 3 + 2 t.
  std::vector<double> t, v;
  for (int i = 0; i < 1000; ++i) t.push_back(0.001 * i);
  for (int i = 0; i < 1000; ++i) t.push_back(1.5 + 0.001 * i);
  for (double x : t) v.push_back(3.0 + 2.0 * x);
  std::vector<double> bt, bv;
  BlockMeans(t, v, 0, t.size() - 1, 9.5e-3, &bt, &bv);
  ASSERT_EQ(bt.size(), 200u);  // exactly 10 samples per block on each side of the gap
  for (size_t j = 0; j < bt.size(); ++j) {
    EXPECT_NEAR(bv[j], 3.0 + 2.0 * bt[j], 1e-12);  // the mean of a line is the line at mean t
    EXPECT_FALSE(bt[j] > 0.999 && bt[j] < 1.5) << "a block spans the gap at " << bt[j];
    if (j > 0) {
      EXPECT_GT(bt[j], bt[j - 1]);
    }
  }
  // span <= 0: the samples themselves.
  BlockMeans(t, v, 10, 19, 0.0, &bt, &bv);
  ASSERT_EQ(bt.size(), 10u);
  EXPECT_EQ(bt[0], t[10]);
  EXPECT_EQ(bv[9], v[19]);
}

TEST(BlockMean, PointNoiseIsMeasuredOnTheRestsBlockMeans) {
  // 10 s of rest then 100 s of signal at 10 kHz; k = 20 per block (max_points 50000).
  constexpr double kSigma = 0.01;
  BlockMeanOptions o;
  o.max_points = 50000;
  for (double phi : {0.0, 0.8}) {
    std::mt19937_64 rng(7);
    std::normal_distribution<double> w(0.0, kSigma * std::sqrt(1.0 - phi * phi));
    std::vector<double> t, rate;
    double e = std::normal_distribution<double>(0.0, kSigma)(rng);
    for (int i = 0; i < 1100000; ++i) {
      t.push_back(1e-4 * i);
      e = phi * e + w(rng);
      rate.push_back(e + (t.back() > 10.0 ? std::sin(2.0 * M_PI * t.back() / 2.5) : 0.0));
    }
    const size_t first = 100001;
    const FitSeries s = MakeFitSeries(t, rate, first, t.size() - 1, 2.5, kSigma, 10.0, o);
    ASSERT_TRUE(s.block_means());
    EXPECT_NEAR(s.samples_per_point, 20.0, 0.01);
    // The std of a mean of k = 20 AR(1) samples: sigma^2 / k^2 (k + 2 sum_{l<k} (k - l) phi^l).
    double var = 20.0;
    for (int l = 1; l < 20; ++l) var += 2.0 * (20 - l) * std::pow(phi, l);
    const double expected = kSigma * std::sqrt(var) / 20.0;
    // 5000 rest blocks (coloured: ~1000 independent): 10 % is > 4 sigma of the estimate.
    EXPECT_NEAR(s.noise_rad_per_s / expected, 1.0, 0.1) << "phi " << phi;
  }
}

// A 2 kHz window (40 k samples, period ~2.8 s): the fit on block means of 5 samples (max_points
// 5000 here, so the test stays fast) against the fit on every sample and the truth.
TEST(BlockMean, FitOnBlockMeansMatchesTheFitOnEverySample) {
  SyntheticTraceOptions truth = ExampleRigTraceOptions(25.0, 1);
  truth.duration_s = 20.0;
  truth.sample_rate_hz = 2000.0;
  truth.noise_deg_per_s = 0.5;
  truth.seed = 3;
  TraceFitInput all;
  ASSERT_TRUE(MakeSyntheticTrace(truth, &all));
  all.label = "dense.csv";
  all.noise_rad_per_s = 0.0;  // both fits estimate their points' noise from the data
  const size_t n = all.t_s.size();

  BlockMeanOptions o;
  o.max_points = 5000;
  // Period 2.8 s at 2 kHz: 5600 samples per period, k = min(ceil(40 k / 5000), 5) = 5.
  const FitSeries s = MakeFitSeries(all.t_s, all.rate_rad_per_s, 0, n - 1, 2.8, 0.0, 0.0, o);
  ASSERT_TRUE(s.block_means());
  EXPECT_NEAR(s.samples_per_point, 5.0, 0.2);
  TraceFitInput means = all;
  means.t_s = s.t_s;
  means.rate_rad_per_s = s.rate_rad_per_s;

  TraceFitOptions fit_options;
  fit_options.amplitude_sweep = false;
  const TraceFitResult fit_all = FitTrace(all, fit_options);
  const TraceFitResult fit_means = FitTrace(means, fit_options);
  ASSERT_EQ(fit_all.status, TraceFitStatus::kOk) << fit_all.message;
  ASSERT_EQ(fit_means.status, TraceFitStatus::kOk) << fit_means.message;
  const double std_all = fit_all.inertia_stat_std_kg_m2;
  ASSERT_GT(std_all, 0.0);
  // White noise: the means carry the same information, so the same I to a small fraction of its
  // std (the block bias, (omega h)^2 / 24 ~ 4e-8 here, is far below it) and the same std.
  EXPECT_LT(std::abs(fit_means.params.inertia_kg_m2 - fit_all.params.inertia_kg_m2), 0.1 * std_all);
  EXPECT_NEAR(fit_means.inertia_stat_std_kg_m2 / std_all, 1.0, 0.1);
  // Both find the truth within 4 sigma.
  EXPECT_LT(std::abs(fit_means.params.inertia_kg_m2 - truth.params.inertia_kg_m2), 4.0 * std_all);
  // The noise of a point is the noise of a mean of 5 samples.
  EXPECT_NEAR(fit_means.noise_rad_per_s / (fit_all.noise_rad_per_s / std::sqrt(5.0)), 1.0, 0.1);
}

}  // namespace
}  // namespace bifilar

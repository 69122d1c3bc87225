// Trace fit against known truth: synthetic free-oscillation windows (fit/trace_synth.h) from the
// `full` model at jittered timestamps with 1 % dropped samples, a gyro bias and 0.25 deg/s white
// noise, fitted with FitTrace. Seeds are fixed; tolerances are explained where they are set.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <random>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <unistd.h>

#include "base/units.h"
#include "fit/trace_fit.h"
#include "fit/trace_guess.h"
#include "fit/trace_synth.h"
#include "pipeline/figures/trace_plot.h"

namespace bifilar {
namespace {

// The docs/physics.md §2 example rig (fit/trace_synth.h): D/L = 0.44 and m (D/2)^2 / I = 1 at
// I = 1.1616 kg m^2, where the full model's kinetic term matters (period ~2.8 s).
SyntheticTraceOptions Truth(double amplitude_deg, uint64_t seed) {
  return ExampleRigTraceOptions(amplitude_deg, seed);
}

TraceFitInput Make(const SyntheticTraceOptions& o) {
  TraceFitInput in;
  EXPECT_TRUE(MakeSyntheticTrace(o, &in));
  in.label = "synthetic.csv";
  return in;
}

bool AllFinite(const TraceFitResult& r) {
  const double v[] = {r.params.inertia_kg_m2,
                      r.params.drag_coeff_kg_m2,
                      r.params.viscous_coeff_kg_m2_per_s,
                      r.angle0_rad,
                      r.rate0_rad_per_s,
                      r.bias_rad_per_s,
                      r.inertia_std_kg_m2,
                      r.inertia_stat_std_kg_m2,
                      r.inertia_budget_std_kg_m2,
                      r.residual_rms_rad_per_s,
                      r.noise_rad_per_s,
                      r.rms_over_noise,
                      r.residual_autocorr_lag1,
                      r.residual_autocorr_max,
                      r.ljung_box_q,
                      r.amplitude_start_deg,
                      r.amplitude_end_deg,
                      r.period_s,
                      r.initial_cost,
                      r.final_cost,
                      r.fit_seconds,
                      r.drag_coeff_std,
                      r.viscous_coeff_std};
  for (double x : v)
    if (!std::isfinite(x)) return false;
  for (double x : r.residual_rad_per_s)
    if (!std::isfinite(x)) return false;
  return true;
}

bool HasFlag(const TraceFitResult& r, const std::string& flag) {
  return std::find(r.flags.begin(), r.flags.end(), flag) != r.flags.end();
}

double Median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  const size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

TEST(TraceFit, RecoversEveryParameterOnA20DegTrace) {
  const SyntheticTraceOptions truth = Truth(20.0, 11);
  const TraceFitInput in = Make(truth);
  const TraceFitResult r = FitTrace(in, TraceFitOptions());
  ASSERT_EQ(r.status, TraceFitStatus::kOk) << r.BriefReport();
  EXPECT_TRUE(r.flags.empty());
  EXPECT_TRUE(AllFinite(r));
  // 5 sigma of the reported (Cramer-Rao, residual-scaled) standard errors.
  const double I = truth.params.inertia_kg_m2;
  EXPECT_NEAR(r.params.inertia_kg_m2, I, 5 * r.inertia_stat_std_kg_m2);
  EXPECT_NEAR(r.params.drag_coeff_kg_m2, truth.params.drag_coeff_kg_m2, 5 * r.drag_coeff_std);
  EXPECT_NEAR(r.params.viscous_coeff_kg_m2_per_s, truth.params.viscous_coeff_kg_m2_per_s,
              5 * r.viscous_coeff_std);
  // The reported std is ~1e-5 of I at this amplitude (CRLB-sized, not inflated).
  EXPECT_LT(r.inertia_stat_std_kg_m2, 2e-5 * I);
  EXPECT_GT(r.inertia_stat_std_kg_m2, 2e-6 * I);
  // Bias: sigma / sqrt(N) = 4.4e-3 / 77 = 5.7e-5 rad/s; 5 sigma.
  EXPECT_NEAR(r.bias_rad_per_s, truth.bias_deg_per_s * kRadPerDeg, 3e-4);
  EXPECT_NEAR(r.angle0_rad, 20.0 * kRadPerDeg, 1e-3);
  EXPECT_NEAR(r.rate0_rad_per_s, 0.0, 1e-3);
  // White residuals at the noise level.
  EXPECT_NEAR(r.rms_over_noise, 1.0, 0.05);
  EXPECT_LT(r.residual_autocorr_max, 0.06);  // ~4.5/sqrt(N): white noise, max over 10 lags
  EXPECT_NEAR(r.amplitude_start_deg, 20.0, 0.05);
  EXPECT_LT(r.amplitude_end_deg, r.amplitude_start_deg);
  EXPECT_FALSE(r.nlopt_refined);
  EXPECT_LT(r.iterations, 20);
  EXPECT_LT(r.final_cost, r.initial_cost);
  // The guess alone is already close: I within 0.1 %, period within 0.1 %.
  EXPECT_NEAR(r.guess.params.inertia_kg_m2, I, 1e-3 * I);
  // Series for the figure: fitted - measured = residual.
  ASSERT_EQ(r.t_s.size(), in.t_s.size());
  ASSERT_EQ(r.fitted_rate_rad_per_s.size(), in.t_s.size());
  for (size_t k = 0; k < in.t_s.size(); k += 97)
    EXPECT_NEAR(r.fitted_rate_rad_per_s[k] - r.measured_rate_rad_per_s[k], r.residual_rad_per_s[k],
                1e-12);
  EXPECT_NE(r.BriefReport().find("ok [full]"), std::string::npos);
}

// The numbers: >= 30 traces, amplitudes 5..30 deg, full-model truth, 0.25 deg/s noise,
// 1 % drops, jitter. The same traces are fitted with jardin and linear for the README table.
TEST(TraceFit, AccuracyOverAmplitudes5To30Deg) {
  const int kTraces = 30;
  std::vector<double> err_full, err_jardin, err_linear, z_full;
  int ok_jardin = 0, ok_linear = 0;
  std::printf("  amp_deg   I_true    err_full   err_jardin  err_linear  std_full  it  ms\n");
  for (int i = 0; i < kTraces; ++i) {
    const double amplitude = 5.0 + 25.0 * i / (kTraces - 1);
    SyntheticTraceOptions truth = Truth(amplitude, 100 + i);
    // Vary the body: I +-20 %, drag and viscous damping, release rate, twist direction.
    truth.params.inertia_kg_m2 = 1.1616 * (0.8 + 0.4 * ((i * 7) % kTraces) / kTraces);
    truth.params.drag_coeff_kg_m2 = 0.002 * (1 + (i % 4));
    truth.params.viscous_coeff_kg_m2_per_s = 0.001 * (1 + (i % 3));
    truth.rate0_deg_per_s = 0.5 * ((i % 5) - 2);
    if (i % 2) truth.amplitude_deg = -amplitude;
    const TraceFitInput in = Make(truth);
    const double I = truth.params.inertia_kg_m2;
    double err[3] = {0, 0, 0};
    TraceFitResult full;
    for (int m = 0; m < 3; ++m) {
      TraceFitOptions options;
      options.model = m == 0 ? PendulumModel::kFull
                             : (m == 1 ? PendulumModel::kJardin : PendulumModel::kLinear);
      const TraceFitResult r = FitTrace(in, options);
      ASSERT_TRUE(AllFinite(r)) << r.BriefReport();
      ASSERT_NE(r.status, TraceFitStatus::kError) << r.BriefReport();
      err[m] = r.params.inertia_kg_m2 / I - 1.0;
      if (m == 0) {
        EXPECT_EQ(r.status, TraceFitStatus::kOk) << r.BriefReport();
        full = r;
        z_full.push_back((r.params.inertia_kg_m2 - I) / r.inertia_std_kg_m2);
      }
      if (m == 1 && r.IsUsable()) ++ok_jardin;
      if (m == 2 && r.IsUsable()) ++ok_linear;
    }
    err_full.push_back(std::abs(err[0]));
    err_jardin.push_back(std::abs(err[1]));
    err_linear.push_back(std::abs(err[2]));
    std::printf("  %6.1f  %8.5f  %+9.2e  %+9.2e  %+9.2e  %8.1e  %2d %4.0f\n", amplitude, I, err[0],
                err[1], err[2], full.inertia_std_kg_m2 / I, full.iterations,
                full.fit_seconds * 1e3);
  }
  const double med = Median(err_full);
  const double mx = *std::max_element(err_full.begin(), err_full.end());
  int within2 = 0;
  for (double z : z_full) within2 += std::abs(z) < 2.0;
  std::printf(
      "  |rel err I|  full: median %.2e max %.2e | jardin: median %.2e max %.2e (%d ok) |"
      " linear: median %.2e max %.2e (%d ok) | full within 2 sigma: %d/%d\n",
      med, mx, Median(err_jardin), *std::max_element(err_jardin.begin(), err_jardin.end()),
      ok_jardin, Median(err_linear), *std::max_element(err_linear.begin(), err_linear.end()),
      ok_linear, within2, kTraces);
  // Issue 3 targets: median <= 0.01 %, max <= 0.05 %.
  EXPECT_LE(med, 1e-4);
  EXPECT_LE(mx, 5e-4);
  // The simpler models are biased on the same traces (docs/physics.md §2: jardin misses the rise's
  // kinetic energy, linear the amplitude dependence of the period): their median error is many
  // times the full model's.
  EXPECT_GT(Median(err_jardin), 5 * med);
  EXPECT_GT(Median(err_linear), 20 * med);
}

// Honest standard error: seeded Monte Carlo over noise, jitter and drops of one truth.
TEST(TraceFit, ReportedStdIsHonestInMonteCarlo) {
  const int kFits = 120;
  int within2 = 0;
  double sum_z2 = 0.0;
  for (int i = 0; i < kFits; ++i) {
    SyntheticTraceOptions truth = Truth(15.0, 5000 + i);
    truth.duration_s = 40.0;  // shorter traces keep the test fast; the statistics do not care
    const TraceFitResult r = FitTrace(Make(truth), TraceFitOptions());
    ASSERT_EQ(r.status, TraceFitStatus::kOk) << r.BriefReport();
    const double z = (r.params.inertia_kg_m2 - truth.params.inertia_kg_m2) / r.inertia_std_kg_m2;
    within2 += std::abs(z) < 2.0;
    sum_z2 += z * z;
  }
  const double fraction = double(within2) / kFits;
  const double z_rms = std::sqrt(sum_z2 / kFits);
  std::printf("  Monte Carlo: %d/%d = %.1f %% within 2 sigma, rms(z) = %.3f\n", within2, kFits,
              100 * fraction, z_rms);
  // Expected 95.4 %; binomial sd at n = 120 is 1.9 %, so [88 %, 99.5 %] is about -4 / +2 sd.
  EXPECT_GE(fraction, 0.88);
  EXPECT_LE(fraction, 0.995);
  // rms of z is 1 for an honest sigma; its sampling sd at n = 120 is ~0.065: allow ~3 sd.
  EXPECT_NEAR(z_rms, 1.0, 0.2);
}

// The guess must bring LM home on its own (no multi-starts, no NLopt): a seeded sweep over rigs
// (D/L 0.15-0.6, I/(m D^2/4) 0.3-2.3), amplitudes 2-60 deg, damping up to K_D/I = 0.2,
// window lengths 8-108 s and sample rates 25-400 Hz. Every fit is ok and within 5 sigma.
TEST(TraceFit, ConvergesFromTheGuessAcrossRigsRatesAndAmplitudes) {
  std::mt19937 rng(2024);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  int fitted = 0;
  for (int i = 0; i < 40; ++i) {
    SyntheticTraceOptions o;
    const double L = 1.0 + 2.0 * u(rng), D = L * (0.15 + 0.45 * u(rng)), m = 2.0 + 20.0 * u(rng);
    o.geometry.filar_length_m = L;
    o.geometry.filar_separation_m = D;
    o.geometry.mass_kg = m;
    const double I = m * D * D / 4 * (0.3 + 2.0 * u(rng));
    o.params.inertia_kg_m2 = I;
    o.params.drag_coeff_kg_m2 = I * 0.02 * u(rng) * (u(rng) < 0.3 ? 10 : 1);
    o.params.viscous_coeff_kg_m2_per_s = I * 0.005 * u(rng);
    o.amplitude_deg = (u(rng) < 0.5 ? -1 : 1) * (2.0 + 58.0 * u(rng));
    o.rate0_deg_per_s = 2.0 * (u(rng) - 0.5);
    o.duration_s = 8.0 + 100.0 * u(rng);
    o.sample_rate_hz = u(rng) < 0.3 ? 25.0 + 50.0 * u(rng) : 100.0 + 300.0 * u(rng);
    o.bias_deg_per_s = 2.0 * (u(rng) - 0.5);
    o.seed = 900 + i;
    const TraceFitResult r = FitTrace(Make(o), TraceFitOptions());
    ASSERT_TRUE(AllFinite(r));
    if (r.status == TraceFitStatus::kRejected && HasFlag(r, "no_usable_oscillation")) {
      EXPECT_NE(r.message.find("periods"), std::string::npos) << r.message;  // short + slow
      continue;
    }
    ++fitted;
    EXPECT_EQ(r.status, TraceFitStatus::kOk) << i << ": " << r.BriefReport();
    EXPECT_FALSE(r.nlopt_refined) << i;
    EXPECT_LT(std::abs(r.params.inertia_kg_m2 - I), 5 * r.inertia_std_kg_m2)
        << i << ": " << r.BriefReport();
  }
  EXPECT_GE(fitted, 36);
}

TEST(TraceFit, HeavyQuadraticDragFrom56Deg) {
  // K_D / I = 0.11: the swing decays from 56 to ~4 deg in 100 s, far from one exponential;
  // the guess splits the decay into C and K_D from the amplitude dependence of the decrement.
  SyntheticTraceOptions truth = Truth(56.0, 91);
  truth.params.drag_coeff_kg_m2 = 0.127;
  truth.params.viscous_coeff_kg_m2_per_s = 0.005;
  truth.duration_s = 100.0;
  const TraceFitResult r = FitTrace(Make(truth), TraceFitOptions());
  ASSERT_EQ(r.status, TraceFitStatus::kOk) << r.BriefReport();
  EXPECT_NEAR(r.params.inertia_kg_m2, truth.params.inertia_kg_m2, 5 * r.inertia_stat_std_kg_m2);
  EXPECT_NEAR(r.guess.params.drag_coeff_kg_m2, 0.127, 0.3 * 0.127);
  EXPECT_NEAR(r.params.drag_coeff_kg_m2, 0.127, 5 * r.drag_coeff_std);
  EXPECT_LT(r.amplitude_end_deg, 10.0);
}

TEST(TraceFit, LinearModelOnA30DegTraceIsFlaggedByTheAmplitudeSweep) {
  // `linear` misses the amplitude dependence of the period: fitted in successive bands, its I
  // trends with amplitude far beyond the statistical error. The trace is kept (ok, with warnings),
  // the result comes from the lowest-amplitude band, and a model-inadequacy term is added.
  const SyntheticTraceOptions truth = Truth(30.0, 21);
  const TraceFitInput in = Make(truth);
  TraceFitOptions options;
  options.model = PendulumModel::kLinear;
  const TraceFitResult r = FitTrace(in, options);
  EXPECT_EQ(r.status, TraceFitStatus::kOk) << r.BriefReport();
  EXPECT_TRUE(HasFlag(r, "amplitude_trend")) << r.BriefReport();
  EXPECT_TRUE(r.sweep.trend_detected);
  EXPECT_GT(r.sweep.trend_z, 5.0);
  EXPECT_EQ(r.inertia_source, "low_amplitude_band");
  EXPECT_GT(r.model_inadequacy_std_kg_m2, 0.0);
  ASSERT_FALSE(r.warnings.empty());
  EXPECT_NE(r.warnings[0].find("per 10 deg"), std::string::npos) << r.warnings[0];
  // The linear model's bias at the low band is covered by the uncertainty it reports.
  EXPECT_LT(std::abs(r.params.inertia_kg_m2 - truth.params.inertia_kg_m2),
            3.0 * r.inertia_std_kg_m2)
      << r.BriefReport();
  EXPECT_TRUE(AllFinite(r));
  // The same trace with the full model is clean: flat I(A), no warning.
  const TraceFitResult full = FitTrace(in, TraceFitOptions());
  EXPECT_EQ(full.status, TraceFitStatus::kOk) << full.BriefReport();
  EXPECT_TRUE(full.sweep.evaluated);
  EXPECT_FALSE(full.sweep.trend_detected) << full.BriefReport();
  EXPECT_TRUE(full.warnings.empty()) << full.BriefReport();
}

TEST(TraceFit, NloptRefinementRunsOnPoorFitsAndNeverMakesThemWorse) {
  // linear on 30 deg leaves RMS ~4x the noise, above refine_rms_over_noise = 3.
  const TraceFitInput in = Make(Truth(30.0, 22));
  TraceFitOptions options;
  options.model = PendulumModel::kLinear;
  const TraceFitResult refined = FitTrace(in, options);
  options.use_nlopt_refine = false;
  const TraceFitResult plain = FitTrace(in, options);
  EXPECT_TRUE(refined.nlopt_refined);
  EXPECT_FALSE(plain.nlopt_refined);
  EXPECT_LE(refined.final_cost, plain.final_cost * (1 + 1e-9));
  EXPECT_TRUE(AllFinite(refined));
}

TEST(TraceFit, UncertaintyBudgetMatchesExactScalingOfTheLinearModel) {
  // linear: I psi'' + K_D psi'|psi'| + C psi' + (m g D^2 / 4L) psi = 0 is unchanged when I, K_D,
  // C all scale with m g D^2 / L, so dI/dm = I/m, dI/dg = I/g, dI/dD = 2I/D, dI/dL = -I/L.
  SyntheticTraceOptions truth = Truth(10.0, 31);
  truth.model = PendulumModel::kLinear;
  const TraceFitInput in = Make(truth);
  TraceFitOptions options;
  options.model = PendulumModel::kLinear;
  options.filar_length_std_m = 0.002;
  options.filar_separation_std_m = 0.001;
  options.mass_std_kg = 0.01;
  options.gravity_std_mps2 = 0.001;
  const TraceFitResult r = FitTrace(in, options);
  ASSERT_EQ(r.status, TraceFitStatus::kOk) << r.BriefReport();
  ASSERT_EQ(r.budget.size(), 4u);
  const RigGeometry g = in.geometry;
  const double I = r.params.inertia_kg_m2;
  const double expected[4] = {-I / g.filar_length_m, 2 * I / g.filar_separation_m, I / g.mass_kg,
                              I / g.gravity_mps2};
  double sum_sq = 0.0;
  for (int i = 0; i < 4; ++i) {
    // Central difference (step 1e-4 relative, exact for a power law to ~1e-8) through the
    // implicit-function derivative: 1e-4 relative covers the Gauss-Newton approximation.
    EXPECT_NEAR(r.budget[i].d_inertia, expected[i], 1e-4 * std::abs(expected[i]))
        << r.budget[i].name;
    EXPECT_NEAR(r.budget[i].contribution_kg_m2, std::abs(expected[i]) * r.budget[i].std_input,
                1e-4 * I);
    sum_sq += r.budget[i].contribution_kg_m2 * r.budget[i].contribution_kg_m2;
  }
  EXPECT_EQ(r.budget[0].name, "filar_length");
  EXPECT_EQ(r.budget[3].name, "gravity");
  EXPECT_NEAR(r.inertia_budget_std_kg_m2, std::sqrt(sum_sq), 1e-12);
  EXPECT_NEAR(r.inertia_std_kg_m2, std::hypot(r.inertia_budget_std_kg_m2, r.inertia_stat_std_kg_m2),
              1e-12);
  EXPECT_GT(r.inertia_std_kg_m2, r.inertia_stat_std_kg_m2);
}

TEST(TraceFit, UncertaintyBudgetOfTheFullModelIsNearTheSmallAngleScaling) {
  // full at 20 deg: the rise's kinetic energy m h'^2 breaks the exact m-scaling slightly
  // (mass enters twice); the derivatives stay within 2 % of the power law.
  const TraceFitInput in = Make(Truth(20.0, 32));
  TraceFitOptions options;
  options.mass_std_kg = 0.01;
  options.filar_separation_std_m = 0.001;
  const TraceFitResult r = FitTrace(in, options);
  ASSERT_EQ(r.status, TraceFitStatus::kOk) << r.BriefReport();
  ASSERT_EQ(r.budget.size(), 2u);
  const double I = r.params.inertia_kg_m2;
  EXPECT_EQ(r.budget[0].name, "filar_separation");
  EXPECT_NEAR(r.budget[0].d_inertia, 2 * I / 0.88, 0.02 * 2 * I / 0.88);
  EXPECT_EQ(r.budget[1].name, "mass");
  EXPECT_NEAR(r.budget[1].d_inertia, I / 6.0, 0.02 * I / 6.0);
}

TEST(TraceFit, UnknownNoiseIsEstimatedFromTheWindow) {
  TraceFitInput in = Make(Truth(12.0, 41));
  const double sigma = in.noise_rad_per_s;
  in.noise_rad_per_s = 0.0;
  const TraceFitResult r = FitTrace(in, TraceFitOptions());
  ASSERT_EQ(r.status, TraceFitStatus::kOk) << r.BriefReport();
  EXPECT_FALSE(r.noise_from_input);
  // Median-based scale of ~6000 second differences: ~2 % sampling error, plus < 1 % curvature.
  EXPECT_NEAR(r.noise_rad_per_s, sigma, 0.05 * sigma);
  EXPECT_NEAR(r.rms_over_noise, 1.0, 0.08);
}

TEST(TraceFit, RestNoiseBelowTheMotionNoiseIsAWarning) {
  TraceFitInput in = Make(Truth(12.0, 42));
  in.noise_rad_per_s *= 0.25;  // the rest segment was quieter: RMS is 4x "the noise"
  const TraceFitResult r = FitTrace(in, TraceFitOptions());
  EXPECT_EQ(r.status, TraceFitStatus::kOk) << r.BriefReport();
  EXPECT_TRUE(HasFlag(r, "rms_above_noise")) << r.BriefReport();
  ASSERT_EQ(r.warnings.size(), 1u);
  EXPECT_NE(r.warnings[0].find("noise"), std::string::npos);
}

TEST(TraceFit, SecondaryMotionAndAmplitudeBandAreChecked) {
  TraceFitInput in = Make(Truth(30.0, 43));
  in.secondary_motion_ratio = 0.6;  // heavy: above reject_secondary_motion_ratio (0.5)
  TraceFitResult r = FitTrace(in, TraceFitOptions());
  EXPECT_EQ(r.status, TraceFitStatus::kRejected);
  EXPECT_TRUE(HasFlag(r, "secondary_motion"));
  // A rejected trace still reports its fitted number and says what to change.
  EXPECT_TRUE(r.HasFit());
  EXPECT_GT(r.params.inertia_kg_m2, 0.0);
  EXPECT_NE(r.message.find("max 0.500"), std::string::npos) << r.message;
  EXPECT_NE(r.message.find("imu.swing_axis"), std::string::npos) << r.message;
  in.secondary_motion_ratio = 0.2;  // moderate: a warning
  r = FitTrace(in, TraceFitOptions());
  EXPECT_EQ(r.status, TraceFitStatus::kOk) << r.BriefReport();
  EXPECT_TRUE(HasFlag(r, "secondary_motion"));
  in.secondary_motion_ratio = 0.01;
  r = FitTrace(in, TraceFitOptions());
  EXPECT_EQ(r.status, TraceFitStatus::kOk) << r.BriefReport();
  EXPECT_TRUE(r.warnings.empty()) << r.BriefReport();
  TraceFitOptions band;
  band.max_amplitude_deg = 20.0;  // the window code should have trimmed this trace
  r = FitTrace(in, band);
  EXPECT_EQ(r.status, TraceFitStatus::kOk);
  EXPECT_TRUE(HasFlag(r, "amplitude_above_band"));
  band.max_amplitude_deg = 45.0;
  band.min_amplitude_deg = 28.0;  // decays to ~26 deg: below the band at the end
  r = FitTrace(in, band);
  EXPECT_TRUE(HasFlag(r, "amplitude_below_band")) << r.BriefReport();
}

TEST(TraceFit, CvodesAndRungeKuttaGiveTheSameInertia) {
  const TraceFitInput in = Make(Truth(25.0, 51));
  TraceFitOptions rk;
  TraceFitOptions cv;
  cv.integrator.method = IntegratorMethod::kCvodes;
  TraceFitOptions tight;
  tight.integrator.rel_tol = 1e-11;
  tight.integrator.abs_tol = 1e-13;
  const TraceFitResult a = FitTrace(in, rk), b = FitTrace(in, cv), c = FitTrace(in, tight);
  ASSERT_TRUE(a.IsUsable() && b.IsUsable() && c.IsUsable());
  // Integration error at the default tolerance moves I by far less than its std (~1e-5 of I).
  EXPECT_NEAR(a.params.inertia_kg_m2, c.params.inertia_kg_m2, 1e-6 * c.params.inertia_kg_m2);
  EXPECT_NEAR(b.params.inertia_kg_m2, c.params.inertia_kg_m2, 1e-6 * c.params.inertia_kg_m2);
}

TEST(TracePlot, WritesPngAndSvgAndRefusesAnEmptyResult) {
  const TraceFitResult r = FitTrace(Make(Truth(20.0, 81)), TraceFitOptions());
  ASSERT_TRUE(r.IsUsable());
  const std::filesystem::path dir =
      std::filesystem::temp_directory_path() / ("bifilar_trace_plot_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  TracePlotOptions options;
  options.title = "synthetic.csv";
  for (const char* ext : {".png", ".svg"}) {
    const std::string path = (dir / (std::string("trace") + ext)).string();
    std::string why;
    ASSERT_TRUE(WriteTraceFitFigure(r, path, options, &why)) << why;
    EXPECT_GT(std::filesystem::file_size(path), 10000u) << path;
  }
  std::string why;
  EXPECT_FALSE(WriteTraceFitFigure(TraceFitResult(), (dir / "empty.png").string(), options, &why));
  EXPECT_NE(why.find("no fitted series"), std::string::npos);
  EXPECT_FALSE(std::filesystem::exists(dir / "empty.png"));
  std::filesystem::remove_all(dir);
}

// --- Bad input ---------------------------------------------------------------------------------

TraceFitInput Clean() { return Make(Truth(15.0, 61)); }

void ExpectStatus(const TraceFitInput& in, TraceFitStatus status, const std::string& needle) {
  const TraceFitResult r = FitTrace(in, TraceFitOptions());
  EXPECT_EQ(r.status, status) << r.BriefReport();
  EXPECT_NE(r.message.find(needle), std::string::npos) << r.message;
  EXPECT_NE(r.message.find("synthetic.csv"), std::string::npos) << r.message;
  EXPECT_FALSE(r.IsUsable());
  EXPECT_TRUE(AllFinite(r));
  EXPECT_FALSE(r.BriefReport().empty());
}

TEST(TraceFitBadInput, Empty) {
  TraceFitInput in = Clean();
  in.t_s.clear();
  in.rate_rad_per_s.clear();
  ExpectStatus(in, TraceFitStatus::kError, "empty");
}

TEST(TraceFitBadInput, SizeMismatch) {
  TraceFitInput in = Clean();
  in.rate_rad_per_s.pop_back();
  ExpectStatus(in, TraceFitStatus::kError, "differ in length");
}

TEST(TraceFitBadInput, NanAndInf) {
  TraceFitInput in = Clean();
  in.rate_rad_per_s[100] = std::nan("");
  ExpectStatus(in, TraceFitStatus::kError, "NaN");
  in = Clean();
  in.t_s[200] = HUGE_VAL;
  ExpectStatus(in, TraceFitStatus::kError, "sample 200");
}

TEST(TraceFitBadInput, NonIncreasingTimestamps) {
  TraceFitInput in = Clean();
  in.t_s[300] = in.t_s[299];
  ExpectStatus(in, TraceFitStatus::kError, "strictly increasing");
}

TEST(TraceFitBadInput, ShorterThanTwoPeriods) {
  SyntheticTraceOptions truth = Truth(15.0, 62);
  truth.duration_s = 4.0;  // period ~2.8 s: 1.4 periods
  TraceFitInput in = Make(truth);
  ExpectStatus(in, TraceFitStatus::kRejected, "periods");
}

TEST(TraceFitBadInput, ConstantData) {
  TraceFitInput in = Clean();
  std::fill(in.rate_rad_per_s.begin(), in.rate_rad_per_s.end(), 0.01);
  ExpectStatus(in, TraceFitStatus::kRejected, "constant");
}

TEST(TraceFitBadInput, NoOscillation) {
  // Pure noise (amplitude 0 at rest).
  SyntheticTraceOptions truth = Truth(0.0, 63);
  TraceFitInput in = Make(truth);
  ExpectStatus(in, TraceFitStatus::kRejected, "no oscillation");
  // A slow drift with noise on top: no zero crossings of an oscillation.
  in = Clean();
  for (size_t k = 0; k < in.t_s.size(); ++k)
    in.rate_rad_per_s[k] = 0.5 * in.t_s[k] / in.t_s.back() + 0.004 * std::sin(37.0 * k);
  const TraceFitResult r = FitTrace(in, TraceFitOptions());
  EXPECT_EQ(r.status, TraceFitStatus::kRejected) << r.BriefReport();
  EXPECT_TRUE(AllFinite(r));
}

TEST(TraceFitBadInput, TooFewSamples) {
  TraceFitInput in = Clean();
  in.t_s.resize(5);
  in.rate_rad_per_s.resize(5);
  ExpectStatus(in, TraceFitStatus::kRejected, "too few samples");
}

TEST(TraceFitBadInput, BadGeometryAndOptions) {
  TraceFitInput in = Clean();
  in.geometry.filar_length_m = -1.0;
  ExpectStatus(in, TraceFitStatus::kError, "geometry");
  in = Clean();
  TraceFitOptions options;
  options.max_rms_over_noise = 0.5;
  const TraceFitResult r = FitTrace(in, options);
  EXPECT_EQ(r.status, TraceFitStatus::kError);
  EXPECT_NE(r.message.find("max_rms_over_noise"), std::string::npos);
  std::string why;
  EXPECT_TRUE(TraceFitOptions().Check(&why)) << why;
  options = TraceFitOptions();
  options.mass_std_kg = std::nan("");
  EXPECT_FALSE(options.Check(&why));
}

TEST(TraceGuess, SampleNoiseOfPureNoiseIsItsSigma) {
  SyntheticTraceOptions truth = Truth(0.0, 71);
  const TraceFitInput in = Make(truth);
  // Median-based robust scale over ~6000 samples: 2.5 % covers ~2 sd of its sampling error.
  EXPECT_NEAR(EstimateSampleNoise(in.t_s, in.rate_rad_per_s), in.noise_rad_per_s,
              0.025 * in.noise_rad_per_s);
}

}  // namespace
}  // namespace bifilar

namespace bifilar {
namespace {

TEST(TraceFit, GyroScaleBudgetPredictsTheShiftOfAScaledGyro) {
  // A gyro reading (1 + e) times the true rate moves the fitted amplitude by e and so the
  // amplitude correction of the period: I shifts by about -A^2 e / 4. The budget's dI/de must
  // predict the actual shift of a refit on the scaled data (first order: to a few percent).
  constexpr double kScaleError = 0.01;
  const TraceFitInput in = Make(Truth(30.0, 51));
  TraceFitOptions options;
  options.gyro_scale_std = kScaleError;
  const TraceFitResult base = FitTrace(in, options);
  ASSERT_EQ(base.status, TraceFitStatus::kOk) << base.BriefReport();
  ASSERT_EQ(base.budget.size(), 1u);
  EXPECT_EQ(base.budget[0].name, "gyro_scale");

  TraceFitInput scaled = in;
  for (double& w : scaled.rate_rad_per_s) w *= 1.0 + kScaleError;
  scaled.noise_rad_per_s *= 1.0 + kScaleError;
  const TraceFitResult moved = FitTrace(scaled, options);
  ASSERT_EQ(moved.status, TraceFitStatus::kOk) << moved.BriefReport();
  const double actual = moved.params.inertia_kg_m2 - base.params.inertia_kg_m2;
  const double predicted = base.budget[0].d_inertia * kScaleError;
  EXPECT_NEAR(predicted, actual, 0.05 * std::abs(actual));
  // Order of magnitude from the small-amplitude expansion, -A^2 e / 4 (A in rad).
  const double a = 30.0 * kRadPerDeg;
  const double rough = -a * a * kScaleError / 4.0 * base.params.inertia_kg_m2;
  EXPECT_NEAR(actual, rough, 0.5 * std::abs(rough));
  EXPECT_NEAR(base.budget[0].contribution_kg_m2, std::abs(predicted), 1e-15);
}

}  // namespace
}  // namespace bifilar

// The trace fit: one free-oscillation window of swing rate in, the suspended moment of inertia
// with an honest uncertainty out. Model, signs and units: docs/physics.md §2.
//
// Observation model fitted to every sample k of the window (real, possibly jittered timestamps):
//
//   r_k = psi'(t_k; I, K_D, C, psi(t0), psi'(t0)) + b - omega_meas(t_k)
//
// psi' from the chosen pendulum model (pendulum/model.h) integrated with forward sensitivities
// (pendulum/integrator.h: DOP853 by default, or CVODES), which give the analytic Jacobian. Solver:
// Ceres Levenberg-Marquardt from an initial guess computed from the data alone (fit/trace_guess.h);
// NLopt refines I in one dimension only when that first fit is poor. The solvers stay inside
// fit/: nothing here exposes a Ceres or NLopt type.
#pragma once

#include <atomic>
#include <cmath>
#include <string>
#include <vector>

#include "fit/trace_input.h"
#include "fit/trace_options.h"
#include "pendulum/integrator.h"
#include "pendulum/model.h"

namespace bifilar {

// The fit's options: the solver's, the quality thresholds and the amplitude sweep (the two bases,
// fit/trace_options.h: one struct per concept, each with its table and Check), the amplitude
// band and the uncertainty budget. Bases rather than members `quality` and `sweep`, so that the
// fit's code reads `options.sweep_trend_z` as before; the config holds the same two structs.
struct TraceFitOptions : TraceQualityOptions, AmplitudeSweepOptions {
  PendulumModel model = PendulumModel::kFull;  // Equation of motion fitted (default: full).
  // Integrator inside the fit: the integrator's default method (DOP853 with forward
  // sensitivities; kCvodes gives the same answer ~10x slower) at rel_tol 1e-8, abs_tol 1e-10.
  // The integration error of the rate is then ~1e-8 rad/s, five orders below 0.25 deg/s gyro
  // noise, and moves I by < 1e-7 relative (tests/fit_trace_fit_test.cc compares with 1e-11).
  IntegratorOptions integrator = DefaultIntegrator();
  int max_iterations = 50;  // Levenberg-Marquardt iterations per solve (count); > 0.
  // Bounds of one FitTrace call, over all its solves (the window fit with its active-set rounds
  // and retry, the NLopt refinement, the amplitude-sweep bands). They count work, never time, so
  // the same log gives the same result on any machine, however slow or busy: at most
  // max_total_iterations Levenberg-Marquardt iterations and max_integrator_steps internal steps
  // of the integrator (summed over every integration of the window the solvers ask for; each
  // integration is itself bounded by integrator.max_steps, and the window by 65536 points,
  // fit/block_mean.h). A fit stopped by either is rejected with flag `solver_bound` and the
  // message "the solver was stopped after N iterations and S integrator steps (bounds: ...)".
  // Fits of real and simulated logs take < 100 iterations and < 1e6 steps, so neither bound
  // changes a normal result; they stop a window that does not hold a free swing, which can
  // otherwise drift for minutes.
  int max_total_iterations = 500;        // (count) >= 1
  long max_integrator_steps = 20000000;  // (count) >= 1
  // Last resort only, far above any real fit (< 1 s): CPU time of the calling thread after which
  // the fit is abandoned. Its outcome depends on the machine's speed, so it is not a judgement of
  // the data: status kError, flag `time_guard`, a message of its own ("abandoned by the time
  // guard ..."), and such a record is never cached (pipeline/store/cache.cc).
  double time_guard_cpu_seconds = 600.0;  // (s) > 0
  // Set (by Ctrl-C, for example) to stop the fit between solver iterations: the result is then
  // kError with `interrupted` true. Not owned; nullptr: never interrupted.
  const std::atomic<bool>* interrupt = nullptr;

  // The quality thresholds (TraceQualityOptions: max_rms_over_noise, ..., min_periods) and the
  // amplitude sweep (AmplitudeSweepOptions: amplitude_sweep, sweep_*) are the bases of this
  // struct, declared once in fit/trace_options.h with their table, which the config reads.
  // Amplitude band of the fitted part (deg). The window code trims the trace to the band; here
  // the fitted amplitude is checked against it: start <= max + 1 deg and end >= min - 0.5 deg.
  double max_amplitude_deg = 90.0;  // > min_amplitude_deg, <= 90.
  double min_amplitude_deg = 0.5;   // >= 0.
  // What the log holds beyond the fitted window (the caller's knowledge, for the advice the
  // warnings give): false when the window already runs to the end of the free swing, so that a
  // damping term at its bound is not answered with "fit a longer window" (issue 32).
  bool longer_window_available = true;

  // NLopt one-dimensional global refinement of I when the first fit is poor (residual RMS above
  // refine_rms_over_noise times the noise), then Levenberg-Marquardt again.
  bool use_nlopt_refine = true;
  double refine_rms_over_noise = 3.0;  // (dimensionless) > 1.

  // Uncertainty budget: 1-sigma uncertainties of the configured geometry, each propagated to I
  // to first order (implicit-function derivative of the fitted I). 0 = exact.
  double filar_length_std_m = 0.0;
  double filar_separation_std_m = 0.0;
  double mass_std_kg = 0.0;
  double gravity_std_mps2 = 0.0;
  // 1-sigma gyro scale-factor uncertainty (fraction, e.g. 0.005 = 0.5 %); >= 0. I comes from the
  // frequency, but the amplitude read from the rate sets the nonlinear period correction, so a
  // scale error e moves I by about -A^2 e / 4 at amplitude A (rad).
  double gyro_scale_std = 0.0;

  // Keep the fitted and residual series in the result (needed by the figure); costs 2N doubles.
  bool keep_series = true;

  static IntegratorOptions DefaultIntegrator() {
    IntegratorOptions o;
    o.rel_tol = 1e-8;
    o.abs_tol = 1e-10;
    return o;
  }

  // Every bound: the solver's, the bases' Checks (their tables), the band, the budget.
  bool Check(std::string* why) const;
};

// One line of the uncertainty budget: how an input's uncertainty moves I.
struct UncertaintyContribution {
  std::string name;                 // "filar_length", "filar_separation", "mass", "gravity"
  double std_input = 0.0;           // configured 1-sigma of the input (m, m, kg, m/s^2)
  double d_inertia = 0.0;           // dI / d(input) at the solution (kg m^2 per input unit)
  double contribution_kg_m2 = 0.0;  // |dI/dq| * std_input
};

// One band of the amplitude sweep.
struct AmplitudeSweepBand {
  double t0_s = 0.0, t1_s = 0.0;  // band limits (s, the log's own time)
  int num_samples = 0;
  double cycles = 0.0;               // periods in the band
  double amplitude_start_deg = 0.0;  // fitted |psi| peak over the band's first period
  double amplitude_end_deg = 0.0;    // ... and its last period
  double amplitude_mean_deg = 0.0;   // their mean: the band's amplitude
  double inertia_kg_m2 = 0.0;        // I fitted in the band (K_D, C held)
  double inertia_std_kg_m2 = 0.0;    // its statistical (HAC) std
  double residual_fraction = 0.0;    // residual RMS / swing-rate RMS of the band fit
  // The band fit's state at t0_s and its gyro bias (K_D and C are the window fit's): what the
  // fit figure needs to draw the band's curve (TraceFitResult::band_fitted_rate_rad_per_s).
  double angle0_rad = 0.0;       // psi(t0_s)
  double rate0_rad_per_s = 0.0;  // psi'(t0_s)
  double bias_rad_per_s = 0.0;   // b
  bool ok = false;               // the band fit converged
};

// I against amplitude, and the trend test (docs/method.md, "Amplitude sweep").
struct AmplitudeSweep {
  bool evaluated = false;  // false: too few cycles for two bands (note says why)
  std::string note;
  std::vector<AmplitudeSweepBand> bands;  // in time order (amplitude decreasing)
  // The trend over the bands (fit/amplitude_trend.h, FitAmplitudeShape): the weighted curve
  // I_j = I_0 (1 + c A_j^p) with p in {1, 2} chosen by the data (lowest chi^2); c (per deg^p)
  // with its std scaled by the Birge ratio of the bands about that curve, z = c / std.
  double trend_exponent = 2.0;  // p
  double trend_coeff = 0.0;     // c (per deg^p), relative to I_0
  double trend_coeff_std = 0.0;
  double trend_z = 0.0;
  double trend_chi2 = 0.0;   // chi^2 of the bands about the curve, their own stds
  int trend_dof = 0;         // bands - 2
  double trend_scale = 1.0;  // Birge ratio about the curve: sqrt(chi2/dof) when > 1, else 1
  // Mean relative slope of I over the swept amplitudes (% per 10 deg).
  double trend_percent_per_10deg = 0.0;
  double inertia_zero_amplitude_kg_m2 = 0.0;  // I_0, the trend extrapolated to zero amplitude
  bool trend_detected = false;                // |z| > sweep_trend_z
  // The trend curve at amplitude a (deg); 0 when the sweep was not evaluated.
  double TrendAt(double a_deg) const {
    return inertia_zero_amplitude_kg_m2 *
           (1.0 + trend_coeff * std::pow(std::abs(a_deg), trend_exponent));
  }
  int low_band = -1;  // index in `bands` of the fitted band with the lowest amplitude (-1: none)
  // Consistency of the bands with one constant I: chi^2 about their weighted mean, its degrees of
  // freedom, and the scale applied to the statistical std (sqrt(chi^2/dof) when chi^2 exceeds
  // its degrees of freedom, else 1: the Birge ratio as the Particle Data Group applies it):
  // segments of the same swing that disagree beyond their stds show the real error of the fit
  // (unmodelled motion, coloured disturbances). With a trend the scale is the trend's
  // (trend_scale): the bands' scatter about the curve, not about a constant, which would count the
  // trend a second time.
  double chi2_constant = 0.0;
  // The bands scatter beyond their stds at 5 %: about the constant, or about the trend curve
  // when a trend was detected.
  bool bands_disagree = false;
  int chi2_dof = 0;
  double std_scale = 1.0;
};

enum class TraceFitStatus { kOk, kRejected, kError };
const char* ToString(TraceFitStatus status);  // "ok", "rejected", "error"

struct TraceFitResult {
  TraceFitStatus status = TraceFitStatus::kError;
  std::string message;                // why rejected / error; "" when ok (warnings are separate)
  std::vector<std::string> flags;     // every quality check raised, short machine-readable names
  std::vector<std::string> warnings;  // one sentence per warning, for every status
  PendulumModel model = PendulumModel::kFull;

  PendulumParams params;           // fitted I, K_D, C
  double angle0_rad = 0.0;         // fitted psi(t0)
  double rate0_rad_per_s = 0.0;    // fitted psi'(t0)
  double bias_rad_per_s = 0.0;     // fitted gyro bias b
  double drag_coeff_std = 0.0;     // statistical std of K_D (kg m^2)
  double viscous_coeff_std = 0.0;  // statistical std of C (kg m^2/s)

  // Uncertainty of I: statistical (HAC sandwich covariance, robust to coloured residuals), the
  // model-inadequacy term of the amplitude sweep (0 without a trend), the geometry budget, and
  // all combined in quadrature. params.inertia_kg_m2 is the window fit's I, or the
  // lowest-amplitude band's when the sweep found a trend (inertia_source says which).
  double inertia_stat_std_kg_m2 = 0.0;
  double inertia_iid_std_kg_m2 = 0.0;  // textbook sigma^2 (J^T J)^-1 std (white residuals)
  int hac_bandwidth = 0;               // Bartlett bandwidth of the HAC covariance (lags)
  double model_inadequacy_std_kg_m2 = 0.0;
  std::vector<UncertaintyContribution> budget;
  double inertia_budget_std_kg_m2 = 0.0;  // root-sum-square of the budget contributions
  double inertia_std_kg_m2 = 0.0;         // sqrt(stat^2 + inadequacy^2 + budget^2)
  double inertia_window_kg_m2 = 0.0;      // I of the fit over the whole window
  std::string inertia_source = "window";  // "window" or "low_amplitude_band"
  AmplitudeSweep sweep;

  // Goodness of fit.
  int num_samples = 0;
  double residual_rms_rad_per_s = 0.0;
  double noise_rad_per_s = 0.0;   // noise used for the RMS check (input or data estimate)
  bool noise_from_input = false;  // true: rest-segment noise; false: from the window
  double rms_over_noise = 0.0;
  double signal_rms_rad_per_s = 0.0;      // RMS of the fitted swing rate about the bias
  double residual_autocorr_lag1 = 0.0;    // rho_1 of the residuals
  double residual_autocorr_max = 0.0;     // max |rho_k|, k = 1..whiteness_lags
  double residual_ar1_phi = 0.0;          // AR(1) coefficient of the residuals
  double prewhitened_autocorr_max = 0.0;  // max |rho_k| after AR(1) prewhitening (the check)
  double ljung_box_q = 0.0;               // Ljung-Box Q of the prewhitened residuals (h dof)
  double amplitude_start_deg = 0.0;       // fitted |psi| peak over the first period
  double amplitude_end_deg = 0.0;         // fitted |psi| peak over the last period
  double period_s = 0.0;                  // mean period (guess stage)

  // Solver summary.
  int iterations = 0;
  double initial_cost = 0.0;  // 1/2 sum r^2 at the initial guess (rad^2/s^2)
  double final_cost = 0.0;
  bool nlopt_refined = false;  // NLopt refinement of I was run
  bool interrupted = false;    // stopped by TraceFitOptions::interrupt (status kError)
  bool solver_bound = false;   // stopped by max_total_iterations or max_integrator_steps
  bool time_guard = false;     // abandoned by time_guard_cpu_seconds (status kError)
  long integrator_steps =
      0;  // integrator steps the solvers spent (what max_integrator_steps counts)
  double fit_seconds = 0.0;  // wall time of FitTrace
  TraceInitialGuess guess;

  // Series for plotting (empty unless options.keep_series): the window's times, the measured
  // rate, the fitted rate psi'(t_k) + b and the residual fitted - measured (the fit's own sign;
  // the figures and Python's residual_rad_per_s show its negative, measured - fitted).
  std::vector<double> t_s;
  std::vector<double> measured_rate_rad_per_s;
  std::vector<double> fitted_rate_rad_per_s;
  std::vector<double> residual_rad_per_s;
  // The fit that gave params.inertia_kg_m2 when it is a band's (inertia_source
  // "low_amplitude_band", kept with the series): its fitted rate psi'(t_k) + b at the samples
  // t_s[band_first_index], t_s[band_first_index + 1], ... of the window. Empty otherwise; the
  // series above are then the result's fit.
  size_t band_first_index = 0;
  std::vector<double> band_fitted_rate_rad_per_s;

  bool IsUsable() const { return status == TraceFitStatus::kOk; }
  bool HasFit() const { return status != TraceFitStatus::kError && params.inertia_kg_m2 > 0.0; }
  // One line: status, I +- std, K_D, C, rms/noise, iterations, time (and message when not ok).
  std::string BriefReport() const;
};

// Fits one window. Never throws on bad data and never returns NaN: invalid input (sizes, NaN,
// non-increasing times, bad geometry or options) gives kError; data that cannot support a fit
// (too short, constant, no oscillation) or a failed quality check gives kRejected.
TraceFitResult FitTrace(const TraceFitInput& input, const TraceFitOptions& options);

}  // namespace bifilar

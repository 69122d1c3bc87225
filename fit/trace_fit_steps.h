// The steps of FitTrace (fit/trace_fit.h) and the data passed between them. Private to fit/: the
// public header stays solver-free, this one speaks Eigen and fit/trace_cost.h's scaled parameters
// p = (I / I_guess, K_D / I_guess, C / I_guess, psi(t0), psi'(t0), b).
//
// The procedure (FitTrace in fit/trace_fit.cc), one function per step:
//   ValidateTraceFit        options, geometry, sizes, finite values, increasing times
//   (trace_fit.cc) EstimateTraceGuess      initial guess from the data alone (trace_guess.cc)
//   MinimizeLm              Levenberg-Marquardt with an active set for K_D, C >= 0, one retry
//                           from K_D = C = 0                                    (trace_solve.cc)
//   RefineInertia           NLopt global search along I, then LM again, when the first fit is
//                           poor (NeedsRefinement)                              (trace_solve.cc)
//   MakeSolution            the parameters, residual RMS, fitted trajectory and amplitude
//                                                                               (trace_fit.cc)
//   EstimateStatisticalStd  HAC sandwich covariance over the free parameters (trace_uncertainty.cc)
//   ComputeInputBudget      geometry and gyro-scale uncertainties to I by the implicit-function
//                           derivative                                     (trace_uncertainty.cc)
//   RunAmplitudeSweep       I refitted in equal-cycle bands, trend of I against A^p
//   (trace_sweep.cc) ApplySweepRule          trend -> low-amplitude band + model inadequacy; Birge
//   scale
//                                                                               (trace_sweep.cc)
//   ComputeWhiteness        residual whiteness against their own AR(1) noise (residual_stats.cc)
//   JudgeQuality            reasons to reject, and warnings                    (trace_quality.cc)
//   AssembleResult          the public result, non-finite guard, kept series   (trace_fit.cc)
// Each step reads the outputs of the earlier ones and writes only its own struct; flags and
// warnings are collected per step and joined in this order.
#pragma once

#include "base/text_format.h"  // Fmt, a number for a message
#include "base/units.h"
#include "fit/trace_fit.h"

#include <array>
#include <cmath>
#include <cstddef>
#include <string>
#include <utility>
#include <vector>

#include "fit/residual_stats.h"
#include "fit/trace_cost.h"

namespace bifilar {
namespace trace {

// Scaled parameters, indexed by TraceParamIndex (fit/trace_cost.h).
using Params = std::array<double, kNumTraceParams>;

// Flags (short machine-readable names) and warnings (one sentence each) raised by a step.
struct Findings {
  std::vector<std::string> flags;
  std::vector<std::string> warnings;
  void Warn(const char* flag, const std::string& why) {
    flags.push_back(flag);
    warnings.push_back(why);
  }
};

// --- The fitted trajectory (trace_fit.cc).

// RMS of v about its mean (0 for an empty v).
double RmsAboutMean(const std::vector<double>& v);

// Peak |psi| (deg) over the first and the last period of a trajectory sampled at t.
std::pair<double, double> AmplitudeAtEnds(const std::vector<double>& t, const Trajectory& traj,
                                          double period_s);

// Residual RMS of a cost 1/2 sum r^2 over n samples.
inline double RmsOfCost(double cost, size_t n) { return std::sqrt(2.0 * cost / n); }

// --- Step 1: validation (trace_fit.cc).

// False with *why (the error message) when the options, the geometry or the window are invalid.
bool ValidateTraceFit(const TraceFitInput& input, const TraceFitOptions& options, std::string* why);

// --- The bounds of one fit (trace_solve.cc).

// What every solver step of one FitTrace may spend, counted in work so that a result never
// depends on the machine's speed: Levenberg-Marquardt iterations over all its solves
// (TraceFitOptions::max_total_iterations) and internal integrator steps over all the
// integrations the solvers ask for (max_integrator_steps). Besides, a last-resort time guard
// (time_guard_cpu_seconds of CPU time of the calling thread, far above any real fit) and the
// caller's interrupt flag. Checked between solver iterations, before each cost evaluation of a
// solve and each NLopt evaluation; once exhausted it stays so and every later solve returns at
// once (not ok).
class SolveBudget {
 public:
  enum class Stop { kNone, kIterations, kSteps, kTimeGuard, kInterrupted };
  explicit SolveBudget(const TraceFitOptions& options);
  // Counts one solver iteration.
  void CountIteration() { ++iterations_; }
  // Counts the internal steps of one integration.
  void CountSteps(long steps) { integrator_steps_ += steps; }
  // True (and stays true) once a bound is reached or the interrupt flag is set.
  bool Exhausted();
  Stop stop() const { return stop_; }
  int iterations() const { return iterations_; }
  long integrator_steps() const { return integrator_steps_; }
  double cpu_seconds() const;
  // "the solver was stopped after 500 iterations and 1234 integrator steps (bounds: ...)",
  // "abandoned by the time guard ...", "interrupted ...".
  std::string Message() const;

 private:
  const TraceFitOptions& options_;
  double start_cpu_s_ = 0.0;
  int iterations_ = 0;
  long integrator_steps_ = 0;
  Stop stop_ = Stop::kNone;
};

// --- Steps 3-4: the minimisation (trace_solve.cc).

// 1/2 sum r^2 at p, the residuals in *r (sized N); HUGE_VAL when the integration fails.
double Cost(const TraceRateCost& cost, const double* p, std::vector<double>* r);

// One Levenberg-Marquardt solve (or a sequence of them over the active set).
struct SolveOutcome {
  bool ok = false;
  std::string message;
  int iterations = 0;
  double initial_cost = 0.0;
  double final_cost = 0.0;
  bool converged = false;
  bool stopped_at_bound = false;  // a free damping coefficient reached 0
};

// Levenberg-Marquardt on p (in place), K_D and C held where fixed[0], fixed[1]; with
// stop_at_bound, ends when a free damping coefficient lands on 0.
SolveOutcome SolveLm(const TraceRateCost& cost, int max_iterations, const bool fixed[2],
                     bool stop_at_bound, double* p, SolveBudget* budget);

// The start of the minimisation: the initial guess, I scaled to 1.
Params StartFromGuess(const TraceInitialGuess& guess);

struct Minimum {
  Params p{};                      // the solution, scaled
  bool fixed[2] = {false, false};  // active set: K_D, C held at 0
  SolveOutcome lm;                 // the accepted solve (its convergence is judged)
  int iterations = 0;              // LM iterations, refinement included
  double initial_cost = 0.0;       // 1/2 sum r^2 at the start (rad^2/s^2)
  double final_cost = 0.0;
  std::vector<double> residuals;  // fitted - measured at p (rad/s)
  bool nlopt_refined = false;     // RefineInertia ran
};

// Levenberg-Marquardt with the active set from `start`; when it fails, once more from `start`
// with K_D = C = 0 (a bad damping guess can make the first integration fail). lm.ok false:
// both failed, lm.message says why.
Minimum MinimizeLm(const TraceRateCost& cost, const Params& start, int max_iterations,
                   SolveBudget* budget);

// The first fit is poor: residual RMS above options.refine_rms_over_noise times the noise.
bool NeedsRefinement(const Minimum& minimum, double noise_rad_per_s,
                     const TraceFitOptions& options);

// NLopt DIRECT-L along I over +-10 % of the guess (other parameters at `start`), then
// Levenberg-Marquardt from there; *minimum takes the result when its cost is lower.
void RefineInertia(const TraceRateCost& cost, const Params& start, int max_iterations,
                   Minimum* minimum, SolveBudget* budget);

// --- Step 5: the solution (trace_fit.cc).

struct Solution {
  PendulumParams params;  // unscaled I, K_D, C
  double angle0_rad = 0.0;
  double rate0_rad_per_s = 0.0;
  double bias_rad_per_s = 0.0;
  double residual_rms_rad_per_s = 0.0;
  double rms_over_noise = 0.0;        // 0 when the noise is unknown
  Trajectory trajectory;              // fitted psi, psi' (and sensitivities) at the samples
  double amplitude_start_deg = 0.0;   // fitted |psi| peak over the first period
  double amplitude_end_deg = 0.0;     // ... and the last
  double signal_rms_rad_per_s = 0.0;  // RMS of the fitted psi' about its mean
};

// Reads the solution off the minimum; the cost's cache must sit at minimum.p.
Solution MakeSolution(const TraceFitInput& input, const TraceRateCost& cost, const Minimum& minimum,
                      double period_s, double noise_rad_per_s);

// --- Steps 6-7: uncertainty (trace_uncertainty.cc).

// HAC and iid stds of the free parameters `free` (scaled units), HAC bandwidth from the
// residuals' AR(1) coefficient.
struct FreeParamStd {
  bool ok = false;
  std::vector<double> hac;  // per free parameter (scaled units)
  std::vector<double> iid;
  int bandwidth = 0;
};
FreeParamStd StatisticalStd(const TraceRateCost& cost, const double* p,
                            const std::vector<int>& free);

struct StatisticalUncertainty {
  double inertia_std_kg_m2 = 0.0;      // HAC
  double inertia_iid_std_kg_m2 = 0.0;  // sigma^2 (J^T J)^-1
  int hac_bandwidth = 0;
  double drag_coeff_std = 0.0;     // 0 when K_D is held
  double viscous_coeff_std = 0.0;  // 0 when C is held
  Findings findings;               // covariance_failed
};

// Over I, the free damping coefficients, psi(t0), psi'(t0) and b.
StatisticalUncertainty EstimateStatisticalStd(const TraceRateCost& cost, const Minimum& minimum);

struct InputBudget {
  std::vector<UncertaintyContribution> contributions;
  double inertia_std_kg_m2 = 0.0;  // root-sum-square of the contributions
  Findings findings;               // budget_failed_<input>
};

// Each configured 1-sigma input uncertainty (geometry, gyro scale) moved to I to first order.
// Empty when none is configured.
InputBudget ComputeInputBudget(const TraceFitInput& input, const TraceFitOptions& options,
                               const TraceRateCost& cost, const Minimum& minimum,
                               const Solution& solution);

// --- Step 8: the amplitude sweep and its rule (trace_sweep.cc).

// I refitted in successive equal-cycle bands of the window, from the window fit's state at each
// band's first sample, K_D and C held at the window fit; then the trend of I against A^p.
AmplitudeSweep RunAmplitudeSweep(const TraceFitInput& input, const TraceFitOptions& options,
                                 const double* p, double scale, const Trajectory& traj,
                                 double period_s, SolveBudget* budget);

// The fitted rate psi' + b of `band` (a band of the sweep, at its own state and I, K_D and C of
// the window fit p) at its samples, which start at input.t_s[*first]; empty when the band is not
// in the window or its integration fails.
std::vector<double> BandFittedRate(const TraceFitInput& input, const TraceFitOptions& options,
                                   const double* p, double scale, const AmplitudeSweepBand& band,
                                   size_t* first);

// I and its statistical std after the sweep's rule.
struct SweepRule {
  double inertia_kg_m2 = 0.0;
  double inertia_stat_std_kg_m2 = 0.0;
  double model_inadequacy_std_kg_m2 = 0.0;
  std::string inertia_source = "window";
  Findings findings;  // bands_disagree, amplitude_trend
};

// The statistical std scaled by the Birge ratio when the bands scatter; on a trend, I from the
// lowest-amplitude band with the trend's bias left there as the model-inadequacy term.
SweepRule ApplySweepRule(const AmplitudeSweep& sweep, const Solution& solution,
                         const StatisticalUncertainty& stat, const TraceFitOptions& options);

// The action against an I that depends on the amplitude, for the options in force: "swing lower,
// or set fit.max_amplitude_deg (--max-amplitude)", or, when a band is set already (below 90
// deg), "swing lower, or lower fit.max_amplitude_deg (--max-amplitude, now 15 deg)".
std::string AmplitudeAction(const TraceFitOptions& options);

// --- Step 10: quality (trace_quality.cc).

struct Quality {
  std::vector<std::string> reasons;  // to reject; empty: ok
  Findings findings;
};

Quality JudgeQuality(const TraceFitInput& input, const TraceFitOptions& options,
                     const Minimum& minimum, const Solution& solution, const AmplitudeSweep& sweep,
                     const WhitenessStats& whiteness, double noise_rad_per_s);

}  // namespace trace
}  // namespace bifilar

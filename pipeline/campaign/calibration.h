// Rig calibration with a reference object (`rig.calibration`, docs/method.md §15): a machined bar
// or plate of known inertia and mass is swung on the rig; its swings fix the rig's effective
// D^2/L, which every trace of the campaign (tare logs included) then uses. To leading order the
// pendulum depends on L, D and g only through g D^2/L (docs/physics.md §2.6), so the tape-measure
// errors of L and D, and an error of g, are absorbed; the factor's own std becomes one relative
// term common to every moment (the `calibration` term of each trace's budget).
//
// The iteration: with the factor k, every reference swing is fitted (suspended mass = rig +
// reference) and, when the rig inertia comes from tare logs, every tare log too (their fitted
// inertia scales with k as well). Fitted inertias scale almost exactly like k (not exactly with
// the `full` model: the kinetic energy of the rise), so
//   k <- k * target / fitted,  target: I_reference (tare: fitted reference - fitted tare) or
//                                      I_rig + I_reference (a given rig inertia: fitted reference)
// converges in two or three rounds; it stops when the ratio is within kCalibrationTolerance of 1.
#pragma once

#include <functional>
#include <string>
#include <vector>

#include "pipeline/config/config.h"
#include "pipeline/records/calibration_result.h"
#include "pipeline/records/trace_record.h"

namespace bifilar {

constexpr double kCalibrationTolerance = 1e-6;  // |target / fitted - 1| at convergence
constexpr int kCalibrationMaxIterations = 8;
// A calibration that moves D^2/L by more than a factor 2 is not a tape-measure error: a wrong
// reference inertia or mass, a unit slip, or the wrong rig inertia. It is an error.
constexpr double kMinCalibrationFactor = 0.5, kMaxCalibrationFactor = 2.0;
constexpr int kRecommendedReferenceSwings = 3;  // fewer: a warning (the scatter is not measured)
// A factor further from 1 than kCalibrationFactorSigmas times the std the configured L, D and g
// uncertainties (and the calibration's own std) give it, and always one beyond +-10 %, warns
// (FarFromOneWarning): a reference inertia 45 % low gave k = 0.567 with a std of 0.09 % and no
// word, and every moment of the run 43 % low.
constexpr double kCalibrationFactorSigmas = 3.0;
constexpr double kCalibrationFactorWarnFraction = 0.10;

// Fits every reference swing of rig.calibration, plus every tare log when rig.inertia is `tare`,
// with `config` (whose geometry_calibration.factor is the round's k). Returns their records.
using CalibrationFitFunction =
    std::function<std::vector<TraceRecord>(const CampaignConfig& config)>;

// Runs the iteration above. Throws UserError naming the log when a reference swing is not `ok`
// (the caller then fits no aircraft trace), naming the key when there is no reference swing, no
// usable tare log, a reference not above the rig, an implausible factor or no convergence.
// `records` (optional) receives the final round's records.
RigCalibrationResult CalibrateRig(const CampaignConfig& config, const CalibrationFitFunction& fit,
                                  std::vector<TraceRecord>* records = nullptr);

// How far from 1 the factor may lie without a warning (fraction): kCalibrationFactorSigmas times
// sqrt((2 s_D / D)^2 + (s_L / L)^2 + (s_g / g)^2 + factor_rel_std^2), the stds in effect
// (RigUncertainties::InEffect: 1 mm on L and D when none are configured), at most
// kCalibrationFactorWarnFraction.
double GeometryFactorAllowance(const CampaignConfig& config, const RigCalibrationResult& c);
// "" when |k - 1| is within that allowance; else a warning naming the reference keys and what
// k implies for D (and for L). CalibrateRig adds it to `warnings` (console, results.json,
// report).
std::string FarFromOneWarning(const CampaignConfig& config, const RigCalibrationResult& c);

// CalibrateRig for `bifilar fit`: the logs of rig.calibration (and rig.inertia.tare) found with
// DiscoverListedLogs and fitted with ProcessTrace every round (no cache). Throws UserError as
// CalibrateRig does, and naming the key when a pattern matches nothing.
RigCalibrationResult CalibrateRigFromLogs(const CampaignConfig& config);

// The mean of repeated fits of one quantity and its standard error: the larger of the
// between-fit std / sqrt(n) and the fits' rms std / sqrt(n) (n = 1: the fit's std), so that a few
// fits that happen to agree closely never claim more than their fits can. NaN when empty.
void MeanAndStandardError(const std::vector<double>& values, const std::vector<double>& stds,
                          double* mean, double* standard_error);

}  // namespace bifilar

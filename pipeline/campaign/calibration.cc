#include "pipeline/campaign/calibration.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "base/statistics.h"
#include "base/text_format.h"
#include "base/user_error.h"
#include "pipeline/campaign/rig_inertia.h"
#include "pipeline/campaign/run_discovery.h"
#include "pipeline/trace/trace_process.h"

namespace bifilar {
namespace {

// The message of a record that is not ok, with its file named once.
std::string Described(const TraceRecord& r) {
  const std::string prefix = r.file + ": ";
  const std::string message =
      r.message.rfind(prefix, 0) == 0 ? r.message.substr(prefix.size()) : r.message;
  return r.file + ": " + ToString(r.status) + (message.empty() ? "" : " (" + message + ")");
}

}  // namespace

double GeometryFactorAllowance(const CampaignConfig& config, const RigCalibrationResult& c) {
  // k absorbs the errors of L, D and g (they enter as g D^2 / L): relative std
  // sqrt((2 s_D / D)^2 + (s_L / L)^2 + (s_g / g)^2), with the calibration's own std beside it.
  const RigUncertainties u = config.uncertainties.InEffect();
  const double d = 2.0 * u.filar_separation_std_m / config.filar_separation_m;
  const double l = u.filar_length_std_m / config.filar_length_m;
  const double g = u.gravity_std_mps2 / config.gravity_mps2;
  const double expected = std::sqrt(d * d + l * l + g * g + c.factor_rel_std * c.factor_rel_std);
  return std::min(kCalibrationFactorSigmas * expected, kCalibrationFactorWarnFraction);
}

std::string FarFromOneWarning(const CampaignConfig& config, const RigCalibrationResult& c) {
  const double allowed = GeometryFactorAllowance(config, c);
  if (!(std::abs(c.factor - 1.0) > allowed)) return "";
  const RigUncertainties u = config.uncertainties.InEffect();
  char buffer[1400];
  std::snprintf(
      buffer, sizeof(buffer),
      "rig.calibration: the factor k = %.4g moves D^2/L by %+.1f %%, beyond the %.2g %% that the "
      "configured uncertainties allow (3 sigma of L +- %.3g m, D +- %.3g m%s and the "
      "calibration's own %.2g %%; never more than %g %%). It implies an effective D of %.4g m "
      "against the %.4g m measured (%+.1f %%, L kept), or L = %.4g m against %.4g m (D kept): "
      "far more than a tape measure misses. More likely rig.calibration.reference_inertia_kg_m2 "
      "(%.6g kg m^2, about the swing axis) or rig.calibration.reference_mass_kg (%.6g kg) is "
      "wrong, or rig.inertia (%.6g kg m^2, from %s): every inertia of the run scales with k, "
      "and its std does not cover such an error",
      c.factor, 100.0 * (c.factor - 1.0), 100.0 * allowed, u.filar_length_std_m,
      u.filar_separation_std_m,
      u.gravity_std_mps2 > 0 ? (", g +- " + Fmt("%.3g", u.gravity_std_mps2) + " m/s^2").c_str()
                             : "",
      100.0 * c.factor_rel_std, 100.0 * kCalibrationFactorWarnFraction, c.effective_separation_m,
      c.nominal_separation_m, 100.0 * (std::sqrt(c.factor) - 1.0), c.filar_length_m / c.factor,
      c.filar_length_m, c.reference_inertia_kg_m2, c.reference_mass_kg, c.rig_inertia_kg_m2,
      c.rig_inertia_source == "tare" ? "the tare logs"
                                     : ("rig.inertia " + c.rig_inertia_source).c_str());
  return buffer;
}

void MeanAndStandardError(const std::vector<double>& values, const std::vector<double>& stds,
                          double* mean, double* standard_error) {
  *mean = NAN;
  *standard_error = NAN;
  if (values.empty()) return;
  const double n = static_cast<double>(values.size());
  double sum = 0.0, fit_var = 0.0;
  for (double v : values) sum += v;
  for (double s : stds) fit_var += s * s / stds.size();
  *mean = sum / n;
  const double fit_sem = std::sqrt(fit_var / n);
  *standard_error =
      values.size() >= 2 ? std::max(SampleStd(values) / std::sqrt(n), fit_sem) : fit_sem;
}

namespace {

// A given rig inertia (rig.inertia a value or a table) does not depend on k: looked up once, at
// rig.calibration.rig_pitch_deg. NaN for a tare rig (measured in every round).
void GivenRigInertia(const CampaignConfig& config, double* rig_given, double* rig_given_std) {
  *rig_given = NAN;
  *rig_given_std = NAN;
  if (config.rig_inertia.kind == RigInertiaSpec::Kind::kTare) return;
  std::string why;
  if (!RigInertiaAt(config, NAN, NAN, config.calibration.rig_pitch_deg, rig_given, rig_given_std,
                    &why)) {
    throw UserError("rig.calibration: rig inertia at rig_pitch_deg " +
                    Fmt("%g", config.calibration.rig_pitch_deg) + " deg: " + why);
  }
}

// One round's records into *out: the reference swings (every one must be ok), their mean
// inertia with its standard error and scatter, and the rig's inertia (the tare logs' mean, or the
// given one).
void ReadReferenceSwings(const std::vector<TraceRecord>& records, bool from_tare, double rig_given,
                         double rig_given_std, RigCalibrationResult* out) {
  std::vector<double> swing, swing_std, tare, tare_std;
  out->logs.clear();
  for (const TraceRecord& r : records) {
    if (!r.cache_key.empty()) out->cache_keys.push_back(r.cache_key);
    if (r.role == TraceRole::kCalibration) {
      if (!r.ok()) {
        throw UserError("rig.calibration: reference swing " + Described(r) +
                        "; the campaign stops before any aircraft trace is fitted with an "
                        "unknown geometry: fix this log (e.g. a fit.windows entry) or remove it "
                        "from rig.calibration.logs");
      }
      out->logs.push_back(r.file);
      swing.push_back(r.inertia_total_kg_m2);
      swing_std.push_back(r.inertia_total_std_kg_m2);
    } else if (r.role == TraceRole::kTare && r.ok()) {
      tare.push_back(r.inertia_total_kg_m2);
      tare_std.push_back(r.inertia_total_std_kg_m2);
    }
  }
  if (swing.empty()) throw UserError("rig.calibration.logs: no reference swing was found");
  out->n_swings = static_cast<int>(swing.size());
  MeanAndStandardError(swing, swing_std, &out->swings_total_kg_m2, &out->swings_total_std_kg_m2);
  out->swings_scatter_kg_m2 = SampleStd(swing);
  if (from_tare) {
    if (tare.empty()) {
      throw UserError(
          "rig.calibration: no usable tare log (rig.inertia.tare.logs): the rig's "
          "own inertia is needed to calibrate; the campaign stops");
    }
    MeanAndStandardError(tare, tare_std, &out->rig_inertia_kg_m2, &out->rig_inertia_std_kg_m2);
  } else {
    out->rig_inertia_kg_m2 = rig_given;
    out->rig_inertia_std_kg_m2 = rig_given_std;
  }
}

// The factor for the next round, k times target/fitted (*ratio), checked against the allowed
// range.
double FactorFromRound(const RigCalibrationSpec& spec, bool from_tare, double rig_given, double k,
                       const RigCalibrationResult& out, double* ratio) {
  // The reference's share of the swings' inertia, which must come out as its known inertia.
  const double measured_reference = out.swings_total_kg_m2 - out.rig_inertia_kg_m2;
  if (!(measured_reference > 0.0)) {
    throw UserError(
        Fmt("rig.calibration: the reference swings (I = %.6g kg m^2) are not "
            "above the rig alone (%.6g kg m^2): check rig.calibration.logs, "
            "reference_mass_kg and rig.inertia",
            out.swings_total_kg_m2, out.rig_inertia_kg_m2));
  }
  // Tare: I_rig scales with k too, so target/fitted = I_ref / (I_swings - I_tare); given rig:
  // (I_rig + I_ref) / I_swings.
  *ratio = from_tare ? spec.reference_inertia_kg_m2 / measured_reference
                     : (rig_given + spec.reference_inertia_kg_m2) / out.swings_total_kg_m2;
  const double next = k * *ratio;
  if (!(next >= kMinCalibrationFactor && next <= kMaxCalibrationFactor)) {
    throw UserError(
        Fmt("rig.calibration: the reference swings give an effective D^2/L %.4g times the "
            "configured one (allowed %g to %g): not a tape-measure error. Check "
            "reference_inertia_kg_m2 (about the swing axis, kg m^2), reference_mass_kg (kg), "
            "rig.inertia and rig.mass_kg",
            next, kMinCalibrationFactor, kMaxCalibrationFactor));
  }
  return next;
}

// The converged factor k into *out with its std (std(k)/k to first order in each input,
// docs/method.md §15), the effective geometry, and the warnings (few swings, a large std, k far
// from 1).
void CalibrationUncertainty(const CampaignConfig& config, bool from_tare, double rig_given,
                            double rig_given_std, double k, RigCalibrationResult* out) {
  const RigCalibrationSpec& spec = config.calibration;
  const double ref = spec.reference_inertia_kg_m2;
  if (from_tare) {  // k = I_ref / (S - T): S - T = I_ref at convergence
    out->rel_std_reference = spec.reference_inertia_std_kg_m2 / ref;
    out->rel_std_swings = out->swings_total_std_kg_m2 / ref;
    out->rel_std_rig = out->rig_inertia_std_kg_m2 / ref;
  } else {  // k = (I_rig + I_ref) / S: S = I_rig + I_ref at convergence
    const double total = rig_given + ref;
    out->rel_std_reference = spec.reference_inertia_std_kg_m2 / total;
    out->rel_std_swings = out->swings_total_std_kg_m2 / out->swings_total_kg_m2;
    out->rel_std_rig = (std::isfinite(rig_given_std) ? rig_given_std : 0.0) / total;
  }
  out->factor = k;
  out->factor_rel_std =
      std::sqrt(out->rel_std_reference * out->rel_std_reference +
                out->rel_std_swings * out->rel_std_swings + out->rel_std_rig * out->rel_std_rig);
  out->factor_std = k * out->factor_rel_std;
  out->effective_separation_m = config.filar_separation_m * std::sqrt(k);
  out->nominal_d2_over_l_m =
      config.filar_separation_m * config.filar_separation_m / config.filar_length_m;
  out->effective_d2_over_l_m = k * out->nominal_d2_over_l_m;
  out->applied = true;
  if (out->n_swings < kRecommendedReferenceSwings) {
    out->warnings.push_back(
        "rig.calibration: " + std::to_string(out->n_swings) + " reference swing" +
        (out->n_swings == 1 ? "" : "s") + "; swing the reference " +
        std::to_string(kRecommendedReferenceSwings) +
        "-5 times, so that their scatter is measured and enters the calibration's std");
  }
  if (out->factor_rel_std > 0.01) {
    out->warnings.push_back(
        Fmt("rig.calibration: the calibration's std is %.2g %%: a heavier reference (inertia well "
            "above the rig's), more swings or a better known reference inertia shrink it",
            100.0 * out->factor_rel_std));
  }
  const std::string far = FarFromOneWarning(config, *out);
  if (!far.empty()) out->warnings.push_back(far);
}

}  // namespace

// GivenRigInertia, then rounds of fit (at factor k) -> ReadReferenceSwings -> FactorFromRound
// until target/fitted is within kCalibrationTolerance of 1, then CalibrationUncertainty.
RigCalibrationResult CalibrateRig(const CampaignConfig& config, const CalibrationFitFunction& fit,
                                  std::vector<TraceRecord>* records_out) {
  const RigCalibrationSpec& spec = config.calibration;
  const RigInertiaSpec::Kind rig_kind = config.rig_inertia.kind;
  const bool from_tare = rig_kind == RigInertiaSpec::Kind::kTare;
  RigCalibrationResult out;
  out.reference_inertia_kg_m2 = spec.reference_inertia_kg_m2;
  out.reference_inertia_std_kg_m2 = spec.reference_inertia_std_kg_m2;
  out.reference_mass_kg = spec.reference_mass_kg;
  out.filar_length_m = config.filar_length_m;
  out.nominal_separation_m = config.filar_separation_m;
  out.rig_inertia_source = from_tare                                  ? "tare"
                           : rig_kind == RigInertiaSpec::Kind::kTable ? "table"
                                                                      : "value";
  double rig_given = NAN, rig_given_std = NAN;
  GivenRigInertia(config, &rig_given, &rig_given_std);

  double k = 1.0;
  std::vector<TraceRecord> records;
  bool converged = false;
  for (int round = 1; round <= kCalibrationMaxIterations && !converged; ++round) {
    CampaignConfig trial = config;
    trial.geometry_calibration = GeometryCalibration();
    trial.geometry_calibration.factor = k;
    records = fit(trial);
    out.iterations = round;
    ReadReferenceSwings(records, from_tare, rig_given, rig_given_std, &out);
    double ratio = NAN;
    const double next = FactorFromRound(spec, from_tare, rig_given, k, out, &ratio);
    if (std::abs(ratio - 1.0) <= kCalibrationTolerance) {
      converged = true;  // the records are those of k: keep k
    } else {
      k = next;
    }
  }
  if (!converged) {
    throw UserError("rig.calibration: the effective geometry did not converge in " +
                    std::to_string(kCalibrationMaxIterations) + " rounds (last factor " +
                    Fmt("%.8g", k) + ")");
  }
  CalibrationUncertainty(config, from_tare, rig_given, rig_given_std, k, &out);
  if (records_out) *records_out = std::move(records);
  return out;
}

RigCalibrationResult CalibrateRigFromLogs(const CampaignConfig& config) {
  std::vector<RunFile> runs =
      DiscoverListedLogs(config, config.calibration.log_patterns, TraceRole::kCalibration);
  if (config.rig_inertia.kind == RigInertiaSpec::Kind::kTare) {
    std::vector<RunFile> tare =
        DiscoverListedLogs(config, config.rig_inertia.tare_patterns, TraceRole::kTare);
    runs.insert(runs.end(), tare.begin(), tare.end());
  }
  const CalibrationFitFunction fit = [&](const CampaignConfig& round) {
    std::vector<TraceRecord> records;
    for (const RunFile& run : runs) {
      if (!run.error.empty()) {
        TraceRecord r;
        r.file = run.display;
        r.role = run.role;
        r.status = TraceStatus::kError;
        r.message = run.error;
        records.push_back(r);
        continue;
      }
      TraceProcessOptions options;
      options.role = run.role;
      options.display_name = run.display;
      records.push_back(ProcessTrace(round, run.path, options));
    }
    return records;
  };
  return CalibrateRig(config, fit);
}

}  // namespace bifilar

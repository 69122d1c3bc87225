#include "pipeline/trace/repeats.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <map>
#include <string>

#include "fit/amplitude_trend.h"
#include "pipeline/records/total_uncertainty.h"

namespace bifilar {
namespace {

bool Usable(const TraceRecord& r) {
  return r.ok() && std::isfinite(r.inertia_total_kg_m2) &&
         std::isfinite(r.inertia_total_std_kg_m2) && r.inertia_total_std_kg_m2 > 0.0;
}

// I against each used member's result amplitude across the repeats (fit/amplitude_trend.h, on
// the per-log stds): the slope in % per 10 deg at the members' amplitudes and its z.
void AmplitudeTrendAcrossRepeats(const std::vector<const TraceRecord*>& used, double reference,
                                 RepeatGroup* group) {
  if (used.size() < 3) return;
  std::vector<AmplitudePoint> points;
  for (const TraceRecord* r : used) {
    const double x = ResultAmplitudeSquared(*r);
    if (!std::isfinite(x)) return;
    points.push_back({std::sqrt(x), r->inertia_total_kg_m2, r->inertia_total_std_kg_m2});
  }
  AmplitudeTrend trend;
  if (!FitAmplitudeTrend(points, reference, &trend) ||
      !(trend.amplitude_max_deg > trend.amplitude_min_deg + 0.1)) {
    return;
  }
  group->amplitude_trend_percent_per_10deg = trend.percent_per_10deg;
  group->amplitude_trend_z = trend.coeff_std_per_deg2 > 0.0 ? trend.z : NAN;
  // The members' own I(A) trends, at the same amplitudes: a trend across the repeats beyond 3
  // sigma of theirs is not amplitude.
  double own = 0.0, own_std = 0.0;
  int n_own = 0;
  if (!PooledOwnTrend(used, &own, &own_std, &n_own)) return;
  const double per_10deg = 1000.0 * (trend.amplitude_max_deg + trend.amplitude_min_deg);
  group->own_trend_percent_per_10deg = own * per_10deg;
  group->own_trend_std_percent_per_10deg = own_std * per_10deg;
  group->trend_contradicts_own =
      trend.coeff_std_per_deg2 > 0.0 &&
      std::abs(trend.coeff_per_deg2 - own) > 3.0 * std::hypot(trend.coeff_std_per_deg2, own_std);
}

// The value a record had before the amplitude correction.
double Uncorrected(const TraceRecord& r) {
  return r.inertia_total_kg_m2 +
         (std::isfinite(r.amplitude_correction_kg_m2) ? r.amplitude_correction_kg_m2 : 0.0);
}

// Sample standard deviation of values over their mean (%), and Cochran's Q about their
// weighted mean with stds s.
void Scatter(const std::vector<double>& v, const std::vector<double>& s, double* spread_percent,
             double* q) {
  double mean = 0.0, sw = 0.0, swy = 0.0;
  for (size_t i = 0; i < v.size(); ++i) {
    mean += v[i] / v.size();
    sw += 1.0 / (s[i] * s[i]);
    swy += v[i] / (s[i] * s[i]);
  }
  double ss = 0.0;
  *q = 0.0;
  for (size_t i = 0; i < v.size(); ++i) {
    ss += (v[i] - mean) * (v[i] - mean);
    *q += std::pow((v[i] - swy / sw) / s[i], 2);
  }
  *spread_percent = 100.0 * std::sqrt(ss / (v.size() - 1.0)) / mean;
}

// Adds the amplitude correction's std (common to the set-up) to a used member's total std.
// Its total (pipeline/records/total_uncertainty.h) is updated: the correction is a term of its own.
void AddCorrectionStd(TraceRecord* r) {
  if (std::isfinite(r->amplitude_correction_std_kg_m2))
    r->inertia_total_std_kg_m2 =
        std::hypot(r->inertia_total_std_kg_m2, r->amplitude_correction_std_kg_m2);
  UpdateTotalUncertainty(r);
}

// The error of the correction's c moves a log by I A_i^2 dc: its part I Abar^2 dc moves every
// repeat of the set-up together (the set-up mean's std gets it), the rest I (A_i^2 - Abar^2) dc
// moves the repeats against each other and counts in their scatter. Abar^2 over the corrected.
double MeanSquaredCorrectionAmplitude(const std::vector<TraceRecord*>& used) {
  double a2bar = 0.0;
  int corrected = 0;
  for (const TraceRecord* r : used) {
    if (!std::isfinite(r->amplitude_correction_kg_m2)) continue;
    a2bar += r->amplitude_correction_from_deg * r->amplitude_correction_from_deg;
    ++corrected;
  }
  if (corrected > 0) a2bar /= corrected;
  return a2bar;
}

// Per used log: its std with the differential part of the correction's std (*s), its inertia
// before (*before) and after (*after) the amplitude correction.
void RepeatValues(const std::vector<TraceRecord*>& used, double a2bar, std::vector<double>* s,
                  std::vector<double>* before, std::vector<double>* after) {
  for (const TraceRecord* r : used) {
    double differential = 0.0;
    const double a2 = r->amplitude_correction_from_deg * r->amplitude_correction_from_deg;
    if (std::isfinite(r->amplitude_correction_kg_m2) && a2 > 0.0)
      differential = r->amplitude_correction_std_kg_m2 * std::abs(a2 - a2bar) / a2;
    s->push_back(std::hypot(r->inertia_total_std_kg_m2, differential));
    before->push_back(Uncorrected(*r));
    after->push_back(r->inertia_total_kg_m2);
  }
}

// The scatter before (per-log stds) and after the amplitude correction.
void ScatterBeforeAndAfter(const std::vector<TraceRecord*>& used, const std::vector<double>& before,
                           const std::vector<double>& after, const std::vector<double>& s,
                           RepeatGroup* group) {
  std::vector<double> s_before;
  for (const TraceRecord* r : used) s_before.push_back(r->inertia_total_std_kg_m2);
  Scatter(before, s_before, &group->spread_before_percent, &group->q_before);
  double q_after = 0.0;
  Scatter(after, s, &group->spread_after_percent, &q_after);
  double plain_before = 0.0;
  for (double v : before) plain_before += v / before.size();
  group->max_abs_z_before = 0.0;
  for (size_t i = 0; i < before.size(); ++i) {
    group->max_abs_z_before =
        std::max(group->max_abs_z_before, std::abs(before[i] - plain_before) / s_before[i]);
  }
}

// DerSimonian-Laird: Q about the fixed-effect mean, tau^2 = max(0, (Q - (k - 1)) / c). Sets the
// group's plain mean, Q and tau; returns tau^2.
double DerSimonianLaird(const std::vector<double>& after, const std::vector<double>& s,
                        RepeatGroup* group) {
  double sw = 0.0, sw2 = 0.0, swy = 0.0, plain = 0.0;
  for (size_t i = 0; i < after.size(); ++i) {
    const double w = 1.0 / (s[i] * s[i]);
    sw += w;
    sw2 += w * w;
    swy += w * after[i];
    plain += after[i];
  }
  const double k = static_cast<double>(after.size());
  const double fixed_mean = swy / sw;
  group->plain_mean_kg_m2 = plain / k;
  double q = 0.0;
  for (size_t i = 0; i < after.size(); ++i) q += std::pow((after[i] - fixed_mean) / s[i], 2);
  group->q = q;
  const double tau2 = std::max(0.0, (q - (k - 1.0)) / (sw - sw2 / sw));
  group->tau_kg_m2 = std::sqrt(tau2);
  return tau2;
}

// The trend is judged on the per-log stds and values before the correction and tau (which
// would absorb it).
void TrendBeforeCorrection(const std::vector<TraceRecord*>& used, RepeatGroup* group) {
  std::vector<TraceRecord> uncorrected;
  for (const TraceRecord* r : used) {
    uncorrected.push_back(*r);
    uncorrected.back().inertia_total_kg_m2 = Uncorrected(*r);
  }
  std::vector<const TraceRecord*> pointers;
  for (const TraceRecord& r : uncorrected) pointers.push_back(&r);
  AmplitudeTrendAcrossRepeats(pointers, group->plain_mean_kg_m2, group);
}

// The two-set-up finding, as the end of the scatter warning ("" for one set-up).
std::string SetupsSentence(const RepeatGroup& g) {
  return g.setups_text.empty() ? ""
                               : "; they look like " + g.setups_text +
                                     ". Fit each set-up as its own group (--group-by, or "
                                     "--runs-table with a group column)";
}

// The random-effects mean (weights 1 / (s_i^2 + tau^2)) and its std with the common part of the
// correction's std; every used log gets tau and its correction's std in its own std, and a
// warning when the repeats scatter beyond their stds.
void RandomEffectsMean(const std::vector<TraceRecord*>& used, const std::vector<double>& after,
                       const std::vector<double>& s, double a2bar, double tau2,
                       RepeatGroup* group) {
  double sw_re = 0.0, swy_re = 0.0, swc = 0.0;
  for (size_t i = 0; i < used.size(); ++i) {
    const double s_re = std::hypot(s[i], group->tau_kg_m2);
    sw_re += 1.0 / (s_re * s_re);
    swy_re += after[i] / (s_re * s_re);
  }
  group->mean_kg_m2 = swy_re / sw_re;
  group->max_abs_z = 0.0;
  group->max_abs_z_own = 0.0;
  for (size_t i = 0; i < used.size(); ++i) {
    TraceRecord& r = *used[i];
    const double s_re = std::hypot(s[i], group->tau_kg_m2);
    const double w = 1.0 / (s_re * s_re);
    // The common part of the correction's std: I Abar^2 std(c) for the set-up mean.
    const double a2 = r.amplitude_correction_from_deg * r.amplitude_correction_from_deg;
    if (std::isfinite(r.amplitude_correction_kg_m2) && a2 > 0.0)
      swc += w * r.amplitude_correction_std_kg_m2 * a2bar / a2;
    // Against the set-up's value, the random-effects mean (a plain mean would be pulled by an
    // imprecise log, a lowest-band result with its large std).
    group->max_abs_z = std::max(group->max_abs_z, std::abs(after[i] - group->mean_kg_m2) / s_re);
    group->max_abs_z_own =
        std::max(group->max_abs_z_own, std::abs(after[i] - group->mean_kg_m2) / s[i]);
    // The log's own std: its per-log std, tau and the whole std of its correction.
    r.repeat_scatter_std_kg_m2 = group->tau_kg_m2;
    r.inertia_total_std_kg_m2 = std::hypot(r.inertia_total_std_kg_m2, group->tau_kg_m2);
    AddCorrectionStd(&r);  // the between-repeat and correction terms enter the total too
    if (tau2 > 0.0) {
      char text[320];
      std::snprintf(text, sizeof(text),
                    "the %d repeats of %s scatter beyond their own stds (Q = %.1f on %d dof): "
                    "a between-repeat std of %.3g kg m^2 (%.2f %%) is added to this log's std",
                    group->n_used, group->name.c_str(), group->q, group->n_used - 1,
                    group->tau_kg_m2, 100.0 * group->tau_kg_m2 / group->plain_mean_kg_m2);
      r.warnings.push_back(text + SetupsSentence(*group));
      r.flags.push_back("repeat_scatter");
    }
  }
  group->correction_std_kg_m2 = swc / sw_re;
  group->mean_std_kg_m2 = std::hypot(1.0 / std::sqrt(sw_re), group->correction_std_kg_m2);
}

// The common-mode terms do not average out over repeats: their mean fraction of I, and the
// group's total std.
void CommonModeStd(const std::vector<TraceRecord*>& used, RepeatGroup* group) {
  const double k = static_cast<double>(used.size());
  double common_fraction = 0.0;
  for (const TraceRecord* r : used) {
    const TotalUncertainty total = ComposeTotalUncertainty(*r);
    common_fraction += total.common_mode_std_kg_m2 / r->inertia_total_kg_m2 / k;
  }
  group->common_mode_std_kg_m2 = common_fraction * group->mean_kg_m2;
  group->total_std_kg_m2 = std::hypot(group->mean_std_kg_m2, group->common_mode_std_kg_m2);
}

// The usable repeats of one set-up: MeanSquaredCorrectionAmplitude -> RepeatValues ->
// ScatterBeforeAndAfter -> DerSimonianLaird -> TrendBeforeCorrection -> RandomEffectsMean ->
// CommonModeStd.
void Combine(RepeatGroup* group, std::vector<TraceRecord>* records) {
  std::vector<TraceRecord*> used;
  for (int i : group->members) {
    if (Usable((*records)[i])) used.push_back(&(*records)[i]);
  }
  group->n_used = static_cast<int>(used.size());
  if (used.size() < 2) {
    group->note = std::to_string(used.size()) + " usable repeat(s) of " +
                  std::to_string(group->members.size()) + ": nothing to combine" +
                  (group->alone.empty() ? "" : " (a group of one: " + group->alone + ")");
    for (TraceRecord* r : used) AddCorrectionStd(r);
    return;
  }
  const double a2bar = MeanSquaredCorrectionAmplitude(used);
  std::vector<double> s, before, after;
  RepeatValues(used, a2bar, &s, &before, &after);
  ScatterBeforeAndAfter(used, before, after, s, group);
  const double tau2 = DerSimonianLaird(after, s, group);
  TrendBeforeCorrection(used, group);
  RandomEffectsMean(used, after, s, a2bar, tau2, group);
  CommonModeStd(used, group);
}

// One set-up or two (repeat_setups.h), on the usable members as fitted; the clusters as
// indices into the records, the finding as text naming the logs.
void TestSetups(const std::vector<TraceRecord>& records, RepeatGroup* group) {
  std::vector<const TraceRecord*> used;
  std::vector<int> index;
  std::vector<std::string> names;
  for (int i : group->members) {
    if (!Usable(records[i])) continue;
    used.push_back(&records[i]);
    index.push_back(i);
    const std::string& file = records[i].file;
    names.push_back(
        file.substr(file.find_last_of('/') == std::string::npos ? 0 : file.find_last_of('/') + 1));
  }
  group->setups = TestTwoSetups(used);
  group->setups_text = TwoSetupsText(group->setups, names);
  for (std::vector<int>& c : group->setups.clusters) {
    for (int& i : c) i = index[i];
  }
}

// The pooled amplitude coefficient over the groups' usable members, applied to every usable
// record: I_0 = I / (1 + c A^2), std I_0 A^2 std(c) / (1 + c A^2) (to first order).
// The pooled coefficient against the logs' own I(A) trends (the logs of the pooled fit): beyond
// 3 sigma the spread between repeats is not amplitude. True when it contradicts them.
bool ContradictsOwnTrends(const std::vector<const TraceRecord*>& fitted,
                          const PooledAmplitudeTrend& pooled, RepeatsAmplitudeCorrection* out) {
  if (!PooledOwnTrend(fitted, &out->own_coeff_per_deg2, &out->own_coeff_std_per_deg2, &out->n_own))
    return false;
  out->own_z = (pooled.coeff_per_deg2 - out->own_coeff_per_deg2) /
               std::hypot(pooled.coeff_std_per_deg2, out->own_coeff_std_per_deg2);
  if (!(std::abs(out->own_z) > 3.0)) return false;
  char text[480];
  std::snprintf(text, sizeof(text),
                "the repeats' differences do not follow their release amplitudes as the logs' own "
                "I(A) trends do (those trends, pooled over %d logs: c = %.3g +- %.2g per deg^2, "
                "%+.2f %% at 20 deg); the repeats differ for another reason (a changed set-up?)",
                out->n_own, out->own_coeff_per_deg2, out->own_coeff_std_per_deg2,
                100.0 * out->own_coeff_per_deg2 * 400.0);
  out->note = text;
  out->contradicts_own = true;
  return true;
}

RepeatsAmplitudeCorrection CorrectAmplitude(const std::vector<RepeatGroup>& groups,
                                            std::vector<TraceRecord>* records) {
  RepeatsAmplitudeCorrection out;
  std::vector<std::vector<AmplitudePoint>> points;
  std::vector<const TraceRecord*> fitted;
  for (const RepeatGroup& g : groups) {
    if (g.setups.two_setups) {  // its spread is not amplitude
      ++out.n_groups_two_setups;
      continue;
    }
    std::vector<AmplitudePoint> group_points;
    std::vector<const TraceRecord*> group_records;
    for (int i : g.members) {
      const TraceRecord& r = (*records)[i];
      const double a2 = ResultAmplitudeSquared(r);
      if (!Usable(r) || !std::isfinite(a2)) continue;
      group_points.push_back({std::sqrt(a2), r.inertia_total_kg_m2, r.inertia_total_std_kg_m2});
      group_records.push_back(&r);
    }
    if (group_points.size() >= 2) {
      points.push_back(group_points);
      fitted.insert(fitted.end(), group_records.begin(), group_records.end());
    }
  }
  PooledAmplitudeTrend pooled;
  if (!FitPooledAmplitudeTrend(points, &pooled)) {
    out.note = points.empty() && out.n_groups_two_setups > 0
                   ? "every group of repeats looks like two set-ups, whose spread is not amplitude"
                   : "the repeats do not vary in amplitude enough to measure how I depends on it "
                     "(needs 2 or more repeats of a set-up at different amplitudes, and 1 degree "
                     "of freedom beyond the fit)";
    if (!points.empty() && out.n_groups_two_setups > 0) {
      out.note += "; " + std::to_string(out.n_groups_two_setups) +
                  " group(s) left out: they look like two set-ups";
    }
    return out;
  }
  if (ContradictsOwnTrends(fitted, pooled, &out)) return out;
  out.coeff_per_deg2 = pooled.coeff_per_deg2;
  out.coeff_std_per_deg2 = pooled.coeff_std_per_deg2;
  out.z = pooled.z;
  out.birge = pooled.birge;
  out.scatter_percent = 100.0 * pooled.scatter_relative;
  out.dof = pooled.dof;
  out.n_logs = pooled.n_points;
  out.n_groups = pooled.n_groups;
  out.amplitude_min_deg = pooled.amplitude_min_deg;
  out.amplitude_max_deg = pooled.amplitude_max_deg;
  for (TraceRecord& r : *records) {
    const double a2 = ResultAmplitudeSquared(r);
    if (!Usable(r) || !std::isfinite(a2)) continue;
    // A result from the lowest band of a log whose own sweep found the trend already carries
    // the change to zero amplitude in its model-inadequacy std: it is a point of the pooled fit
    // (at that band's amplitude), but is not corrected a second time.
    if (r.inertia_source == "low_amplitude_band") {
      ++out.n_low_band_kept;
      continue;
    }
    const double factor = 1.0 + out.coeff_per_deg2 * a2;
    if (!(factor > 0.5)) continue;  // far outside what the fit measured: leave it
    const double corrected = r.inertia_total_kg_m2 / factor;
    r.amplitude_correction_kg_m2 = r.inertia_total_kg_m2 - corrected;
    r.amplitude_correction_std_kg_m2 = corrected * a2 * out.coeff_std_per_deg2 / factor;
    r.amplitude_correction_from_deg = std::sqrt(a2);
    r.inertia_total_kg_m2 = corrected;
    ++out.n_corrected;
  }
  out.applied = out.n_corrected > 0;
  if (!out.applied) {
    out.note =
        "every usable log's result comes from the lowest-amplitude band of its own sweep, "
        "whose std already covers the change to zero amplitude";
  }
  return out;
}

}  // namespace

bool IsRepeatScatterWarning(const std::string& warning) {
  return warning.rfind("the ", 0) == 0 &&
         warning.find(" scatter beyond their own stds (Q = ") != std::string::npos;
}

RepeatsAmplitudeCorrection CombineRepeats(std::vector<RepeatGroup>* groups,
                                          std::vector<TraceRecord>* records) {
  for (RepeatGroup& g : *groups) TestSetups(*records, &g);
  const RepeatsAmplitudeCorrection correction = CorrectAmplitude(*groups, records);
  for (RepeatGroup& g : *groups) Combine(&g, records);
  return correction;
}

namespace {

// How far the logs lie from the mean: with a between-repeat std added, that std is named in the
// same sentence, and the per-log stds' figure beside it.
std::string WithinSigmaText(const RepeatGroup& g) {
  char text[320];
  if (g.tau_kg_m2 > 0.0) {
    std::snprintf(text, sizeof(text),
                  "between-repeat std %.2g kg m^2 = %.2f %% added to each log; with it every log "
                  "is within %.1f sigma of the mean, %.1f sigma on the per-log stds alone",
                  g.tau_kg_m2, 100.0 * g.tau_kg_m2 / g.plain_mean_kg_m2, g.max_abs_z,
                  g.max_abs_z_own);
  } else {
    std::snprintf(text, sizeof(text),
                  "no between-repeat std needed; every log within %.1f sigma (stat) of the mean",
                  g.max_abs_z);
  }
  return text;
}

}  // namespace

std::string RepeatGroupLine(const RepeatGroup& g) {
  char buffer[640];
  if (!g.note.empty()) {
    std::snprintf(buffer, sizeof(buffer), "repeats %s: %s", g.name.c_str(), g.note.c_str());
    return buffer;
  }
  std::snprintf(buffer, sizeof(buffer),
                "repeats %s: I = %s (random-effects mean of %d; Q = %.1f on %d dof; %s)",
                g.name.c_str(),
                StatAndTotal(g.mean_kg_m2, g.mean_std_kg_m2,
                             std::isfinite(g.total_std_kg_m2) ? g.total_std_kg_m2 : NAN, "kg m^2")
                    .c_str(),
                g.n_used, g.q, g.n_used - 1, WithinSigmaText(g).c_str());
  std::string line = buffer;
  if (g.setups.two_setups) {
    line += "\n    the mean above is of two set-ups, not one (the warning below names them)";
  } else if (g.trend_contradicts_own) {
    std::snprintf(buffer, sizeof(buffer),
                  "\n    across the repeats I does not follow the release amplitude as each log's "
                  "own I(A) does (own trends %+.2g +- %.2g %% per 10 deg): the repeats differ for "
                  "another reason than amplitude",
                  g.own_trend_percent_per_10deg, g.own_trend_std_percent_per_10deg);
    line += buffer;
  } else if (std::isfinite(g.amplitude_trend_z)) {
    std::snprintf(
        buffer, sizeof(buffer),
        "\n    across the repeats I changes by %+.2g %% per 10 deg of amplitude (z = %.1f)%s",
        g.amplitude_trend_percent_per_10deg, g.amplitude_trend_z,
        std::abs(g.amplitude_trend_z) > 3.0
            ? ": the rig departs from the ideal model; release every repeat at the same "
              "small amplitude"
            : "");
    line += buffer;
  }
  if (std::isfinite(g.correction_std_kg_m2) && g.correction_std_kg_m2 > 0.0) {
    std::snprintf(buffer, sizeof(buffer),
                  "\n    scatter of the repeats %.2f %% before the amplitude correction, %.2f %% "
                  "after (Q %.1f -> %.1f; largest |z| on the per-log stds %.1f before); the "
                  "correction's std %.2g kg m^2 (%.2f %%) is in the mean's std",
                  g.spread_before_percent, g.spread_after_percent, g.q_before, g.q,
                  g.max_abs_z_before, g.correction_std_kg_m2,
                  100.0 * g.correction_std_kg_m2 / g.plain_mean_kg_m2);
    line += buffer;
  } else if (std::isfinite(g.spread_before_percent)) {
    std::snprintf(buffer, sizeof(buffer),
                  "\n    scatter of the repeats %.2f %% (no amplitude correction; largest |z| on "
                  "the per-log stds %.1f)",
                  g.spread_before_percent, g.max_abs_z_before);
    line += buffer;
  }
  return line;
}

std::string AmplitudeCorrectionLine(const RepeatsAmplitudeCorrection& c) {
  if (!c.applied) return "amplitude correction: none (" + c.note + ")";
  std::string kept;
  if (c.n_low_band_kept > 0) {
    kept = "; " + std::to_string(c.n_low_band_kept) +
           " log(s) whose result comes from their own lowest band keep it (their std covers the "
           "change to zero amplitude)";
  }
  char buffer[640];
  std::snprintf(buffer, sizeof(buffer),
                "amplitude correction: I = I_0 (1 + c A^2), c = %.3g +- %.2g per deg^2 (z = %.1f; "
                "pooled over %d logs in %d set-up(s), %.1f-%.1f deg, weighted with a between-log "
                "scatter of %.2g %%): "
                "each log's I is moved from the amplitude of its result to zero amplitude "
                "(%+.2f %% at 10 deg, %+.2f %% at 20 deg) with the std of c propagated",
                c.coeff_per_deg2, c.coeff_std_per_deg2, c.z, c.n_logs, c.n_groups,
                c.amplitude_min_deg, c.amplitude_max_deg, c.scatter_percent,
                -100.0 * (1.0 - 1.0 / (1.0 + c.coeff_per_deg2 * 100.0)),
                -100.0 * (1.0 - 1.0 / (1.0 + c.coeff_per_deg2 * 400.0)));
  return buffer + kept;
}

}  // namespace bifilar

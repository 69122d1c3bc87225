// Repeats of one set-up: several swings of the same body about the same axis on the same rig.
//
// A single log's std is built from that log alone (HAC covariance, the amplitude sweep). What one
// log cannot see is what changes from release to release: the release amplitude on a rig that
// departs from the ideal model, a slow wander of the period, re-hanging. Repeats see it. Their
// scatter beyond their own stds is measured by Cochran's Q and the between-repeat variance
// tau^2 of DerSimonian and Laird (random-effects meta-analysis), and tau is added in quadrature
// to every repeat's std, so that each log's std covers what a repeat of it would give. The
// combined value is the random-effects mean, weights 1 / (sigma_i^2 + tau^2).
//
// Before that, the release amplitude is taken out: on a rig that departs from the ideal model, I
// grows with the amplitude, and repeats released at different amplitudes scatter for that
// reason. One relative coefficient c of I_0 (1 + c A^2), pooled over every set-up of the run
// (each with its own I_0), moves each log's I from the amplitude of its result to zero amplitude,
// with the std of c propagated (common to all logs of a set-up: it enters each log's std and the
// set-up mean's std, not the scatter between repeats). The scatter is reported before and after.
//
// `bifilar fit --repeats` groups the logs whose paths differ only in the last number of the
// file name, case ignored (`BaseModel_Ixx_Log-1.csv` ... `-4.csv`; `pitch_10/trial_1.csv` ...
// `trial_5.csv`), or as --group-by or a runs table says (RepeatGroupingOptions). A group whose
// repeats disagree far beyond their stds is tested for two set-ups (repeat_setups.h).
// docs/method.md, "Repeats".
#ifndef BIFILAR_PIPELINE_REPEATS_H_
#define BIFILAR_PIPELINE_REPEATS_H_

#include <string>
#include <utility>
#include <vector>

#include "pipeline/logs/imu_format.h"
#include "pipeline/logs/imu_log_options.h"
#include "pipeline/records/trace_record.h"
#include "pipeline/trace/repeat_setups.h"

namespace bifilar {

struct RepeatGroup {
  std::string name;          // the common path, the repeat number replaced by '*'
  std::vector<int> members;  // indices into the records given to CombineRepeats
  int n_used = 0;            // members with a usable I and std (status ok)
  double mean_kg_m2 = NAN;   // random-effects mean
  double mean_std_kg_m2 = NAN;
  double plain_mean_kg_m2 = NAN;  // unweighted mean of the used members
  // Cochran's Q about the fixed-effect mean, n_used - 1 dof, on the per-log stds with the part
  // of the amplitude correction's std that differs between the repeats,
  // I_i (A_i^2 - mean A^2) std(c); the part common to the set-up does not scatter them.
  double q = NAN;
  double tau_kg_m2 = NAN;  // between-repeat std beyond those stds (0: none)
  // Largest |I_i - mean_kg_m2| / std_i over the used members, std_i those stds with tau added.
  double max_abs_z = NAN;
  // Across the repeats, I against the mean squared amplitude of each log's fit (weighted line):
  // the slope in % per 10 deg at the repeats' amplitudes and its z. A rig that departs from the
  // ideal model shows here even when each log is too short to show it.
  double amplitude_trend_percent_per_10deg = NAN;
  double amplitude_trend_z = NAN;
  // The scatter of the used members before and after the amplitude correction: sample standard
  // deviation of I over their plain mean (%), and Cochran's Q; the largest |I_i - plain mean| /
  // std_i before (per-log std alone). q, tau, max_abs_z above are after the
  // correction (the same as before when none was applied).
  double spread_before_percent = NAN;
  double spread_after_percent = NAN;
  double q_before = NAN;
  double max_abs_z_before = NAN;
  // The correction's std for the set-up mean (common to its members), included in mean_std_kg_m2.
  double correction_std_kg_m2 = NAN;
  // Total uncertainty of the mean (pipeline/records/total_uncertainty.h): mean_std_kg_m2 and the
  // members' common-mode terms (budget, calibration; their mean fraction of I times the mean) in
  // quadrature: what the `--repeats` line and JSON give as the set-up's total.
  double common_mode_std_kg_m2 = NAN;
  double total_std_kg_m2 = NAN;
  std::string note;  // why nothing was combined (fewer than 2 usable members)
  // A group of one: why no other log joined it, and the nearest name that almost matched.
  std::string alone;
  // Largest |I_i - mean_kg_m2| / per-log std, without tau (the between-repeat std).
  double max_abs_z_own = NAN;
  // One set-up or two (pipeline/trace/repeat_setups.h), on the values before the amplitude
  // correction; cluster indices are into the records given to CombineRepeats.
  SetupSplit setups;
  std::string setups_text;  // TwoSetupsText with the logs' file names ("" for one set-up)
  // The members' own I(A) trends (as an A^2 coefficient) disagree with the trend across the
  // repeats beyond 3 sigma: the repeats differ for another reason than their amplitude.
  bool trend_contradicts_own = false;
  double own_trend_percent_per_10deg = NAN, own_trend_std_percent_per_10deg = NAN;
};

// How logs are grouped into set-ups: by default, paths that differ only in the last number of
// the file name, ignoring case; `group_by` (a regular expression, case ignored) names the part of
// each file name (of the path, when the expression holds a '/') that names the set-up: its first
// capture group, else the whole match; `named` (one entry per path, "" for a path it does not
// name: a runs table's group column, or its attitude) names groups explicitly. `named` wins over
// `group_by`.
struct RepeatGroupingOptions {
  std::string group_by;
  std::vector<std::string> named;
  std::string named_source;             // the table, for the messages ("runs.csv (group column)")
  std::vector<std::string> named_rows;  // the table's paths, for the nearest name of a lost log
};

// Throws UserError when group_by is not a regular expression.
std::vector<RepeatGroup> GroupRepeats(const std::vector<std::string>& paths,
                                      const RepeatGroupingOptions& options);

// The groups made, for the console before any combining: the rule, then one line per group with
// its logs' file names, or why it is alone and the nearest name.
std::string RepeatGroupsText(const std::vector<RepeatGroup>& groups,
                             const std::vector<std::string>& paths,
                             const RepeatGroupingOptions& options);

// True for the warning CombineRepeats puts on each member of a group whose repeats scatter
// beyond their stds (the same text on every member: `fit --repeats` prints it once).
bool IsRepeatScatterWarning(const std::string& warning);

// Groups `paths` by the path with its last number in the file name removed, ignoring case; a
// path without a number is a group of its own (the default RepeatGroupingOptions).
std::vector<RepeatGroup> GroupRepeats(const std::vector<std::string>& paths);

// One swing is one repeat: a log given twice (the same file under one or two names), a copy
// under another name, or the same swing saved again with other line ends (CRLF), an extra
// newline or comment line, would count twice, give Q = 0 and shrink the std by sqrt(2). So
// identity is judged on the samples the reader gives (times, gyro and accelerometer in SI, read
// with `format` and `options` as the fit reads them), not on the bytes: for each path, the index
// of the first earlier path with the same samples, or -1. A file that cannot be read as a log
// (its fit reports why) is compared by its bytes; one that is not a regular file is -1. Each log
// is read once and its samples hashed (FNV-1a 64); only logs whose hashes meet are compared in
// full, so the scan is linear in the logs, whatever their sizes.
struct IdenticalLog {
  int first = -1;        // index of the first earlier path with the same content, or -1
  std::string relation;  // "given again", "the same file as", "the same bytes as",
                         // "the same samples as" (empty for -1)
};
std::vector<IdenticalLog> FindIdenticalLogs(const std::vector<std::string>& paths,
                                            const ImuFormat& format, const ImuLogOptions& options);

// The logs of `paths` that FindIdenticalLogs keeps (first of each content, in order), and one
// warning per dropped log naming it and the log it repeats.
struct DistinctLogs {
  std::vector<std::string> kept;
  std::vector<std::pair<std::string, std::string>> dropped;  // (dropped log, the kept one)
  std::vector<std::string> warnings;
};
DistinctLogs DropIdenticalLogs(const std::vector<std::string>& paths, const ImuFormat& format,
                               const ImuLogOptions& options);

// The amplitude correction pooled over the groups (fit/amplitude_trend.h,
// FitPooledAmplitudeTrend on each usable log's I, std and result amplitude: the lowest band's
// when the result comes from it, else the RMS of the fitted start and end amplitudes).
struct RepeatsAmplitudeCorrection {
  bool applied = false;
  double coeff_per_deg2 = NAN;      // c of I_0 (1 + c A^2), relative
  double coeff_std_per_deg2 = NAN;  // with the between-log scatter in the weights
  double z = NAN;
  double birge = NAN;            // scatter about the pooled fit over the stds, sqrt(chi^2/dof)
  double scatter_percent = NAN;  // between-log relative std in the pooled fit's weights (%)
  int dof = 0;
  int n_logs = 0, n_groups = 0;  // used by the pooled fit
  int n_corrected = 0;           // logs moved to zero amplitude
  // Logs whose result is the lowest band of their own sweep's trend (inertia_source
  // "low_amplitude_band"): points of the fit, but not corrected (their model-inadequacy std
  // already covers the change to zero amplitude).
  int n_low_band_kept = 0;
  double amplitude_min_deg = NAN, amplitude_max_deg = NAN;
  std::string note;  // why it was not applied (the fields above may be set)
  // The logs' own I(A) trends pooled (PooledOwnTrend, over the logs of the pooled fit), and the
  // pooled coefficient's z against them. Beyond 3 sigma the spread between repeats is not their
  // amplitude: nothing is corrected, and the coefficient fields above stay NaN.
  double own_coeff_per_deg2 = NAN, own_coeff_std_per_deg2 = NAN;
  int n_own = 0;
  double own_z = NAN;
  bool contradicts_own = false;
  int n_groups_two_setups = 0;  // groups left out of the pooled fit: they look like two set-ups
};

// Combines each group's usable members (status ok, finite I, std > 0). First the set-up test of
// each group (TestTwoSetups on the values as fitted): a group that looks like two set-ups is
// left out of the pooled amplitude fit, and its scatter warning says so, naming the clusters.
// Then the amplitude correction: c pooled over the groups with >= 2 usable members; every usable
// record whose result is not already a low-amplitude band gets amplitude_correction_* set, the
// correction subtracted from inertia_total_kg_m2. Then per group: the statistics, and for every
// used member repeat_scatter_std_kg_m2 = tau, tau and the correction's std added in quadrature to
// inertia_total_std_kg_m2 (and its total updated) and, when tau > 0, a warning.
RepeatsAmplitudeCorrection CombineRepeats(std::vector<RepeatGroup>* groups,
                                          std::vector<TraceRecord>* records);

// One line per group for the console.
std::string RepeatGroupLine(const RepeatGroup& group);

// One line for the console: the pooled coefficient, or why no correction was applied.
std::string AmplitudeCorrectionLine(const RepeatsAmplitudeCorrection& correction);

}  // namespace bifilar

#endif  // BIFILAR_PIPELINE_REPEATS_H_

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
// `bifilar fit --repeats` groups the logs whose paths differ only in the last number of the
// file name (`BaseModel_Ixx_Log-1.csv` ... `-4.csv`; `pitch_10/trial_1.csv` ... `trial_5.csv`).
// docs/method.md, "Repeats".
#ifndef BIFILAR_PIPELINE_REPEATS_H_
#define BIFILAR_PIPELINE_REPEATS_H_

#include <string>
#include <vector>

#include "pipeline/trace_process.h"

namespace bifilar {

struct RepeatGroup {
  std::string name;          // the common path, the repeat number replaced by '*'
  std::vector<int> members;  // indices into the records given to CombineRepeats
  int n_used = 0;            // members with a usable I and std (status ok)
  double mean_kg_m2 = NAN;   // random-effects mean
  double mean_std_kg_m2 = NAN;
  double plain_mean_kg_m2 = NAN;  // unweighted mean of the used members
  double q = NAN;            // Cochran's Q about the fixed-effect mean, n_used - 1 dof
  double tau_kg_m2 = NAN;    // between-repeat std beyond the per-log stds (0: none)
  // Largest |I_i - plain mean| / std_i over the used members, std_i with tau added.
  double max_abs_z = NAN;
  // Across the repeats, I against the mean squared amplitude of each log's fit (weighted line):
  // the slope in % per 10 deg at the repeats' amplitudes and its z. A rig that departs from the
  // ideal model shows here even when each log is too short to show it.
  double amplitude_trend_percent_per_10deg = NAN;
  double amplitude_trend_z = NAN;
  // Total uncertainty of the mean (pipeline/total_uncertainty.h): mean_std_kg_m2 and the
  // members' common-mode terms (budget, calibration; their mean fraction of I times the mean) in
  // quadrature: what the `--repeats` line and JSON give as the set-up's total.
  double common_mode_std_kg_m2 = NAN;
  double total_std_kg_m2 = NAN;
  std::string note;          // why nothing was combined (fewer than 2 usable members)
};

// Groups `paths` by the path with its last number in the file name removed; a path without a
// number is a group of its own.
// True for the warning CombineRepeats puts on each member of a group whose repeats scatter
// beyond their stds (the same text on every member: `fit --repeats` prints it once).
bool IsRepeatScatterWarning(const std::string& warning);

std::vector<RepeatGroup> GroupRepeats(const std::vector<std::string>& paths);

// Combines each group's usable members (status ok, finite I, std > 0): fills the group's
// statistics, and for every used member sets repeat_scatter_std_kg_m2 = tau, adds tau in
// quadrature to inertia_total_std_kg_m2 (and updates its total) and, when tau > 0, a warning
// saying so.
void CombineRepeats(std::vector<RepeatGroup>* groups, std::vector<TraceRecord>* records);

// One line per group for the console.
std::string RepeatGroupLine(const RepeatGroup& group);

}  // namespace bifilar

#endif  // BIFILAR_PIPELINE_REPEATS_H_

#include "pipeline/repeats.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <map>

#include "fit/amplitude_trend.h"
#include "pipeline/total_uncertainty.h"

namespace bifilar {
namespace {

// "logs/BaseModel_Ixx_Log-3.csv" -> "logs/BaseModel_Ixx_Log-*.csv": the last run of digits in
// the file name (not the folders) becomes '*'.
std::string RepeatKey(const std::string& path) {
  const size_t name_start = path.find_last_of('/') == std::string::npos ? 0 : path.find_last_of('/') + 1;
  size_t end = path.size();
  while (end > name_start && !std::isdigit(static_cast<unsigned char>(path[end - 1]))) --end;
  if (end == name_start) return path;
  size_t begin = end;
  while (begin > name_start && std::isdigit(static_cast<unsigned char>(path[begin - 1]))) --begin;
  return path.substr(0, begin) + "*" + path.substr(end);
}

bool Usable(const TraceRecord& r) {
  return r.ok() && std::isfinite(r.inertia_total_kg_m2) && std::isfinite(r.inertia_total_std_kg_m2) &&
         r.inertia_total_std_kg_m2 > 0.0;
}

// Mean squared amplitude (deg^2) of the part of the log the result comes from.
double ResultAmplitudeSquared(const TraceRecord& r) {
  if (r.inertia_source == "low_amplitude_band" && r.sweep.low_band >= 0 &&
      r.sweep.low_band < static_cast<int>(r.sweep.bands.size())) {
    const double a = r.sweep.bands[r.sweep.low_band].amplitude_mean_deg;
    return a * a;
  }
  return 0.5 * (r.amplitude_deg[0] * r.amplitude_deg[0] + r.amplitude_deg[1] * r.amplitude_deg[1]);
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
}

void Combine(RepeatGroup* group, std::vector<TraceRecord>* records) {
  std::vector<const TraceRecord*> used;
  for (int i : group->members) {
    if (Usable((*records)[i])) used.push_back(&(*records)[i]);
  }
  group->n_used = static_cast<int>(used.size());
  if (used.size() < 2) {
    group->note = std::to_string(used.size()) + " usable repeat(s) of " +
                  std::to_string(group->members.size()) + ": nothing to combine";
    return;
  }
  // DerSimonian-Laird: Q about the fixed-effect mean, tau^2 = max(0, (Q - (k - 1)) / c).
  double sw = 0.0, sw2 = 0.0, swy = 0.0, plain = 0.0;
  for (const TraceRecord* r : used) {
    const double w = 1.0 / (r->inertia_total_std_kg_m2 * r->inertia_total_std_kg_m2);
    sw += w;
    sw2 += w * w;
    swy += w * r->inertia_total_kg_m2;
    plain += r->inertia_total_kg_m2;
  }
  const double k = static_cast<double>(used.size());
  const double fixed_mean = swy / sw;
  group->plain_mean_kg_m2 = plain / k;
  double q = 0.0;
  for (const TraceRecord* r : used) {
    q += std::pow((r->inertia_total_kg_m2 - fixed_mean) / r->inertia_total_std_kg_m2, 2);
  }
  group->q = q;
  const double tau2 = std::max(0.0, (q - (k - 1.0)) / (sw - sw2 / sw));
  group->tau_kg_m2 = std::sqrt(tau2);
  // The trend is judged on the per-log stds, before tau (which would absorb it).
  AmplitudeTrendAcrossRepeats(used, group->plain_mean_kg_m2, group);
  double sw_re = 0.0, swy_re = 0.0;
  group->max_abs_z = 0.0;
  for (int i : group->members) {
    TraceRecord& r = (*records)[i];
    if (!Usable(r)) continue;
    r.repeat_scatter_std_kg_m2 = group->tau_kg_m2;
    r.inertia_total_std_kg_m2 = std::hypot(r.inertia_total_std_kg_m2, group->tau_kg_m2);
    UpdateTotalUncertainty(&r);  // the between-repeat term enters the total too
    const double w = 1.0 / (r.inertia_total_std_kg_m2 * r.inertia_total_std_kg_m2);
    sw_re += w;
    swy_re += w * r.inertia_total_kg_m2;
    group->max_abs_z = std::max(
        group->max_abs_z,
        std::abs(r.inertia_total_kg_m2 - group->plain_mean_kg_m2) / r.inertia_total_std_kg_m2);
    if (tau2 > 0.0) {
      char text[320];
      std::snprintf(text, sizeof(text),
                    "the %d repeats of %s scatter beyond their own stds (Q = %.1f on %d dof): "
                    "a between-repeat std of %.3g kg m^2 (%.2f %%) is added to this log's std",
                    group->n_used, group->name.c_str(), q, group->n_used - 1, group->tau_kg_m2,
                    100.0 * group->tau_kg_m2 / group->plain_mean_kg_m2);
      r.warnings.push_back(text);
      r.flags.push_back("repeat_scatter");
    }
  }
  group->mean_kg_m2 = swy_re / sw_re;
  group->mean_std_kg_m2 = 1.0 / std::sqrt(sw_re);
  // The common-mode terms do not average out over repeats: their mean fraction of I.
  double common_fraction = 0.0;
  for (const TraceRecord* r : used) {
    const TotalUncertainty total = ComposeTotalUncertainty(*r);
    common_fraction += total.common_mode_std_kg_m2 / r->inertia_total_kg_m2 / k;
  }
  group->common_mode_std_kg_m2 = common_fraction * group->mean_kg_m2;
  group->total_std_kg_m2 = std::hypot(group->mean_std_kg_m2, group->common_mode_std_kg_m2);
}

}  // namespace

bool IsRepeatScatterWarning(const std::string& warning) {
  return warning.rfind("the ", 0) == 0 &&
         warning.find(" scatter beyond their own stds (Q = ") != std::string::npos;
}

std::vector<RepeatGroup> GroupRepeats(const std::vector<std::string>& paths) {
  std::vector<RepeatGroup> groups;
  std::map<std::string, size_t> index;
  for (size_t i = 0; i < paths.size(); ++i) {
    const std::string key = RepeatKey(paths[i]);
    auto [it, inserted] = index.emplace(key, groups.size());
    if (inserted) {
      groups.emplace_back();
      groups.back().name = key;
    }
    groups[it->second].members.push_back(static_cast<int>(i));
  }
  return groups;
}

void CombineRepeats(std::vector<RepeatGroup>* groups, std::vector<TraceRecord>* records) {
  for (RepeatGroup& g : *groups) Combine(&g, records);
}

std::string RepeatGroupLine(const RepeatGroup& g) {
  char buffer[640];
  if (!g.note.empty()) {
    std::snprintf(buffer, sizeof(buffer), "repeats %s: %s", g.name.c_str(), g.note.c_str());
    return buffer;
  }
  std::snprintf(buffer, sizeof(buffer),
                "repeats %s: I = %s (random-effects mean of %d; Q = %.1f on %d "
                "dof; between-repeat std %.2g kg m^2 = %.2f %% added to each log; every log within "
                "%.1f sigma (stat) of the mean)",
                g.name.c_str(),
                StatAndTotal(g.mean_kg_m2, g.mean_std_kg_m2,
                             std::isfinite(g.total_std_kg_m2) ? g.total_std_kg_m2 : NAN, "kg m^2")
                    .c_str(),
                g.n_used, g.q, g.n_used - 1,
                g.tau_kg_m2, 100.0 * g.tau_kg_m2 / g.plain_mean_kg_m2, g.max_abs_z);
  std::string line = buffer;
  if (std::isfinite(g.amplitude_trend_z)) {
    std::snprintf(buffer, sizeof(buffer),
                  "\n    across the repeats I changes by %+.2g %% per 10 deg of amplitude (z = %.1f)%s",
                  g.amplitude_trend_percent_per_10deg, g.amplitude_trend_z,
                  std::abs(g.amplitude_trend_z) > 3.0
                      ? ": the rig departs from the ideal model; release every repeat at the same "
                        "small amplitude"
                      : "");
    line += buffer;
  }
  return line;
}

}  // namespace bifilar

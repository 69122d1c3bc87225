#include "pipeline/records/total_uncertainty.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <vector>

namespace bifilar {
namespace {

double OrZero(double v) { return std::isfinite(v) ? v : 0.0; }

// The budget lines that a calibration with a reference object replaces: it fixes the effective
// D^2 g / L of the rig, so the tape-measure errors of L and D and the error of g drop out.
bool ReplacedByCalibration(const std::string& budget_name) {
  return budget_name == "filar_length" || budget_name == "filar_separation" ||
         budget_name == "gravity";
}

// The configured-inputs term of I_total (kg m^2): the budget in quadrature, without the lines a
// calibration replaces and without the calibration's own line (its term is separate). Summed in
// the order of the terms' names, the order results.json and the cache hold them in (a JSON
// object): a record read back composes the same bits as the one written.
double ConfiguredInputsStd(const TraceRecord& r) {
  if (r.budget.empty()) return OrZero(r.budget_total_std_kg_m2);
  std::vector<const BudgetTerm*> terms;
  for (const BudgetTerm& term : r.budget) terms.push_back(&term);
  std::stable_sort(terms.begin(), terms.end(),
                   [](const BudgetTerm* a, const BudgetTerm* b) { return a->name < b->name; });
  double sum_sq = 0.0;
  for (const BudgetTerm* term : terms) {
    if (r.calibrated && ReplacedByCalibration(term->name)) continue;
    if (term->name == kTermCalibration) continue;  // the calibration term of its own (below)
    sum_sq += OrZero(term->std_kg_m2) * OrZero(term->std_kg_m2);
  }
  return std::sqrt(sum_sq);
}

void Finish(TotalUncertainty* u) {
  double stat = 0.0, common = 0.0;
  for (const UncertaintyTerm& t : u->terms) {
    (t.common_mode ? common : stat) += t.std_kg_m2 * t.std_kg_m2;  // NaN propagates: unknown
    u->assumed = u->assumed || t.assumed;
  }
  u->stat_std_kg_m2 = std::sqrt(stat);
  u->common_mode_std_kg_m2 = std::sqrt(common);
  u->total_std_kg_m2 = std::sqrt(stat + common);
}

// The per-log terms of a record, shared by both compositions.
std::vector<UncertaintyTerm> PerLogTerms(const TraceRecord& r) {
  return {{kTermStatistical, r.inertia_stat_std_kg_m2, false, false},
          {kTermModelInadequacy, OrZero(r.model_inadequacy_std_kg_m2), false, false},
          {kTermBetweenRepeat, OrZero(r.repeat_scatter_std_kg_m2), false, false},
          {kTermAmplitudeCorrection, OrZero(r.amplitude_correction_std_kg_m2), false, false}};
}

std::string Percent(double fraction) {
  if (!std::isfinite(fraction)) return "?";  // a budget line that could not be computed
  char buffer[32];
  std::snprintf(buffer, sizeof(buffer), fraction < 0.001 ? "%.3f" : "%.2g", 100.0 * fraction);
  return buffer;
}

}  // namespace

double TotalUncertainty::Term(const std::string& name) const {
  for (const UncertaintyTerm& t : terms) {
    if (t.name == name) return t.std_kg_m2;
  }
  return 0.0;
}

TotalUncertainty ComposeTotalUncertainty(const TraceRecord& r) {
  TotalUncertainty u;
  u.terms = PerLogTerms(r);
  u.terms.push_back({kTermConfiguredInputs, ConfiguredInputsStd(r), true, r.budget_assumed});
  u.terms.push_back(
      {kTermCalibration,
       r.calibrated ? std::abs(r.calibration_relative_std * r.inertia_total_kg_m2) : 0.0, true,
       false});
  Finish(&u);
  return u;
}

TotalUncertainty ComposeAircraftUncertainty(const TraceRecord& r, double rig_std_kg_m2,
                                            bool rig_from_tare) {
  TotalUncertainty u;
  u.terms = PerLogTerms(r);
  const double share = rig_from_tare ? r.inertia_kg_m2 / r.inertia_total_kg_m2 : 1.0;
  u.terms.push_back(
      {kTermConfiguredInputs, share * ConfiguredInputsStd(r), true, r.budget_assumed});
  u.terms.push_back({kTermCalibration,
                     r.calibrated ? std::abs(r.calibration_relative_std * r.inertia_kg_m2) : 0.0,
                     true, false});
  u.terms.push_back({kTermRigInertia, OrZero(rig_std_kg_m2), true, false});
  Finish(&u);
  return u;
}

void UpdateTotalUncertainty(TraceRecord* r) {
  if (!std::isfinite(r->inertia_total_kg_m2)) {
    r->inertia_total_std_total_kg_m2 = NAN;
    return;
  }
  const double total = ComposeTotalUncertainty(*r).total_std_kg_m2;
  r->inertia_total_std_total_kg_m2 = std::isfinite(total) ? total : NAN;
}

double AssumedInputsRelativeStd(const TraceRecord& r) {
  double sum_sq = 0.0;
  bool any = false;
  for (const BudgetTerm& term : r.budget) {
    if (term.name == "filar_length" || term.name == "filar_separation") {
      sum_sq += OrZero(term.std_kg_m2) * OrZero(term.std_kg_m2);
      any = true;
    }
  }
  if (!any || !(r.inertia_total_kg_m2 > 0.0)) return NAN;
  return std::sqrt(sum_sq) / r.inertia_total_kg_m2;
}

namespace {
constexpr const char* kAssumedWarningStart = "rig.uncertainties is not set:";
}  // namespace

std::string AssumedInputsWarning(const TraceRecord& r) {
  double length = 0.0, separation = 0.0;
  for (const BudgetTerm& term : r.budget) {
    if (term.name == "filar_length") length = OrZero(term.std_kg_m2);
    if (term.name == "filar_separation") separation = OrZero(term.std_kg_m2);
  }
  const double i = r.inertia_total_kg_m2;
  return std::string(kAssumedWarningStart) +
         " the total counts an assumed tape-measure +-1 mm on L and on D, +-" +
         Percent(AssumedInputsRelativeStd(r)) + " % of I on this rig (D " +
         Percent(separation / i) + " %, L " + Percent(length / i) +
         " %); measure L and D and set rig.uncertainties (zeros count nothing), or calibrate the "
         "rig with a reference object";
}

bool IsAssumedInputsWarning(const std::string& warning) {
  return warning.rfind(kAssumedWarningStart, 0) == 0;
}

std::string AssumedInputsSummary(const std::vector<TraceRecord>& records) {
  double lo = INFINITY, hi = -INFINITY;
  int n = 0;
  for (const TraceRecord& r : records) {
    if (!std::isfinite(r.inertia_total_kg_m2) || !r.budget_assumed) continue;
    const double f = AssumedInputsRelativeStd(r);
    if (!std::isfinite(f)) continue;
    lo = std::min(lo, f);
    hi = std::max(hi, f);
    ++n;
  }
  if (n == 0) return "";
  const std::string range = Percent(lo) == Percent(hi)
                                ? "+-" + Percent(lo) + " %"
                                : "+-" + Percent(lo) + " to " + Percent(hi) + " %";
  return "note: rig.uncertainties is not set, so every total counts an assumed tape-measure "
         "+-1 mm on L and on D: " +
         range + " of I on this rig (" + std::to_string(n) + " fit" + (n == 1 ? "" : "s") +
         "). Measure L and D and set rig.uncertainties "
         "(configs/README.md; zeros count nothing), or calibrate the rig with a reference object.";
}

double WithCommonModeScale(double value, double std, double relative_std) {
  if (!std::isfinite(relative_std)) return std;
  return std::hypot(std, relative_std * std::abs(value));
}

std::string StatAndTotal(double value, double stat_std, double total_std, const char* unit) {
  char buffer[200];
  if (std::isfinite(total_std) && value != 0.0) {
    std::snprintf(buffer, sizeof(buffer), "%#.5g +- %#.2g (stat) +- %#.2g (total, %.2g %%) %s",
                  value, stat_std, total_std, 100.0 * total_std / std::abs(value), unit);
  } else {
    std::snprintf(buffer, sizeof(buffer), "%#.5g +- %#.2g (stat) %s", value, stat_std, unit);
  }
  return buffer;
}

}  // namespace bifilar

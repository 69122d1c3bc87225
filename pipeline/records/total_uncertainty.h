// The total uncertainty of a moment of inertia: a list of named 1-sigma terms combined in
// quadrature, composed here and nowhere else (docs/physics.md §5, docs/method.md §8). Every output
// that shows a number (results.json, `bifilar fit`, the --repeats line, traces.csv, angles.csv,
// Table 2, the report) reads the composition, so a new term (the rig calibration) is added once.
//
// Two kinds of term:
//   per-log      statistical (HAC, Birge-scaled), model inadequacy (the sweep's trend), between-
//                repeat (tau of `--repeats`), amplitude correction (its std, `--repeats`): what
//                differs from one log to the next. Their sum in
//                quadrature is the "stat" std, the record's inertia_total_std_kg_m2, which weights
//                the points of the ellipse fit exactly as before.
//   common-mode  configured inputs (the implicit-function budget of L, D, m, g, gyro scale),
//                calibration (rig.calibration's relative std), rig inertia (aircraft alone):
//                one error shared by every trace on the rig. Reported beside the stat std, never
//                in the ellipse's weights; the "total" adds them.
//
// Without `rig.uncertainties` the configured-inputs term counts an assumed tape-measure
// uncertainty of ±1 mm on L and on D (kAssumedLengthStdM), labelled as assumed.
#pragma once

#include <string>
#include <vector>

#include "pipeline/records/trace_record.h"

namespace bifilar {

// Term names, in the order of TotalUncertainty::terms.
constexpr const char* kTermStatistical = "statistical";           // HAC, Birge-scaled (per log)
constexpr const char* kTermModelInadequacy = "model_inadequacy";  // amplitude trend (per log)
constexpr const char* kTermBetweenRepeat = "between_repeat";      // tau of --repeats (per log)
// The std of the amplitude correction of --repeats (pooled c moved to zero amplitude; per log).
constexpr const char* kTermAmplitudeCorrection = "amplitude_correction";
constexpr const char* kTermConfiguredInputs = "configured_inputs";  // L, D, m, g, gyro scale
constexpr const char* kTermCalibration = "calibration";             // rig.calibration (0: none)
constexpr const char* kTermRigInertia = "rig_inertia";  // tare/value std (aircraft alone)

struct UncertaintyTerm {
  std::string name;          // one of the kTerm* names
  double std_kg_m2 = 0.0;    // 1-sigma contribution to the moment (kg m^2); >= 0, NaN unknown
  bool common_mode = false;  // shared by every trace of the rig (not in the ellipse's weights)
  bool assumed = false;      // holds the assumed ±1 mm on L and D (no rig.uncertainties)
};

struct TotalUncertainty {
  std::vector<UncertaintyTerm> terms;  // every term, zero ones included, in the kTerm* order
  double stat_std_kg_m2 = NAN;         // per-log terms in quadrature
  double common_mode_std_kg_m2 = NAN;  // common-mode terms in quadrature
  double total_std_kg_m2 = NAN;        // all terms in quadrature
  bool assumed = false;                // a term holds an assumption

  double Term(const std::string& name) const;  // a term's std (0 when absent)
};

// The total of a record's inertia_total_kg_m2 (everything suspended) from its fields:
// inertia_stat_std_kg_m2, model_inadequacy_std_kg_m2, repeat_scatter_std_kg_m2 (NaN: 0), the
// budget (without its L, D and g lines when calibrated: the calibration fixes the effective
// geometry) and calibration_relative_std.
TotalUncertainty ComposeTotalUncertainty(const TraceRecord& record);

// The total of a campaign record's inertia_kg_m2 (aircraft alone, I_total - I_rig): the per-log
// terms as above, the rig inertia's std, and the scale terms (configured inputs, calibration).
// A rig measured on the same rig (tare logs) shares the scale error, so the scale terms move the
// difference by the same fraction (term / I_total x I_aircraft); a rig inertia given as a value
// or a table does not, and the terms carry whole (kg m^2).
TotalUncertainty ComposeAircraftUncertainty(const TraceRecord& record, double rig_std_kg_m2,
                                            bool rig_from_tare);

// Sets record->inertia_total_std_total_kg_m2 from ComposeTotalUncertainty (NaN without a fit).
void UpdateTotalUncertainty(TraceRecord* record);

// What the assumed ±1 mm on L and D adds to I on this rig (fraction of I), from the record's
// budget lines of L and D; NaN when the record has none.
double AssumedInputsRelativeStd(const TraceRecord& record);

// The warning every record carries without `rig.uncertainties` (flag kAssumedInputsFlag).
constexpr const char* kAssumedInputsFlag = "assumed_input_uncertainties";
std::string AssumedInputsWarning(const TraceRecord& record);
bool IsAssumedInputsWarning(const std::string& warning);

// The run summary's one line about the assumption over `records` (ok ones with the flag); ""
// when no record carries it.
std::string AssumedInputsSummary(const std::vector<TraceRecord>& records);

// Table 2's total std of a moment of the ellipse: its std (statistical, rig offset included)
// and the common-mode scale fraction of the campaign in quadrature, hypot(std, relative x
// |value|); `std` itself when the relative is not finite.
double WithCommonModeScale(double value, double std, double relative_std);

// "I = 1.5234e-05 +- 2.1e-09 (stat) +- 1.0e-06 (total, 6.7 %) kg m^2": the console's form of a
// value with both stds (printf formats of the value and the stds; `unit` appended).
std::string StatAndTotal(double value, double stat_std, double total_std, const char* unit);

}  // namespace bifilar

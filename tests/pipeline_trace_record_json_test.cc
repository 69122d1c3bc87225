// One writer and one reader of the trace record (issue 24 item 5): TraceRecordFromJson, the
// cache's and the report's reader, gives back bit for bit every field TraceRecordToJson writes,
// in both its forms (the campaign's and the fit's), for records of every kind (ok, rejected,
// error; tare and calibration; with and without a sweep; warnings; NaN); the keys it reads are
// the keys the writer writes, less the ones it composes from the fields (DerivedTraceKeys), so a
// read of a key the writer never writes fails here; a record that lacks a key or holds one of
// another type is refused naming the key. On real output: the committed sample's results.json. The
// same for the calibration and summary sections.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <limits>
#include <map>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "base/user_error.h"
#include "pipeline/records/results_json.h"
#include "pipeline/records/results_reader.h"
#include "pipeline/records/total_uncertainty.h"
#include "test_support.h"

namespace bifilar {
namespace {

using nlohmann::json;
using test_support::ReadFile;

// Numbers whose decimal form is long (a third, the smallest normal, a negative zero): they show
// that the text in between loses no bit.
constexpr double kThird = 1.0 / 3.0;
const double kTiny = std::numeric_limits<double>::min();

AmplitudeSweep EvaluatedSweep() {
  AmplitudeSweep s;
  s.evaluated = true;
  s.note = "3 bands of 4 cycles";
  for (int k = 0; k < 3; ++k) {
    AmplitudeSweepBand b;
    b.t0_s = 6.5 + 10 * k + kThird;
    b.t1_s = 16.5 + 10 * k;
    b.num_samples = 1000 + k;
    b.cycles = 4.0 + kThird;
    b.amplitude_start_deg = 29.1 - 5 * k;
    b.amplitude_end_deg = 24.3 - 5 * k;
    b.amplitude_mean_deg = 26.7 - 5 * k;
    b.ok = k != 1;  // a failed band in the middle: its I is written null
    b.inertia_kg_m2 = b.ok ? 4.05 + k * 1e-4 : 0.0;
    b.inertia_std_kg_m2 = b.ok ? 2.1e-5 * (k + 1) : 0.0;
    s.bands.push_back(b);
  }
  s.low_band = 2;
  s.trend_exponent = 1.0;
  s.trend_coeff = 4.4e-5 + kTiny;
  s.trend_coeff_std = 1.1e-5;
  s.trend_z = 4.1;
  s.trend_chi2 = 0.7;
  s.trend_dof = 1;
  s.trend_scale = 1.0;
  s.std_scale = 1.3;
  s.trend_percent_per_10deg = 0.127;
  s.inertia_zero_amplitude_kg_m2 = 4.04;
  s.trend_detected = true;
  return s;
}

// An ok aircraft record with every field set (finite where the writer writes a number).
TraceRecord FullRecord() {
  TraceRecord r;
  r.file = "pitch_20/trial_2.csv.gz";
  r.status = TraceStatus::kOk;
  r.message = "";
  r.inertia_total_kg_m2 = 4.050213 + kThird * 1e-7;
  r.inertia_total_std_kg_m2 = 5.8e-3;
  r.drag_coeff_kg_m2 = -0.0;
  r.viscous_coeff_kg_m2_per_s = 1.7e-4;
  r.window_s = {6.56, 47.28};
  r.amplitude_deg = {29.1, 24.3};
  r.amplitude_band_deg = {0.0, 30.0};
  r.period_s = 2.4914;
  r.frequency_hz = 1.0 / 2.4914;
  r.small_angle_inertia_total_kg_m2 = 4.215;
  r.bias_rad_per_s = -3.2e-4;
  r.residual_rms_rad_per_s = 2.1e-3;
  r.noise_rms_rad_per_s = 2.0e-3;
  r.pitch_measured_deg = 20.3;
  r.roll_measured_deg = -0.4;
  r.model = "full";
  r.iterations = 17;
  r.fit_seconds = 0.041;
  r.budget = {{"filar_length", 1.2e-4},
              {"filar_separation", 2.6e-2},
              {"mass", 3.3e-3},
              {"gravity", 4.0e-5},
              {"gyro_scale", kTiny}};
  r.budget_total_std_kg_m2 = 2.7e-2;
  r.flags = {"amplitude_trend", kAssumedInputsFlag};
  r.warnings = {
      "I changes with amplitude (+0.127 % per 10 deg, z = 4.1): the rig departs from "
      "the model; swing lower, or set fit.max_amplitude_deg (--max-amplitude). Detail.",
      "second warning"};
  r.figure = "e66b1c80ca5f617c.svg";
  r.figures = {"/out/figures/e66b1c80ca5f617c.svg", "/out/figures/e66b1c80ca5f617c_sweep.svg"};
  r.sweep_figure = "e66b1c80ca5f617c_sweep.svg";
  r.swing_axis_in_imu = {0.01, -0.02, 0.9997};
  r.secondary_motion_ratio = 0.003;
  r.rms_over_noise = 1.05;
  r.residual_autocorr_lag1 = 0.31;
  r.residual_ar1_phi = 0.30;
  r.prewhitened_autocorr_max = 0.12;
  r.inertia_window_kg_m2 = 4.06;
  r.inertia_source = "low_amplitude_band";
  r.inertia_stat_std_kg_m2 = 1.6e-4;
  r.inertia_iid_std_kg_m2 = 0.9e-4;
  r.model_inadequacy_std_kg_m2 = 5.8e-3;
  r.repeat_scatter_std_kg_m2 = 2.2e-4;
  r.amplitude_correction_kg_m2 = 1.1e-3;
  r.amplitude_correction_std_kg_m2 = 3.0e-4;
  r.amplitude_correction_from_deg = 26.7;
  r.budget_assumed = true;
  r.calibrated = true;
  r.calibration_relative_std = 0.0021;
  r.hac_bandwidth = 5;
  r.sweep = EvaluatedSweep();
  UpdateTotalUncertainty(&r);
  r.inertia_total_std_total_kg_m2 += kTiny;  // read back as written, not composed again
  r.role = TraceRole::kAircraft;
  r.content_hash = "0123456789abcdef";
  r.cache_key = "fedcba9876543210";
  r.from_cache = true;
  r.pitch_nominal_deg = 20.0;
  r.pitch_used_deg = 20.0;
  r.roll_nominal_deg = 0.0;
  r.roll_used_deg = 0.0;
  r.rig_inertia_kg_m2 = 0.25;
  r.inertia_kg_m2 = r.inertia_total_kg_m2 - 0.25;
  r.inertia_std_kg_m2 = 5.9e-3;
  r.inertia_std_total_kg_m2 = 1.1e-2;
  r.aircraft_scale_std_kg_m2 = 9.0e-3;
  return r;
}

// A record of each kind the pipeline writes.
std::vector<TraceRecord> Records() {
  std::vector<TraceRecord> out;
  out.push_back(FullRecord());
  TraceRecord rejected = FullRecord();  // a fit, rejected; no sweep, no --repeats terms
  rejected.status = TraceStatus::kRejected;
  rejected.message = "pitch_20/trial_2.csv.gz: rejected: rms/noise 3.1 > 2";
  rejected.sweep = AmplitudeSweep();
  rejected.sweep.note = "too few cycles for two bands";
  rejected.repeat_scatter_std_kg_m2 = NAN;
  rejected.amplitude_correction_kg_m2 = NAN;
  rejected.amplitude_correction_std_kg_m2 = NAN;
  rejected.amplitude_correction_from_deg = NAN;
  rejected.budget_assumed = false;
  rejected.calibrated = false;
  rejected.window_s = {6.5, NAN};  // a pair with one end unknown is written null
  rejected.pitch_measured_deg.reset();
  rejected.roll_nominal_deg.reset();
  out.push_back(rejected);
  TraceRecord error;  // nothing fitted: every number NaN, every list empty
  error.file = "pitch_0/broken.csv";
  error.status = TraceStatus::kError;
  error.message = "pitch_0/broken.csv: line 3: not a number";
  out.push_back(error);
  TraceRecord tare = FullRecord();
  tare.file = "tare/tare_1.csv.gz";
  tare.role = TraceRole::kTare;
  tare.warnings.clear();
  tare.flags.clear();
  tare.inertia_kg_m2 = NAN;
  out.push_back(tare);
  TraceRecord calibration = FullRecord();
  calibration.file = "calibration/reference_1.csv";
  calibration.role = TraceRole::kCalibration;
  calibration.swing_axis_in_imu = {NAN, NAN, NAN};
  out.push_back(calibration);
  return out;
}

bool SameBits(double a, double b) {
  return (std::isnan(a) && std::isnan(b)) || std::memcmp(&a, &b, sizeof(double)) == 0;
}

#define EXPECT_SAME_BITS(field) \
  EXPECT_TRUE(SameBits(a.field, b.field)) << #field << ": " << a.field << " against " << b.field

// Every field TraceRecordToJson writes (the campaign's only with `campaign_fields`), compared bit
// for bit; the budget's terms by name (results.json holds them as an object, in name order).
void ExpectSameRecord(const TraceRecord& a, const TraceRecord& b, bool campaign_fields) {
  EXPECT_EQ(a.file, b.file);
  EXPECT_EQ(a.status, b.status);
  EXPECT_EQ(a.message, b.message);
  EXPECT_SAME_BITS(inertia_total_kg_m2);
  EXPECT_SAME_BITS(inertia_total_std_kg_m2);
  EXPECT_SAME_BITS(drag_coeff_kg_m2);
  EXPECT_SAME_BITS(viscous_coeff_kg_m2_per_s);
  const bool window = std::isfinite(a.window_s[0]) && std::isfinite(a.window_s[1]);
  for (int k = 0; k < 2; ++k) {
    // A pair with an unknown end is written null: both ends read back NaN.
    EXPECT_TRUE(window ? SameBits(a.window_s[k], b.window_s[k]) : std::isnan(b.window_s[k]));
    EXPECT_SAME_BITS(amplitude_deg[k]);
    EXPECT_SAME_BITS(amplitude_band_deg[k]);
  }
  EXPECT_SAME_BITS(period_s);
  EXPECT_SAME_BITS(frequency_hz);
  EXPECT_SAME_BITS(small_angle_inertia_total_kg_m2);
  EXPECT_SAME_BITS(bias_rad_per_s);
  EXPECT_SAME_BITS(residual_rms_rad_per_s);
  EXPECT_SAME_BITS(noise_rms_rad_per_s);
  EXPECT_EQ(a.pitch_measured_deg, b.pitch_measured_deg);
  EXPECT_EQ(a.roll_measured_deg, b.roll_measured_deg);
  EXPECT_EQ(a.model, b.model);
  EXPECT_EQ(a.iterations, b.iterations);
  EXPECT_SAME_BITS(fit_seconds);
  std::map<std::string, double> terms_a, terms_b;
  for (const BudgetTerm& t : a.budget) terms_a[t.name] = t.std_kg_m2;
  for (const BudgetTerm& t : b.budget) terms_b[t.name] = t.std_kg_m2;
  ASSERT_EQ(terms_a.size(), terms_b.size());
  for (const auto& [name, value] : terms_a) EXPECT_TRUE(SameBits(value, terms_b[name])) << name;
  EXPECT_SAME_BITS(budget_total_std_kg_m2);
  EXPECT_EQ(a.flags, b.flags);
  EXPECT_EQ(a.warnings, b.warnings);
  EXPECT_EQ(a.figure, b.figure);
  EXPECT_EQ(a.figures, b.figures);
  EXPECT_EQ(a.sweep_figure, b.sweep_figure);
  for (int k = 0; k < 3; ++k) {
    // Written null when its first component is unknown.
    EXPECT_TRUE(std::isfinite(a.swing_axis_in_imu[0])
                    ? SameBits(a.swing_axis_in_imu[k], b.swing_axis_in_imu[k])
                    : std::isnan(b.swing_axis_in_imu[k]));
  }
  EXPECT_SAME_BITS(secondary_motion_ratio);
  EXPECT_SAME_BITS(rms_over_noise);
  EXPECT_SAME_BITS(residual_autocorr_lag1);
  EXPECT_SAME_BITS(residual_ar1_phi);
  EXPECT_SAME_BITS(prewhitened_autocorr_max);
  EXPECT_SAME_BITS(inertia_window_kg_m2);
  EXPECT_EQ(a.inertia_source, b.inertia_source);
  EXPECT_SAME_BITS(inertia_stat_std_kg_m2);
  EXPECT_SAME_BITS(inertia_iid_std_kg_m2);
  EXPECT_SAME_BITS(model_inadequacy_std_kg_m2);
  EXPECT_SAME_BITS(repeat_scatter_std_kg_m2);
  EXPECT_SAME_BITS(amplitude_correction_kg_m2);
  if (std::isfinite(a.amplitude_correction_kg_m2)) {  // written only with the correction
    EXPECT_SAME_BITS(amplitude_correction_std_kg_m2);
    EXPECT_SAME_BITS(amplitude_correction_from_deg);
  }
  EXPECT_SAME_BITS(inertia_total_std_total_kg_m2);
  EXPECT_EQ(a.budget_assumed, b.budget_assumed);
  EXPECT_EQ(a.calibrated, b.calibrated);
  EXPECT_SAME_BITS(calibration_relative_std);
  EXPECT_EQ(a.hac_bandwidth, b.hac_bandwidth);
  const AmplitudeSweep &s = a.sweep, &t = b.sweep;
  EXPECT_EQ(s.evaluated, t.evaluated);
  EXPECT_EQ(s.note, t.note);
  ASSERT_EQ(s.bands.size(), t.bands.size());
  for (size_t k = 0; k < s.bands.size(); ++k) {
    const AmplitudeSweepBand &x = s.bands[k], &y = t.bands[k];
    EXPECT_TRUE(SameBits(x.t0_s, y.t0_s) && SameBits(x.t1_s, y.t1_s)) << k;
    EXPECT_EQ(x.num_samples, y.num_samples);
    EXPECT_TRUE(SameBits(x.cycles, y.cycles)) << k;
    EXPECT_TRUE(SameBits(x.amplitude_start_deg, y.amplitude_start_deg)) << k;
    EXPECT_TRUE(SameBits(x.amplitude_end_deg, y.amplitude_end_deg)) << k;
    EXPECT_TRUE(SameBits(x.amplitude_mean_deg, y.amplitude_mean_deg)) << k;
    EXPECT_EQ(x.ok, y.ok);
    if (x.ok) {  // a failed band's I is written null
      EXPECT_TRUE(SameBits(x.inertia_kg_m2, y.inertia_kg_m2)) << k;
      EXPECT_TRUE(SameBits(x.inertia_std_kg_m2, y.inertia_std_kg_m2)) << k;
    }
  }
  EXPECT_EQ(s.low_band, t.low_band);
  if (s.evaluated) {  // the trend is written only for an evaluated sweep
    EXPECT_TRUE(SameBits(s.trend_exponent, t.trend_exponent));
    EXPECT_TRUE(SameBits(s.trend_coeff, t.trend_coeff));
    EXPECT_TRUE(SameBits(s.trend_coeff_std, t.trend_coeff_std));
    EXPECT_TRUE(SameBits(s.trend_z, t.trend_z));
    EXPECT_TRUE(SameBits(s.trend_chi2, t.trend_chi2));
    EXPECT_EQ(s.trend_dof, t.trend_dof);
    EXPECT_TRUE(SameBits(s.trend_scale, t.trend_scale));
    EXPECT_TRUE(SameBits(s.std_scale, t.std_scale));
    EXPECT_TRUE(SameBits(s.trend_percent_per_10deg, t.trend_percent_per_10deg));
    EXPECT_TRUE(SameBits(s.inertia_zero_amplitude_kg_m2, t.inertia_zero_amplitude_kg_m2));
    EXPECT_EQ(s.trend_detected, t.trend_detected);
  }
  if (!campaign_fields) return;
  EXPECT_EQ(a.role, b.role);
  EXPECT_EQ(a.content_hash, b.content_hash);
  EXPECT_EQ(a.cache_key, b.cache_key);
  EXPECT_EQ(a.from_cache, b.from_cache);
  EXPECT_EQ(a.pitch_nominal_deg, b.pitch_nominal_deg);
  EXPECT_SAME_BITS(pitch_used_deg);
  EXPECT_EQ(a.roll_nominal_deg, b.roll_nominal_deg);
  EXPECT_SAME_BITS(roll_used_deg);
  EXPECT_SAME_BITS(rig_inertia_kg_m2);
  EXPECT_SAME_BITS(inertia_kg_m2);
  EXPECT_SAME_BITS(inertia_std_kg_m2);
  EXPECT_SAME_BITS(inertia_std_total_kg_m2);
  EXPECT_SAME_BITS(aircraft_scale_std_kg_m2);
}

TEST(TraceRecordJson, ReaderGivesBackEveryFieldTheWriterWritesBitForBit) {
  for (const bool campaign_fields : {true, false}) {
    for (const TraceRecord& r : Records()) {
      SCOPED_TRACE(r.file + (campaign_fields ? " (campaign)" : " (fit)"));
      // Through text, as the cache and results.json hold it.
      const json written = TraceRecordToJson(r, campaign_fields);
      const TraceRecord back = TraceRecordFromJson(json::parse(written.dump()), campaign_fields);
      ExpectSameRecord(r, back, campaign_fields);
      // And the record read writes the same text again: no key is lost or changed.
      EXPECT_EQ(TraceRecordToJson(back, campaign_fields).dump(), written.dump());
    }
  }
}

TEST(TraceRecordJson, TheReaderReadsExactlyTheKeysTheWriterWrites) {
  for (const bool campaign_fields : {true, false}) {
    KeyLog written, read;
    for (const TraceRecord& r : Records()) {
      const json j = TraceRecordToJson(r, campaign_fields);
      const KeyLog w = KeyPaths(j);
      written.insert(w.begin(), w.end());
      TraceRecordFromJson(j, campaign_fields, &read);
    }
    // Reading a key the writer never writes (a misspelt key, one of an older version).
    for (const std::string& key : read)
      EXPECT_EQ(written.count(key), 1u) << key << " is never written";
    // A key written and neither read nor composed from the fields (a field the reader forgot).
    for (const std::string& key : written) {
      EXPECT_TRUE(read.count(key) == 1 || DerivedTraceKeys().count(key) == 1)
          << key << " is written and never read";
    }
    // The list of composed keys names keys the writer writes.
    for (const std::string& key : DerivedTraceKeys()) EXPECT_EQ(written.count(key), 1u) << key;
    EXPECT_EQ(read.count("role"), campaign_fields ? 1u : 0u);
    // The two keys pipeline/store/output_set.cc reads by hand from results.json's traces (the
    // files a folder's manifest adopts and the mixed-set check): written.
    EXPECT_EQ(written.count("cache_key"), campaign_fields ? 1u : 0u);
    EXPECT_EQ(written.count("figure"), 1u);
  }
}

// A record without one of the keys the writer always writes, or with a value of another type, is
// refused naming the key, for each such key (no silent NaN, no crash).
TEST(TraceRecordJson, AMissingOrMistypedKeyIsRefusedNamingIt) {
  const json full = TraceRecordToJson(FullRecord(), true);
  KeyLog read;
  TraceRecordFromJson(full, true, &read);
  int refused = 0;
  for (const std::string& key : read) {
    if (key.find("[]") != std::string::npos || key.rfind("budget.", 0) == 0) continue;
    // Written only sometimes: absent is a valid record.
    if (key == "uncertainty.repeat_scatter_kg_m2" || key == "amplitude_correction") continue;
    json without = full;
    const size_t dot = key.find('.');
    json& parent = dot == std::string::npos ? without : without[key.substr(0, dot)];
    parent.erase(dot == std::string::npos ? key : key.substr(dot + 1));
    const std::string error = test_support::ErrorOf([&] { TraceRecordFromJson(without, true); });
    EXPECT_EQ(error, "'" + key + "' is missing") << key;
    ++refused;
  }
  EXPECT_GT(refused, 60);
  json mistyped = full;
  mistyped["uncertainty"]["hac_bandwidth"] = "five";
  EXPECT_EQ(test_support::ErrorOf([&] { TraceRecordFromJson(mistyped, true); }),
            "'uncertainty.hac_bandwidth' is not a whole number (string)");
  mistyped = full;
  mistyped["amplitude_sweep"]["bands"][0]["window_s"] = json::array({1.0});
  EXPECT_EQ(test_support::ErrorOf([&] { TraceRecordFromJson(mistyped, true); }),
            "'amplitude_sweep.bands[].window_s' is not a pair of numbers (array)");
  mistyped = full;
  mistyped["amplitude_sweep"]["low_band"] = 7;
  EXPECT_NE(test_support::ErrorOf([&] {
              TraceRecordFromJson(mistyped, true);
            }).find("'amplitude_sweep.low_band' = 7 is not a band's index"),
            std::string::npos);
  mistyped = full;
  mistyped["status"] = "fine";
  EXPECT_EQ(test_support::ErrorOf([&] { TraceRecordFromJson(mistyped, true); }),
            "'status' is not ok, rejected or error");
  // The fit's form has no campaign fields: read as the campaign's, its first is missing.
  EXPECT_EQ(test_support::ErrorOf(
                [&] { TraceRecordFromJson(TraceRecordToJson(FullRecord(), false), true); }),
            "'role' is missing");
}

// The calibration and summary sections have one typed reader each too (the report's): every
// field written comes back bit for bit, and the keys read are the keys written.
TEST(ResultsSectionsJson, CalibrationAndSummaryReadBackEveryFieldAndOnlyWrittenKeys) {
  RigCalibrationResult c;
  c.applied = true;
  c.factor = 1.0 + kThird * 0.09;
  c.factor_std = 4.1e-4;
  c.factor_rel_std = 4.0e-4;
  c.rel_std_reference = 3.0e-4;
  c.rel_std_swings = 2.0e-4;
  c.rel_std_rig = kTiny;
  c.filar_length_m = 1.5;
  c.nominal_separation_m = 0.5;
  c.effective_separation_m = 0.5 * std::sqrt(c.factor);
  c.nominal_d2_over_l_m = 0.25 / 1.5;
  c.effective_d2_over_l_m = c.nominal_d2_over_l_m * c.factor;
  c.reference_inertia_kg_m2 = 0.2;
  c.reference_inertia_std_kg_m2 = 1e-4;
  c.reference_mass_kg = 2.0;
  c.n_swings = 3;
  c.swings_total_kg_m2 = 0.2312;
  c.swings_total_std_kg_m2 = 2.2e-5;
  c.swings_scatter_kg_m2 = NAN;  // one swing: written null
  c.rig_inertia_source = "tare";
  c.rig_inertia_kg_m2 = 0.0312;
  c.rig_inertia_std_kg_m2 = 1.1e-5;
  c.iterations = 2;
  c.logs = {"calibration/plate_1.csv", "calibration/plate_2.csv", "calibration/plate_3.csv"};
  c.warnings = {"rig.calibration: the factor k = 1.03 moves D^2/L by +3.0 %"};
  const json written = CalibrationToJson(c);
  KeyLog read;
  const RigCalibrationResult b = CalibrationFromJson(json::parse(written.dump()), &read);
  EXPECT_EQ(read, KeyPaths(written));
  EXPECT_EQ(CalibrationToJson(b).dump(), written.dump());
  EXPECT_EQ(b.applied, c.applied);
  for (const auto& [x, y] : std::vector<std::pair<double, double>>{
           {b.factor, c.factor},
           {b.factor_std, c.factor_std},
           {b.factor_rel_std, c.factor_rel_std},
           {b.rel_std_reference, c.rel_std_reference},
           {b.rel_std_swings, c.rel_std_swings},
           {b.rel_std_rig, c.rel_std_rig},
           {b.filar_length_m, c.filar_length_m},
           {b.nominal_separation_m, c.nominal_separation_m},
           {b.effective_separation_m, c.effective_separation_m},
           {b.nominal_d2_over_l_m, c.nominal_d2_over_l_m},
           {b.effective_d2_over_l_m, c.effective_d2_over_l_m},
           {b.reference_inertia_kg_m2, c.reference_inertia_kg_m2},
           {b.reference_inertia_std_kg_m2, c.reference_inertia_std_kg_m2},
           {b.reference_mass_kg, c.reference_mass_kg},
           {b.swings_total_kg_m2, c.swings_total_kg_m2},
           {b.swings_total_std_kg_m2, c.swings_total_std_kg_m2},
           {b.swings_scatter_kg_m2, c.swings_scatter_kg_m2},
           {b.rig_inertia_kg_m2, c.rig_inertia_kg_m2},
           {b.rig_inertia_std_kg_m2, c.rig_inertia_std_kg_m2}}) {
    EXPECT_TRUE(SameBits(x, y)) << x << " against " << y;
  }
  EXPECT_EQ(b.n_swings, c.n_swings);
  EXPECT_EQ(b.rig_inertia_source, c.rig_inertia_source);
  EXPECT_EQ(b.iterations, c.iterations);
  EXPECT_EQ(b.logs, c.logs);
  EXPECT_EQ(b.warnings, c.warnings);
  json without = written;
  without["swings"].erase("n");
  EXPECT_EQ(test_support::ErrorOf([&] { CalibrationFromJson(without); }), "'swings.n' is missing");

  CampaignSummary s;
  s.n_traces = 57;
  s.n_ok = 55;
  s.n_rejected = 1;
  s.n_error = 1;
  s.n_fitted = 40;
  s.n_reused = 17;
  s.wall_s = 2.32 + kTiny;
  s.ellipse_fitted = true;
  s.ellipse_message = "";
  s.tensor_fitted = false;
  s.tensor_message = "a pitch-only campaign";
  s.exit_code = 1;
  const json summary = CampaignSummaryToJson(s);
  KeyLog summary_read;
  const CampaignSummary t = CampaignSummaryFromJson(json::parse(summary.dump()), &summary_read);
  EXPECT_EQ(summary_read, KeyPaths(summary));
  EXPECT_EQ(CampaignSummaryToJson(t).dump(), summary.dump());
  EXPECT_TRUE(SameBits(t.wall_s, s.wall_s));
  EXPECT_EQ(t.n_reused, 17);
  EXPECT_EQ(t.tensor_message, s.tensor_message);
}

// A copy of a written record without the keys composed from its fields (DerivedTraceKeys).
json WithoutDerivedKeys(json j) {
  for (const std::string& key : DerivedTraceKeys()) {
    const size_t dot = key.find('.');
    if (key.find("[]") != std::string::npos || !j.contains(key.substr(0, dot))) continue;
    j[key.substr(0, dot)].erase(key.substr(dot + 1));
  }
  return j;
}

// Real output: every trace of the committed sample's results.json reads, and writes back the same
// text for every key read (what `bifilar report` reads of it is all there, typed). The composed
// keys within 1e-15 relative: sample_runs/prandtl_d/out may predate the budget's sum in name
// order (ConfiguredInputsStd), which moved them by a bit at most.
TEST(TraceRecordJson, CommittedSampleTracesReadAndWriteBackUnchanged) {
  const json results = json::parse(
      ReadFile(std::string(BIFILAR_SOURCE_DIR) + "/sample_runs/prandtl_d/out/results.json"));
  ASSERT_EQ(results["traces"].size(), 57u);
  for (const json& trace : results["traces"]) {
    const TraceRecord r = TraceRecordFromJson(trace, true);
    const json back = TraceRecordToJson(r, true);
    EXPECT_EQ(WithoutDerivedKeys(back).dump(), WithoutDerivedKeys(trace).dump()) << r.file;
    for (const char* key : {"stat_kg_m2", "common_mode_kg_m2", "total_kg_m2", "total_percent"}) {
      const double a = back["uncertainty"][key].get<double>(),
                   b = trace["uncertainty"][key].get<double>();
      EXPECT_NEAR(a, b, 1e-15 * std::abs(b)) << r.file << " uncertainty." << key;
    }
  }
}

}  // namespace
}  // namespace bifilar

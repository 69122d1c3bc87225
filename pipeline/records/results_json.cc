#include "pipeline/records/results_json.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <limits>
#include <optional>
#include <sstream>
#include <thread>

#include "base/json_number.h"
#include "base/user_error.h"
#include "base/version.h"
#include "pipeline/records/tensor_json.h"
#include "pipeline/records/total_uncertainty.h"

namespace bifilar {
namespace {

using nlohmann::json;

json Pair(const std::array<double, 2>& v) {
  if (!std::isfinite(v[0]) || !std::isfinite(v[1])) return json(nullptr);
  return json::array({v[0], v[1]});
}

// One object of a trace record being read (TraceRecordFromJson): a key is required unless read
// through Has(); each key read is logged with its path; a value of another type throws UserError
// naming the path. null reads as NaN (numbers) or none (optional numbers), as JsonNumber writes
// a NaN.
class RecordNode {
 public:
  RecordNode(const json& node, std::string path, KeyLog* log)
      : node_(node), path_(std::move(path)), log_(log) {}

  // Logs `key`; true when it is present (a key the writer writes only sometimes).
  bool Has(const char* key) const {
    Log(key);
    return node_.contains(key);
  }
  double Num(const char* key) const {
    const json& v = At(key);
    if (v.is_null()) return NAN;
    if (!v.is_number()) Mistyped(key, "a number", v);
    return v.get<double>();
  }
  std::optional<double> OptionalNum(const char* key) const {
    const double v = Num(key);
    return std::isnan(v) ? std::nullopt : std::optional<double>(v);
  }
  int Int(const char* key) const {
    const json& v = At(key);
    if (!v.is_number_integer()) Mistyped(key, "a whole number", v);
    return v.get<int>();
  }
  bool Bool(const char* key) const {
    const json& v = At(key);
    if (!v.is_boolean()) Mistyped(key, "true or false", v);
    return v.get<bool>();
  }
  std::string Str(const char* key) const {
    const json& v = At(key);
    if (!v.is_string()) Mistyped(key, "text", v);
    return v.get<std::string>();
  }
  std::vector<std::string> Strs(const char* key) const {
    const json& v = At(key);
    if (!v.is_array()) Mistyped(key, "a list of texts", v);
    std::vector<std::string> out;
    for (const json& e : v) {
      if (!e.is_string()) Mistyped(key, "a list of texts", v);
      out.push_back(e.get<std::string>());
    }
    return out;
  }
  // N numbers (null elements NaN), or null (all NaN) as the writer's Pair and swing axis write.
  template <size_t N>
  std::array<double, N> Numbers(const char* key) const {
    std::array<double, N> out;
    out.fill(NAN);
    const json& v = At(key);
    if (v.is_null()) return out;
    if (!v.is_array() || v.size() != N)
      Mistyped(key, N == 2 ? "a pair of numbers" : "3 numbers", v);
    for (size_t k = 0; k < N; ++k) {
      if (!v[k].is_number() && !v[k].is_null()) Mistyped(key, "a list of numbers", v);
      if (v[k].is_number()) out[k] = v[k].get<double>();
    }
    return out;
  }
  RecordNode Object(const char* key) const {
    const json& v = At(key);
    if (!v.is_object()) Mistyped(key, "an object", v);
    return RecordNode(v, Where(key), log_);
  }
  std::vector<RecordNode> Objects(const char* key) const {
    const json& v = At(key);
    if (!v.is_array()) Mistyped(key, "a list", v);
    std::vector<RecordNode> out;
    for (const json& e : v) {
      if (!e.is_object()) Mistyped(key, "a list of objects", v);
      out.emplace_back(e, Where(key) + "[]", log_);
    }
    return out;
  }
  // Every key of this object with its value (the budget, whose keys are the terms' names).
  const json& node() const { return node_; }
  void Log(const std::string& key) const {
    if (log_ != nullptr) log_->insert(Where(key));
  }

 private:
  std::string Where(const std::string& key) const {
    return path_.empty() ? key : path_ + "." + key;
  }
  const json& At(const char* key) const {
    Log(key);
    const auto it = node_.find(key);
    if (it == node_.end()) throw UserError("'" + Where(key) + "' is missing");
    return *it;
  }
  [[noreturn]] void Mistyped(const char* key, const char* expected, const json& v) const {
    throw UserError("'" + Where(key) + "' is not " + expected + " (" + v.type_name() + ")");
  }
  const json& node_;
  std::string path_;
  KeyLog* log_;
};
json SweepToJson(const AmplitudeSweep& s) {
  json bands = json::array();
  for (const AmplitudeSweepBand& b : s.bands) {
    bands.push_back({{"window_s", json::array({b.t0_s, b.t1_s})},
                     {"samples", b.num_samples},
                     {"cycles", JsonNumber(b.cycles)},
                     {"amplitude_deg", json::array({JsonNumber(b.amplitude_start_deg),
                                                    JsonNumber(b.amplitude_end_deg)})},
                     {"amplitude_mean_deg", JsonNumber(b.amplitude_mean_deg)},
                     {"inertia_kg_m2", b.ok ? JsonNumber(b.inertia_kg_m2) : json(nullptr)},
                     {"inertia_std_kg_m2", b.ok ? JsonNumber(b.inertia_std_kg_m2) : json(nullptr)},
                     {"ok", b.ok}});
  }
  json j = {
      {"evaluated", s.evaluated}, {"note", s.note}, {"bands", bands}, {"low_band", s.low_band}};
  if (s.evaluated) {
    j["trend_exponent"] = JsonNumber(s.trend_exponent);
    j["trend_coeff_per_deg_p"] = JsonNumber(s.trend_coeff);
    j["trend_coeff_std_per_deg_p"] = JsonNumber(s.trend_coeff_std);
    j["trend_z"] = JsonNumber(s.trend_z);
    j["trend_chi2"] = JsonNumber(s.trend_chi2);
    j["trend_dof"] = s.trend_dof;
    j["trend_scale"] = JsonNumber(s.trend_scale);
    j["std_scale"] = JsonNumber(s.std_scale);
    j["trend_percent_per_10deg"] = JsonNumber(s.trend_percent_per_10deg);
    j["inertia_zero_amplitude_kg_m2"] = JsonNumber(s.inertia_zero_amplitude_kg_m2);
    j["trend_detected"] = s.trend_detected;
  }
  return j;
}

AmplitudeSweepBand SweepBandFromJson(const RecordNode& b) {
  AmplitudeSweepBand band;
  const std::array<double, 2> w = b.Numbers<2>("window_s");
  const std::array<double, 2> a = b.Numbers<2>("amplitude_deg");
  band.t0_s = w[0];
  band.t1_s = w[1];
  band.num_samples = b.Int("samples");
  band.cycles = b.Num("cycles");
  band.amplitude_start_deg = a[0];
  band.amplitude_end_deg = a[1];
  band.amplitude_mean_deg = b.Num("amplitude_mean_deg");
  band.ok = b.Bool("ok");
  // A failed band's I is written null: it keeps the struct's 0.
  const double inertia = b.Num("inertia_kg_m2"), inertia_std = b.Num("inertia_std_kg_m2");
  if (band.ok) {
    band.inertia_kg_m2 = inertia;
    band.inertia_std_kg_m2 = inertia_std;
  }
  return band;
}

AmplitudeSweep SweepFromJson(const RecordNode& j) {
  AmplitudeSweep s;
  s.evaluated = j.Bool("evaluated");
  s.note = j.Str("note");
  for (const RecordNode& b : j.Objects("bands")) s.bands.push_back(SweepBandFromJson(b));
  s.low_band = j.Int("low_band");
  if (s.low_band < -1 || s.low_band >= static_cast<int>(s.bands.size())) {
    throw UserError("'amplitude_sweep.low_band' = " + std::to_string(s.low_band) +
                    " is not a band's index (-1 to " +
                    std::to_string(static_cast<int>(s.bands.size()) - 1) + ")");
  }
  if (!s.evaluated) return s;  // the trend keys are written only for an evaluated sweep
  s.trend_exponent = j.Num("trend_exponent");
  s.trend_coeff = j.Num("trend_coeff_per_deg_p");
  s.trend_coeff_std = j.Num("trend_coeff_std_per_deg_p");
  s.trend_z = j.Num("trend_z");
  s.trend_chi2 = j.Num("trend_chi2");
  s.trend_dof = j.Int("trend_dof");
  s.trend_scale = j.Num("trend_scale");
  s.std_scale = j.Num("std_scale");
  s.trend_percent_per_10deg = j.Num("trend_percent_per_10deg");
  s.inertia_zero_amplitude_kg_m2 = j.Num("inertia_zero_amplitude_kg_m2");
  s.trend_detected = j.Bool("trend_detected");
  return s;
}

// The budget object: "<term>_kg_m2" per term and "total_kg_m2" (TraceRecordToJson).
void BudgetFromJson(const RecordNode& budget, TraceRecord* r) {
  const std::string suffix = "_kg_m2";
  for (const auto& [key, value] : budget.node().items()) {
    budget.Log(key);
    if (key.size() <= suffix.size() ||
        key.compare(key.size() - suffix.size(), suffix.size(), suffix) != 0 ||
        !(value.is_number() || value.is_null())) {
      throw UserError("'budget." + key + "' is not a term NAME_kg_m2 with a number");
    }
    const std::string name = key.substr(0, key.size() - suffix.size());
    const double v = value.is_number() ? value.get<double>() : NAN;
    if (name == "total") {
      r->budget_total_std_kg_m2 = v;
    } else {
      r->budget.push_back({name, v});
    }
  }
  if (!budget.node().contains("total_kg_m2")) throw UserError("'budget.total_kg_m2' is missing");
}

// The "uncertainty" object's fields of the record (the rest is composed from them).
void UncertaintyFromJson(const RecordNode& u, TraceRecord* r) {
  r->inertia_stat_std_kg_m2 = u.Num("statistical_kg_m2");
  r->inertia_iid_std_kg_m2 = u.Num("iid_kg_m2");
  r->hac_bandwidth = u.Int("hac_bandwidth");
  r->model_inadequacy_std_kg_m2 = u.Num("model_inadequacy_kg_m2");
  if (u.Has("repeat_scatter_kg_m2")) r->repeat_scatter_std_kg_m2 = u.Num("repeat_scatter_kg_m2");
  r->budget_assumed = u.Bool("configured_inputs_assumed");
  r->calibrated = u.Bool("calibrated");
  r->calibration_relative_std = u.Num("calibration_relative_std");
}

// The fields of `bifilar process` (TraceRecordToJson with campaign_fields).
void CampaignFieldsFromJson(const RecordNode& j, TraceRecord* r) {
  if (!ParseTraceRole(j.Str("role"), &r->role)) {
    throw UserError("'role' is not " + TraceRoleAllowedValues());
  }
  r->content_hash = j.Str("content_hash");
  r->cache_key = j.Str("cache_key");
  r->from_cache = j.Bool("from_cache");
  r->pitch_nominal_deg = j.OptionalNum("pitch_nominal_deg");
  r->pitch_used_deg = j.Num("pitch_used_deg");
  r->roll_nominal_deg = j.OptionalNum("roll_nominal_deg");
  r->roll_used_deg = j.Num("roll_used_deg");
  r->rig_inertia_kg_m2 = j.Num("rig_inertia_kg_m2");
  r->inertia_kg_m2 = j.Num("inertia_kg_m2");
  r->inertia_std_kg_m2 = j.Num("inertia_std_kg_m2");
  r->inertia_std_total_kg_m2 = j.Num("inertia_std_total_kg_m2");
  r->aircraft_scale_std_kg_m2 = j.Num("aircraft_scale_std_kg_m2");
}

// The fit's numbers and its diagnostics (the keys of TraceRecordToJson in its order).
void FitFieldsFromJson(const RecordNode& j, TraceRecord* r) {
  r->message = j.Str("message");
  r->inertia_total_kg_m2 = j.Num("inertia_total_kg_m2");
  r->inertia_total_std_kg_m2 = j.Num("inertia_total_std_kg_m2");
  r->drag_coeff_kg_m2 = j.Num("drag_coeff_kg_m2");
  r->viscous_coeff_kg_m2_per_s = j.Num("viscous_coeff_kg_m2_per_s");
  r->window_s = j.Numbers<2>("window_s");
  r->amplitude_deg = j.Numbers<2>("amplitude_deg");
  r->amplitude_band_deg = j.Numbers<2>("amplitude_band_deg");
  r->period_s = j.Num("period_s");
  r->frequency_hz = j.Num("frequency_hz");
  r->small_angle_inertia_total_kg_m2 = j.Num("small_angle_inertia_total_kg_m2");
  r->bias_rad_per_s = j.Num("bias_rad_per_s");
  r->residual_rms_rad_per_s = j.Num("residual_rms_rad_per_s");
  r->noise_rms_rad_per_s = j.Num("noise_rms_rad_per_s");
  r->pitch_measured_deg = j.OptionalNum("pitch_measured_deg");
  r->roll_measured_deg = j.OptionalNum("roll_measured_deg");
  r->model = j.Str("model");
  r->iterations = j.Int("iterations");
  r->fit_seconds = j.Num("fit_seconds");
  BudgetFromJson(j.Object("budget"), r);
  r->flags = j.Strs("flags");
  r->warnings = j.Strs("warnings");
  r->figure = j.Str("figure");
  r->figures = j.Strs("figures");
  r->sweep_figure = j.Str("sweep_figure");
  r->swing_axis_in_imu = j.Numbers<3>("swing_axis_in_imu");
  r->secondary_motion_ratio = j.Num("secondary_motion_ratio");
  r->rms_over_noise = j.Num("rms_over_noise");
  const RecordNode autocorrelation = j.Object("residual_autocorrelation");
  r->residual_autocorr_lag1 = autocorrelation.Num("lag1");
  r->residual_ar1_phi = autocorrelation.Num("ar1_phi");
  r->prewhitened_autocorr_max = autocorrelation.Num("prewhitened_max");
  r->inertia_window_kg_m2 = j.Num("inertia_window_kg_m2");
  r->inertia_source = j.Str("inertia_source");
  UncertaintyFromJson(j.Object("uncertainty"), r);
  if (j.Has("amplitude_correction")) {
    const RecordNode c = j.Object("amplitude_correction");
    r->amplitude_correction_kg_m2 = c.Num("correction_kg_m2");
    r->amplitude_correction_std_kg_m2 = c.Num("std_kg_m2");
    r->amplitude_correction_from_deg = c.Num("from_amplitude_deg");
  }
  r->inertia_total_std_total_kg_m2 = j.Num("inertia_total_std_total_kg_m2");
  r->sweep = SweepFromJson(j.Object("amplitude_sweep"));
}
// CSV cell: numbers with full precision, NaN empty; text quoted when needed.
std::string Cell(double value) {
  if (!std::isfinite(value)) return "";
  char buffer[32];
  std::snprintf(buffer, sizeof(buffer), "%.10g", value);
  return buffer;
}
// A text that a CSV reader would take for a non-finite number ("nan", "-Inf": a log named so).
bool ReadsAsNonFinite(std::string text) {
  std::transform(text.begin(), text.end(), text.begin(), ::tolower);
  if (!text.empty() && (text[0] == '-' || text[0] == '+')) text.erase(text.begin());
  return text == "nan" || text == "inf" || text == "infinity";
}
std::string Cell(const std::string& text) {
  // Text stays text: quoted when it holds a separator or would read as NaN/inf.
  if (text.find_first_of(",\"\n") == std::string::npos && !ReadsAsNonFinite(text)) return text;
  std::string quoted = "\"";
  for (char c : text) {
    if (c == '"') quoted += '"';
    quoted += c == '\n' ? ' ' : c;
  }
  return quoted + "\"";
}

std::string Join(const std::vector<std::string>& parts, const char* separator) {
  std::string out;
  for (size_t i = 0; i < parts.size(); ++i) out += (i ? separator : "") + parts[i];
  return out;
}

// The headline total as a percentage of the headline I: the aircraft's after a tare, else the
// whole suspended I's.
double TotalPercent(const TraceRecord& r) {
  if (std::isfinite(r.inertia_std_total_kg_m2) && r.inertia_kg_m2 > 0.0)
    return 100.0 * r.inertia_std_total_kg_m2 / r.inertia_kg_m2;
  if (r.inertia_total_kg_m2 > 0.0)
    return 100.0 * r.inertia_total_std_total_kg_m2 / r.inertia_total_kg_m2;
  return NAN;
}

// The terms of I_total's total in one cell: "statistical:2.1e-09 model_inadequacy:0 ...", the
// assumed one marked "(assumed)"; "" without a fit.
std::string TermsCell(const TraceRecord& r) {
  if (!std::isfinite(r.inertia_total_kg_m2)) return "";
  std::string out;
  char buffer[96];
  for (const UncertaintyTerm& t : ComposeTotalUncertainty(r).terms) {
    std::snprintf(buffer, sizeof(buffer), "%s%s:%.3g%s", out.empty() ? "" : " ", t.name.c_str(),
                  t.std_kg_m2, t.assumed ? "(assumed)" : "");
    out += buffer;
  }
  return out;
}

// The total uncertainty of I_total into the record's "uncertainty" object: every named term
// (pipeline/records/total_uncertainty.h), the stat, common-mode and total stds, and what was
// assumed.
void AddTotalUncertainty(const TraceRecord& r, json* u) {
  const TotalUncertainty total = ComposeTotalUncertainty(r);
  const bool fitted = std::isfinite(r.inertia_total_kg_m2);
  json terms = json::array();
  for (const UncertaintyTerm& t : total.terms) {
    json term = {{"name", t.name},
                 {"std_kg_m2", fitted ? JsonNumber(t.std_kg_m2) : json(nullptr)},
                 {"kind", t.common_mode ? "common_mode" : "per_log"}};
    if (t.assumed) term["assumed"] = true;
    terms.push_back(term);
  }
  (*u)["terms"] = terms;
  (*u)["stat_kg_m2"] = fitted ? JsonNumber(total.stat_std_kg_m2) : json(nullptr);
  (*u)["common_mode_kg_m2"] = fitted ? JsonNumber(total.common_mode_std_kg_m2) : json(nullptr);
  (*u)["total_kg_m2"] = JsonNumber(r.inertia_total_std_total_kg_m2);
  (*u)["total_percent"] =
      fitted && r.inertia_total_kg_m2 > 0.0
          ? JsonNumber(100.0 * r.inertia_total_std_total_kg_m2 / r.inertia_total_kg_m2)
          : json(nullptr);
  (*u)["configured_inputs_assumed"] = r.budget_assumed;
  (*u)["assumed_inputs"] = r.budget_assumed ? json({{"filar_length_std_m", kAssumedLengthStdM},
                                                    {"filar_separation_std_m", kAssumedLengthStdM}})
                                            : json(nullptr);
  (*u)["calibrated"] = r.calibrated;
  (*u)["calibration_relative_std"] = r.calibration_relative_std;
}

}  // namespace

std::string SweepSummary(const AmplitudeSweep& sweep) {
  // "A_deg:I+-std" per band, amplitude decreasing, separated by spaces.
  std::string out;
  char buf[96];
  for (const AmplitudeSweepBand& b : sweep.bands) {
    if (!b.ok) continue;
    std::snprintf(buf, sizeof(buf), "%s%.1f:%.5g+-%.2g", out.empty() ? "" : " ",
                  b.amplitude_mean_deg, b.inertia_kg_m2, b.inertia_std_kg_m2);
    out += buf;
  }
  return out;
}

json TraceRecordToJson(const TraceRecord& r, bool campaign_fields) {
  json j;
  j["file"] = r.file;
  j["status"] = ToString(r.status);
  j["message"] = r.message;
  j["inertia_total_kg_m2"] = JsonNumber(r.inertia_total_kg_m2);
  j["inertia_total_std_kg_m2"] = JsonNumber(r.inertia_total_std_kg_m2);
  j["drag_coeff_kg_m2"] = JsonNumber(r.drag_coeff_kg_m2);
  j["viscous_coeff_kg_m2_per_s"] = JsonNumber(r.viscous_coeff_kg_m2_per_s);
  j["window_s"] = Pair(r.window_s);
  j["amplitude_deg"] = Pair(r.amplitude_deg);
  j["amplitude_band_deg"] = Pair(r.amplitude_band_deg);
  j["period_s"] = JsonNumber(r.period_s);
  j["frequency_hz"] = JsonNumber(r.frequency_hz);
  j["small_angle_inertia_total_kg_m2"] = JsonNumber(r.small_angle_inertia_total_kg_m2);
  j["bias_rad_per_s"] = JsonNumber(r.bias_rad_per_s);
  j["residual_rms_rad_per_s"] = JsonNumber(r.residual_rms_rad_per_s);
  j["noise_rms_rad_per_s"] = JsonNumber(r.noise_rms_rad_per_s);
  j["pitch_measured_deg"] =
      r.pitch_measured_deg ? JsonNumber(*r.pitch_measured_deg) : json(nullptr);
  j["roll_measured_deg"] = r.roll_measured_deg ? JsonNumber(*r.roll_measured_deg) : json(nullptr);
  j["model"] = r.model;
  j["iterations"] = r.iterations;
  j["fit_seconds"] = r.fit_seconds;
  json budget = json::object();
  for (const BudgetTerm& term : r.budget) budget[term.name + "_kg_m2"] = JsonNumber(term.std_kg_m2);
  budget["total_kg_m2"] = JsonNumber(r.budget_total_std_kg_m2);
  j["budget"] = budget;
  j["flags"] = r.flags;
  j["warnings"] = r.warnings;
  j["figure"] = r.figure;
  j["figures"] = r.figures;
  j["sweep_figure"] = r.sweep_figure;
  j["swing_axis_in_imu"] =
      std::isfinite(r.swing_axis_in_imu[0])
          ? json::array({r.swing_axis_in_imu[0], r.swing_axis_in_imu[1], r.swing_axis_in_imu[2]})
          : json(nullptr);
  j["secondary_motion_ratio"] = JsonNumber(r.secondary_motion_ratio);
  j["rms_over_noise"] = JsonNumber(r.rms_over_noise);
  j["residual_autocorrelation"] = {{"lag1", JsonNumber(r.residual_autocorr_lag1)},
                                   {"ar1_phi", JsonNumber(r.residual_ar1_phi)},
                                   {"prewhitened_max", JsonNumber(r.prewhitened_autocorr_max)}};
  j["inertia_window_kg_m2"] = JsonNumber(r.inertia_window_kg_m2);
  j["inertia_source"] = r.inertia_source;
  j["uncertainty"] = {{"statistical_kg_m2", JsonNumber(r.inertia_stat_std_kg_m2)},
                      {"iid_kg_m2", JsonNumber(r.inertia_iid_std_kg_m2)},
                      {"hac_bandwidth", r.hac_bandwidth},
                      {"model_inadequacy_kg_m2", JsonNumber(r.model_inadequacy_std_kg_m2)}};
  if (std::isfinite(r.repeat_scatter_std_kg_m2))
    j["uncertainty"]["repeat_scatter_kg_m2"] = r.repeat_scatter_std_kg_m2;
  if (std::isfinite(r.amplitude_correction_kg_m2)) {
    j["amplitude_correction"] = {
        {"correction_kg_m2", JsonNumber(r.amplitude_correction_kg_m2)},
        {"std_kg_m2", JsonNumber(r.amplitude_correction_std_kg_m2)},
        {"from_amplitude_deg", JsonNumber(r.amplitude_correction_from_deg)},
        {"to_amplitude_deg", 0.0}};
  }
  j["inertia_total_std_total_kg_m2"] = JsonNumber(r.inertia_total_std_total_kg_m2);
  AddTotalUncertainty(r, &j["uncertainty"]);
  j["amplitude_sweep"] = SweepToJson(r.sweep);
  if (campaign_fields) {
    j["role"] = ToString(r.role);
    j["content_hash"] = r.content_hash;
    j["cache_key"] = r.cache_key;
    j["from_cache"] = r.from_cache;
    j["pitch_nominal_deg"] = r.pitch_nominal_deg ? JsonNumber(*r.pitch_nominal_deg) : json(nullptr);
    j["pitch_used_deg"] = JsonNumber(r.pitch_used_deg);
    j["roll_nominal_deg"] = r.roll_nominal_deg ? JsonNumber(*r.roll_nominal_deg) : json(nullptr);
    j["roll_used_deg"] = JsonNumber(r.roll_used_deg);
    j["rig_inertia_kg_m2"] = JsonNumber(r.rig_inertia_kg_m2);
    j["inertia_kg_m2"] = JsonNumber(r.inertia_kg_m2);
    j["inertia_std_kg_m2"] = JsonNumber(r.inertia_std_kg_m2);
    j["inertia_std_total_kg_m2"] = JsonNumber(r.inertia_std_total_kg_m2);
    j["aircraft_scale_std_kg_m2"] = JsonNumber(r.aircraft_scale_std_kg_m2);
  }
  return j;
}

TraceRecord TraceRecordFromJson(const json& j, bool campaign_fields, KeyLog* keys_read) {
  if (!j.is_object()) {
    throw UserError(std::string("a trace record is an object, not ") + j.type_name());
  }
  const RecordNode node(j, "", keys_read);
  TraceRecord r;
  r.file = node.Str("file");
  if (!ParseTraceStatus(node.Str("status"), &r.status)) {
    throw UserError("'status' is not " + TraceStatusAllowedValues());
  }
  FitFieldsFromJson(node, &r);
  if (campaign_fields) CampaignFieldsFromJson(node, &r);
  return r;
}

const KeyLog& DerivedTraceKeys() {
  static const KeyLog kKeys = {"uncertainty.terms",
                               "uncertainty.terms[].name",
                               "uncertainty.terms[].std_kg_m2",
                               "uncertainty.terms[].kind",
                               "uncertainty.terms[].assumed",
                               "uncertainty.stat_kg_m2",
                               "uncertainty.common_mode_kg_m2",
                               "uncertainty.total_kg_m2",
                               "uncertainty.total_percent",
                               "uncertainty.assumed_inputs",
                               "uncertainty.assumed_inputs.filar_length_std_m",
                               "uncertainty.assumed_inputs.filar_separation_std_m",
                               "amplitude_correction.to_amplitude_deg"};
  return kKeys;
}

json CalibrationToJson(const RigCalibrationResult& c) {
  return {{"applied", c.applied},
          {"factor", JsonNumber(c.factor)},
          {"factor_std", JsonNumber(c.factor_std)},
          {"factor_relative_std", JsonNumber(c.factor_rel_std)},
          {"relative_std_parts",
           {{"reference_inertia", JsonNumber(c.rel_std_reference)},
            {"reference_swings", JsonNumber(c.rel_std_swings)},
            {"rig_inertia", JsonNumber(c.rel_std_rig)}}},
          {"nominal",
           {{"filar_length_m", JsonNumber(c.filar_length_m)},
            {"filar_separation_m", JsonNumber(c.nominal_separation_m)},
            {"d2_over_l_m", JsonNumber(c.nominal_d2_over_l_m)}}},
          {"effective",
           {{"filar_length_m", JsonNumber(c.filar_length_m)},
            {"filar_separation_m", JsonNumber(c.effective_separation_m)},
            {"d2_over_l_m", JsonNumber(c.effective_d2_over_l_m)}}},
          {"reference",
           {{"inertia_kg_m2", JsonNumber(c.reference_inertia_kg_m2)},
            {"inertia_std_kg_m2", JsonNumber(c.reference_inertia_std_kg_m2)},
            {"mass_kg", JsonNumber(c.reference_mass_kg)}}},
          {"swings",
           {{"n", c.n_swings},
            {"logs", c.logs},
            {"total_mean_kg_m2", JsonNumber(c.swings_total_kg_m2)},
            {"total_standard_error_kg_m2", JsonNumber(c.swings_total_std_kg_m2)},
            {"scatter_kg_m2", JsonNumber(c.swings_scatter_kg_m2)}}},
          {"rig_inertia",
           {{"source", c.rig_inertia_source},
            {"inertia_kg_m2", JsonNumber(c.rig_inertia_kg_m2)},
            {"inertia_std_kg_m2", JsonNumber(c.rig_inertia_std_kg_m2)}}},
          {"iterations", c.iterations},
          {"warnings", c.warnings}};
}

RigCalibrationResult CalibrationFromJson(const json& j, KeyLog* keys_read) {
  if (!j.is_object())
    throw UserError(std::string("a calibration is an object, not ") + j.type_name());
  const RecordNode c(j, "", keys_read);
  RigCalibrationResult r;
  r.applied = c.Bool("applied");
  r.factor = c.Num("factor");
  r.factor_std = c.Num("factor_std");
  r.factor_rel_std = c.Num("factor_relative_std");
  const RecordNode parts = c.Object("relative_std_parts");
  r.rel_std_reference = parts.Num("reference_inertia");
  r.rel_std_swings = parts.Num("reference_swings");
  r.rel_std_rig = parts.Num("rig_inertia");
  const RecordNode nominal = c.Object("nominal"), effective = c.Object("effective");
  r.filar_length_m = nominal.Num("filar_length_m");
  r.nominal_separation_m = nominal.Num("filar_separation_m");
  r.nominal_d2_over_l_m = nominal.Num("d2_over_l_m");
  // L is kept: the effective geometry's L is the configured one.
  const double effective_length_m = effective.Num("filar_length_m");
  if (!(effective_length_m == r.filar_length_m ||
        (std::isnan(effective_length_m) && std::isnan(r.filar_length_m)))) {
    throw UserError(
        "'effective.filar_length_m' is not 'nominal.filar_length_m' (the calibration "
        "keeps L)");
  }
  r.effective_separation_m = effective.Num("filar_separation_m");
  r.effective_d2_over_l_m = effective.Num("d2_over_l_m");
  const RecordNode reference = c.Object("reference");
  r.reference_inertia_kg_m2 = reference.Num("inertia_kg_m2");
  r.reference_inertia_std_kg_m2 = reference.Num("inertia_std_kg_m2");
  r.reference_mass_kg = reference.Num("mass_kg");
  const RecordNode swings = c.Object("swings");
  r.n_swings = swings.Int("n");
  r.logs = swings.Strs("logs");
  r.swings_total_kg_m2 = swings.Num("total_mean_kg_m2");
  r.swings_total_std_kg_m2 = swings.Num("total_standard_error_kg_m2");
  r.swings_scatter_kg_m2 = swings.Num("scatter_kg_m2");
  const RecordNode rig = c.Object("rig_inertia");
  r.rig_inertia_source = rig.Str("source");
  r.rig_inertia_kg_m2 = rig.Num("inertia_kg_m2");
  r.rig_inertia_std_kg_m2 = rig.Num("inertia_std_kg_m2");
  r.iterations = c.Int("iterations");
  r.warnings = c.Strs("warnings");
  return r;
}

json CampaignSummaryToJson(const CampaignSummary& s) {
  json summary;
  summary["n_traces"] = s.n_traces;
  summary["n_ok"] = s.n_ok;
  summary["n_rejected"] = s.n_rejected;
  summary["n_error"] = s.n_error;
  summary["n_fitted"] = s.n_fitted;
  summary["n_reused"] = s.n_reused;
  summary["wall_s"] = s.wall_s;
  summary["ellipse_fitted"] = s.ellipse_fitted;
  summary["ellipse_message"] = s.ellipse_message;
  summary["tensor_fitted"] = s.tensor_fitted;
  summary["tensor_message"] = s.tensor_message;
  summary["exit_code"] = s.exit_code;
  return summary;
}

CampaignSummary CampaignSummaryFromJson(const json& j, KeyLog* keys_read) {
  if (!j.is_object()) throw UserError(std::string("a summary is an object, not ") + j.type_name());
  const RecordNode node(j, "", keys_read);
  CampaignSummary s;
  s.n_traces = node.Int("n_traces");
  s.n_ok = node.Int("n_ok");
  s.n_rejected = node.Int("n_rejected");
  s.n_error = node.Int("n_error");
  s.n_fitted = node.Int("n_fitted");
  s.n_reused = node.Int("n_reused");
  s.wall_s = node.Num("wall_s");
  s.ellipse_fitted = node.Bool("ellipse_fitted");
  s.ellipse_message = node.Str("ellipse_message");
  s.tensor_fitted = node.Bool("tensor_fitted");
  s.tensor_message = node.Str("tensor_message");
  s.exit_code = node.Int("exit_code");
  return s;
}

json ResultsToJson(const CampaignConfig& config, const CampaignResult& result) {
  json j;
  j["program"] = "bifilar";
  j["version"] = ProgramVersion();
  j["schema_version"] = kResultsSchemaVersion;
  // Relative to the working folder when below it (results do not carry the machine's layout).
  std::error_code ec;
  const std::string relative = std::filesystem::path(config.file)
                                   .lexically_relative(std::filesystem::current_path(ec))
                                   .string();
  j["config_file"] = !relative.empty() && relative.rfind("..", 0) != 0 ? relative : config.file;
  j["config"] = config.text;
  // The aircraft's mass, for export (not measured by the bifilar; from the config).
  j["aircraft"] = config.aircraft_mass_kg > 0
                      ? json{{"mass_kg", JsonNumber(config.aircraft_mass_kg)},
                             {"mass_std_kg", config.aircraft_mass_std_given
                                                 ? JsonNumber(config.aircraft_mass_std_kg)
                                                 : json(nullptr)}}
                      : json(nullptr);
  j["units"] = ToString(config.units);
  j["pitch_source"] = ToString(config.runs.pitch_source);
  // The fit settings in effect: the config's, with the command line's overrides (--integrator),
  // which the config text above does not show.
  const GlitchOptions& glitch = config.fit.glitch;
  j["fit_settings"] = {{"model", ToString(config.fit.model)},
                       {"integrator", ToString(config.fit.integrator)},
                       {"amplitude_sweep", config.fit.sweep.amplitude_sweep},
                       {"glitch",
                        {{"enabled", glitch.enabled},
                         {"threshold_sigmas", glitch.threshold_sigmas},
                         {"range_factor", glitch.range_factor},
                         {"excursion_fraction", glitch.excursion_fraction},
                         {"max_fraction", glitch.max_fraction}}}};
  j["summary"] = CampaignSummaryToJson(result.summary);
  json rig;
  rig["filar_length_m"] = config.filar_length_m;
  rig["filar_separation_m"] = config.filar_separation_m;
  rig["mass_kg"] = config.rig_mass_kg;
  rig["aircraft_mass_kg"] = config.aircraft_mass_kg;
  rig["gravity_mps2"] = config.gravity_mps2;
  rig["inertia_source"] = !config.rig_inertia_given                                 ? "none"
                          : config.rig_inertia.kind == RigInertiaSpec::Kind::kValue ? "value"
                          : config.rig_inertia.kind == RigInertiaSpec::Kind::kTable ? "table"
                                                                                    : "tare";
  rig["inertia_kg_m2"] = JsonNumber(result.rig_inertia_kg_m2);
  rig["inertia_std_kg_m2"] = JsonNumber(result.rig_inertia_std_kg_m2);
  rig["tare_n"] = result.rig_tare_n;
  j["rig"] = rig;
  json table1;
  table1["raw_sigma_kg_m2"] = JsonNumber(result.raw_sigma_kg_m2);
  table1["cv_percent"] = JsonNumber(result.cv_percent);
  table1["regression_rmse_kg_m2"] = JsonNumber(result.regression_rmse_kg_m2);
  j["table1"] = table1;
  j["systematic_relative_std"] = JsonNumber(result.systematic_relative_std);
  // rig.calibration: the effective geometry of every fit; its relative std is the `calibration`
  // term of each trace's budget (and so inside systematic_relative_std). null without one.
  j["calibration"] = result.calibration ? CalibrationToJson(*result.calibration) : json(nullptr);
  // Table 2's total (pipeline/records/total_uncertainty.h): each moment's std and the common-mode
  // scale fraction in quadrature; tau has no scale term.
  json total = {{"common_mode_relative_std", JsonNumber(result.common_mode_relative_std)},
                {"configured_inputs_assumed", result.common_mode_assumed},
                {"note", result.assumed_inputs_note}};
  if (result.ellipse_fit) {
    const EllipseResult& e = *result.ellipse_fit;
    const double rel = result.common_mode_relative_std;
    auto moment = [&](const EllipseEstimate& est) {
      return est.defined ? JsonNumber(WithCommonModeScale(est.value, est.std, rel)) : json(nullptr);
    };
    total["Ix_kg_m2"] = moment(e.ix);
    total["Iz_kg_m2"] = moment(e.iz);
    total["Ixz_kg_m2"] = moment(e.ixz);
    total["Ixp_kg_m2"] = moment(e.ixp);
    total["Izp_kg_m2"] = moment(e.izp);
    total["tau_deg"] = e.tau_deg.defined ? JsonNumber(e.tau_deg.std) : json(nullptr);
  }
  j["total_uncertainty"] = total;
  json traces = json::array();
  for (const TraceRecord& r : result.traces) traces.push_back(TraceRecordToJson(r));
  j["traces"] = traces;
  json angles = json::array();
  for (const AngleStats& a : result.angles) {
    angles.push_back({{"pitch_deg", JsonNumber(a.pitch_deg)},
                      {"n", a.n},
                      {"inertia_mean_kg_m2", JsonNumber(a.inertia_mean_kg_m2)},
                      {"inertia_std_kg_m2", JsonNumber(a.inertia_std_kg_m2)},
                      {"inertia_sem_kg_m2", JsonNumber(a.inertia_sem_kg_m2)},
                      {"cv_percent", JsonNumber(a.cv_percent)},
                      {"fit_std_mean_kg_m2", JsonNumber(a.fit_std_mean_kg_m2)},
                      {"common_mode_std_kg_m2", JsonNumber(a.common_mode_std_kg_m2)},
                      {"inertia_std_total_kg_m2", JsonNumber(a.inertia_std_total_kg_m2)},
                      {"roll_deg", JsonNumber(a.roll_deg)}});
  }
  j["angles"] = angles;
  j["ellipse"] = result.ellipse;
  j["tensor"] = result.tensor;
  if (result.physical) j["physical"] = PhysicalCheckToJson(*result.physical);
  j["figures"] = {{"moments", result.moments_figure},
                  {"polar", result.polar_figure},
                  {"tensor", result.tensor_figure}};
  return j;
}

std::string TracesCsv(const CampaignResult& result) {
  std::ostringstream out;
  out << "file,role,status,pitch_nominal_deg,pitch_measured_deg,pitch_used_deg,"
         "inertia_total_kg_m2,inertia_total_std_kg_m2,period_s,frequency_hz,"
         "small_angle_inertia_total_kg_m2,rig_inertia_kg_m2,inertia_kg_m2,inertia_std_kg_m2,"
         "inertia_total_std_total_kg_m2,inertia_std_total_kg_m2,"
         "std_total_percent,uncertainty_terms,budget_assumed,"
         "budget_total_std_kg_m2,drag_coeff_kg_m2,viscous_coeff_kg_m2_per_s,"
         "window_t0_s,window_t1_s,amplitude_start_deg,amplitude_end_deg,bias_rad_per_s,"
         "residual_rms_rad_per_s,model,iterations,fit_seconds,from_cache,inertia_source,"
         "inertia_window_kg_m2,model_inadequacy_std_kg_m2,secondary_motion_ratio,rms_over_noise,"
         "residual_ar1_phi,sweep_bands,sweep_trend_percent_per_10deg,sweep_trend_z,"
         "sweep_trend_detected,sweep_inertia_by_amplitude,warnings,message,roll_nominal_deg,"
         "roll_measured_deg,roll_used_deg\n";
  for (const TraceRecord& r : result.traces) {
    out << Cell(r.file) << ',' << ToString(r.role) << ',' << ToString(r.status) << ','
        << Cell(r.pitch_nominal_deg ? *r.pitch_nominal_deg : NAN) << ','
        << Cell(r.pitch_measured_deg ? *r.pitch_measured_deg : NAN) << ',' << Cell(r.pitch_used_deg)
        << ',' << Cell(r.inertia_total_kg_m2) << ',' << Cell(r.inertia_total_std_kg_m2) << ','
        << Cell(r.period_s) << ',' << Cell(r.frequency_hz) << ','
        << Cell(r.small_angle_inertia_total_kg_m2) << ',' << Cell(r.rig_inertia_kg_m2) << ','
        << Cell(r.inertia_kg_m2) << ',' << Cell(r.inertia_std_kg_m2) << ','
        << Cell(r.inertia_total_std_total_kg_m2) << ',' << Cell(r.inertia_std_total_kg_m2) << ','
        << Cell(TotalPercent(r)) << ',' << Cell(TermsCell(r)) << ','
        << (r.budget_assumed ? "true" : "false") << ',' << Cell(r.budget_total_std_kg_m2) << ','
        << Cell(r.drag_coeff_kg_m2) << ',' << Cell(r.viscous_coeff_kg_m2_per_s) << ','
        << Cell(r.window_s[0]) << ',' << Cell(r.window_s[1]) << ',' << Cell(r.amplitude_deg[0])
        << ',' << Cell(r.amplitude_deg[1]) << ',' << Cell(r.bias_rad_per_s) << ','
        << Cell(r.residual_rms_rad_per_s) << ',' << Cell(r.model) << ',' << r.iterations << ','
        << Cell(r.fit_seconds) << ',' << (r.from_cache ? "true" : "false") << ','
        << Cell(r.inertia_source) << ',' << Cell(r.inertia_window_kg_m2) << ','
        << Cell(r.model_inadequacy_std_kg_m2) << ',' << Cell(r.secondary_motion_ratio) << ','
        << Cell(r.rms_over_noise) << ',' << Cell(r.residual_ar1_phi) << ',' << r.sweep.bands.size()
        << ',' << (r.sweep.evaluated ? Cell(r.sweep.trend_percent_per_10deg) : "") << ','
        << (r.sweep.evaluated ? Cell(r.sweep.trend_z) : "") << ','
        << (r.sweep.evaluated ? (r.sweep.trend_detected ? "true" : "false") : "") << ','
        << Cell(SweepSummary(r.sweep)) << ',' << Cell(Join(r.warnings, " | ")) << ','
        << Cell(r.message) << ',' << Cell(r.roll_nominal_deg ? *r.roll_nominal_deg : NAN) << ','
        << Cell(r.roll_measured_deg ? *r.roll_measured_deg : NAN) << ',' << Cell(r.roll_used_deg)
        << '\n';
  }
  return out.str();
}

std::string AnglesCsv(const CampaignResult& result) {
  std::ostringstream out;
  out << "pitch_deg,n,inertia_mean_kg_m2,inertia_std_kg_m2,inertia_sem_kg_m2,cv_percent,"
         "fit_std_mean_kg_m2,common_mode_std_kg_m2,inertia_std_total_kg_m2,roll_deg\n";
  for (const AngleStats& a : result.angles) {
    out << Cell(a.pitch_deg) << ',' << a.n << ',' << Cell(a.inertia_mean_kg_m2) << ','
        << Cell(a.inertia_std_kg_m2) << ',' << Cell(a.inertia_sem_kg_m2) << ','
        << Cell(a.cv_percent) << ',' << Cell(a.fit_std_mean_kg_m2) << ','
        << Cell(a.common_mode_std_kg_m2) << ',' << Cell(a.inertia_std_total_kg_m2) << ','
        << Cell(a.roll_deg) << '\n';
  }
  return out.str();
}

int SchemaVersionOf(const json& document) {
  const auto it = document.is_object() ? document.find("schema_version") : document.end();
  if (it == document.end()) return 0;
  if (!it->is_number_integer() || it->get<long long>() < 0 ||
      it->get<long long>() > std::numeric_limits<int>::max()) {
    throw UserError("'schema_version' is not a whole number >= 0 (" + it->dump() + ")");
  }
  return it->get<int>();
}

void CheckResultsSchema(const json& results, const std::string& name) {
  int schema = 0;
  try {
    schema = SchemaVersionOf(results);
  } catch (const UserError& e) {
    throw UserError(name + ": " + e.what() + "; rerun `bifilar process` to rewrite it");
  }
  if (schema <= kResultsSchemaVersion) return;
  const auto version = results.find("version");
  const std::string writer = version != results.end() && version->is_string()
                                 ? "bifilar " + version->get<std::string>()
                                 : std::string("a bifilar of an unknown version");
  throw UserError(name + ": results schema " + std::to_string(schema) + ", written by " + writer +
                  "; this is bifilar " + ProgramVersion() + ", which reads schema " +
                  std::to_string(kResultsSchemaVersion) +
                  " and older: use that version or a newer one, or rerun `bifilar process` "
                  "with this one to rewrite the file");
}

}  // namespace bifilar

#include "pipeline/store/cache.h"

#include <algorithm>
#include <cinttypes>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "base/atomic_file.h"
#include "base/bounded_read.h"
#include "base/json_error.h"
#include "base/user_error.h"
#include "base/version.h"
#include "pipeline/records/results_json.h"

namespace bifilar {

namespace {
void Put(std::ostringstream& out, const char* name, double value) {
  char buffer[40];
  std::snprintf(buffer, sizeof(buffer), "%.17g", value);
  out << name << '=' << buffer << ';';
}
}  // namespace

std::string FitFingerprint(const CampaignConfig& config, TraceRole role,
                           const std::optional<std::array<double, 2>>& window_s) {
  std::ostringstream out;
  const RigGeometry geometry = GeometryForRole(config, role);  // D: the calibrated one, if any
  out << "version=" << ProgramVersion() << ';';
  out << "role=" << ToString(role) << ';';
  Put(out, "L", geometry.filar_length_m);
  Put(out, "D", geometry.filar_separation_m);
  Put(out, "m", geometry.mass_kg);
  Put(out, "g", geometry.gravity_mps2);
  // The stds in effect (the assumed 1 mm on L and D without rig.uncertainties, marked: the
  // record then carries the assumption's warning).
  const RigUncertainties uncertainties = config.uncertainties.InEffect();
  if (config.uncertainties.Assumed()) out << "unc=assumed;";
  Put(out, "L_std", uncertainties.filar_length_std_m);
  Put(out, "D_std", uncertainties.filar_separation_std_m);
  Put(out, "m_rig_std", uncertainties.mass_std_kg);
  if (role == TraceRole::kAircraft) Put(out, "m_aircraft_std", config.aircraft_mass_std_kg);
  Put(out, "g_std", uncertainties.gravity_std_mps2);
  Put(out, "gyro_scale_std", config.imu.gyro_scale_std);
  // A calibrated geometry (rig.calibration) changes D above, drops the L, D and g terms of the
  // budget and adds its own; only then in the key, so uncalibrated keys stay those of 0.2.0.
  if (config.geometry_calibration.applied) {
    Put(out, "calibration_factor", config.geometry_calibration.factor);
    Put(out, "calibration_rel_std", config.geometry_calibration.factor_rel_std);
  }
  out << "model=" << ToString(config.fit.model) << ';';
  // Only a non-default integrator enters the key, so rk853 keys stay those of earlier versions.
  if (config.fit.integrator != IntegratorMethod::kRungeKutta) {
    out << "integrator=" << ToString(config.fit.integrator) << ';';
  }
  if (window_s) {
    Put(out, "t0", (*window_s)[0]);
    Put(out, "t1", (*window_s)[1]);
  }
  if (config.fit.max_amplitude_deg) Put(out, "amax", *config.fit.max_amplitude_deg);
  if (config.fit.min_amplitude_deg) Put(out, "amin", *config.fit.min_amplitude_deg);
  const ImuFormat& f = config.imu.format;
  out << "time=" << f.time_column << ',' << ToString(f.time_unit) << ';';
  out << "gyro=" << f.gyro_columns[0] << ',' << f.gyro_columns[1] << ',' << f.gyro_columns[2]
      << ',' << ToString(f.gyro_unit) << ';';
  out << "accel=" << f.accel_columns[0] << ',' << f.accel_columns[1] << ',' << f.accel_columns[2]
      << ',' << ToString(f.accel_unit) << ';' << "delim=" << f.delimiter << ';';
  out << "ulog=" << static_cast<int>(f.container) << ',' << f.ulog.topic << ',' << f.ulog.multi_id << ','
      << f.ulog.time_field << ',' << f.ulog.gyro_fields[0] << ',' << f.ulog.gyro_fields[1] << ','
      << f.ulog.gyro_fields[2] << ',' << f.ulog.accel_fields[0] << ',' << f.ulog.accel_fields[1] << ','
      << f.ulog.accel_fields[2] << ';';
  if (config.imu.dataflash_instance >= 0) out << "dataflash=" << config.imu.dataflash_instance << ';';
  out << "axis=" << (config.imu.swing_axis_auto ? "auto" : "fixed") << ';';
  for (int i = 0; i < 3; ++i) Put(out, "n", config.imu.swing_axis_in_imu[i]);
  for (int i = 0; i < 9; ++i) Put(out, "R", config.imu.imu_to_body(i / 3, i % 3));
  const QualityThresholds& q = config.fit.quality;
  Put(out, "q_noise", q.max_rms_over_noise);
  Put(out, "q_white", q.max_residual_autocorr);
  Put(out, "q_lags", q.whiteness_lags);
  Put(out, "q_secondary", q.max_secondary_motion_ratio);
  Put(out, "q_periods", q.min_periods);
  Put(out, "q_secondary_reject", q.reject_secondary_motion_ratio);
  Put(out, "q_residual_reject", q.reject_residual_fraction);
  const SweepConfig& sw = config.fit.sweep;
  Put(out, "sweep", sw.enabled ? 1.0 : 0.0);
  Put(out, "sweep_cycles", sw.min_cycles_per_band);
  Put(out, "sweep_bands", sw.max_bands);
  Put(out, "sweep_z", sw.trend_z);
  // The sweep's trend rule (I_0 (1 + c A^p), p in {1, 2}; Birge scale about the trend): a
  // record fitted under the earlier A^2-only rule is not replayed.
  out << "sweep_rule=power12;";
  // Only non-default glitch settings enter the key, so default keys stay those of 0.2.0.
  const GlitchConfig& gl = config.fit.glitch;
  if (!gl.IsDefault()) {
    Put(out, "glitch", gl.enabled ? 1.0 : 0.0);
    Put(out, "glitch_sigmas", gl.threshold_sigmas);
    Put(out, "glitch_range", gl.range_factor);
    Put(out, "glitch_excursion", gl.excursion_fraction);
    Put(out, "glitch_fraction", gl.max_fraction);
  }
  return out.str();
}

std::string CacheKey(const std::string& content_hash_hex, const std::string& fingerprint) {
  return HashToHex(Fnv1a64(fingerprint, Fnv1a64(content_hash_hex)));
}

TraceCache::TraceCache(std::string folder) : folder_(std::move(folder)) {}

std::string TraceCache::EntryPath(const std::string& key) const {
  return (std::filesystem::path(folder_) / (key + ".json")).string();
}

namespace {

std::string EntryChecksum(const std::string& key, const std::string& content_hash,
                          const std::string& version, const nlohmann::json& record) {
  const std::string text = record.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
  return HashToHex(Fnv1a64(key + ";" + content_hash + ";" + version + ";" + text));
}

}  // namespace

bool TraceCache::Load(const std::string& key, const std::string& content_hash,
                      TraceRecord* record, std::string* problem) const {
  problem->clear();
  const std::string path = EntryPath(key);
  std::error_code ec;
  if (!std::filesystem::exists(path, ec)) return false;
  std::string bytes, why;
  if (!ReadRegularFile(path, CacheEntryCap(), &bytes, &why)) {
    *problem = why;
    return false;
  }
  auto refuse = [&](const std::string& reason) {
    *problem = path + ": cache entry refused (" + reason + ")";
    return false;
  };
  nlohmann::json entry;
  try {
    entry = nlohmann::json::parse(bytes);
  } catch (const std::exception&) {
    return refuse("not valid JSON");
  }
  if (!entry.is_object() || !entry.contains("bifilar_cache") || entry["bifilar_cache"] != kFormat ||
      !entry.contains("record") || !entry["record"].is_object()) {
    return refuse("not a bifilar cache entry of format " + std::to_string(kFormat));
  }
  // The record's schema (base/version.h): an older entry is a miss (refitted and overwritten),
  // a newer one refused.
  int schema = 0;
  try {
    schema = SchemaVersionOf(entry);
  } catch (const UserError& e) {
    return refuse(e.what());
  }
  if (schema < kResultsSchemaVersion) return false;
  if (schema > kResultsSchemaVersion) {
    return refuse("schema " + std::to_string(schema) + ", newer than this bifilar's " +
                  std::to_string(kResultsSchemaVersion));
  }
  auto text = [&](const char* field) {
    return entry.contains(field) && entry[field].is_string() ? entry[field].get<std::string>()
                                                             : std::string();
  };
  if (text("key") != key) return refuse("it belongs to key '" + text("key") + "'");
  if (text("content_hash") != content_hash) return refuse("it is of another log's content");
  if (text("version") != ProgramVersion()) return refuse("written by version " + text("version"));
  const nlohmann::json& fields = entry["record"];
  if (text("checksum") != EntryChecksum(key, content_hash, ProgramVersion(), fields)) {
    return refuse("checksum mismatch: the entry was changed after it was written");
  }
  // The one reader of a record (pipeline/records/results_json.h): an entry missing a key the
  // writer writes (one of an older format, such as before records carried the period) is
  // refitted, not shown with a blank.
  try {
    *record = TraceRecordFromJson(fields, false);  // the fit fields, as Store writes them
  } catch (const std::exception& e) {
    return refuse(DescribeJsonError(e));
  }
  // null reads as NaN (no fit); an infinity cannot come from the parser (it refuses 1e999 as a
  // number overflow), but a record is never taken with one.
  for (const auto& [field, value] :
       {std::make_pair("inertia_total_kg_m2", record->inertia_total_kg_m2),
        std::make_pair("inertia_total_std_kg_m2", record->inertia_total_std_kg_m2)}) {
    if (std::isinf(value)) return refuse(std::string(field) + " is not a finite number");
  }
  if (record->ok() && !(record->inertia_total_kg_m2 > 0.0 &&
                        std::isfinite(record->inertia_total_kg_m2) &&
                        record->inertia_total_std_kg_m2 >= 0.0 &&
                        std::isfinite(record->inertia_total_std_kg_m2))) {
    return refuse("an ok record needs a finite inertia > 0 and a finite std >= 0");
  }
  return true;
}

void TraceCache::Store(const std::string& key, const std::string& content_hash,
                       const TraceRecord& record) const {
  if (std::find(record.flags.begin(), record.flags.end(), "time_guard") != record.flags.end())
    return;  // depends on the machine's speed: never replayed
  std::error_code ec;
  std::filesystem::create_directories(folder_, ec);
  if (ec) throw UserError(folder_ + ": cannot create cache folder: " + ec.message());
  nlohmann::json entry;
  entry["bifilar_cache"] = kFormat;
  entry["key"] = key;
  entry["content_hash"] = content_hash;
  entry["version"] = ProgramVersion();
  entry["schema_version"] = kResultsSchemaVersion;
  entry["record"] = TraceRecordToJson(record, false);
  entry["checksum"] = EntryChecksum(key, content_hash, ProgramVersion(), entry["record"]);
  // Invalid UTF-8 (a log's bytes in a message) is replaced, never a json exception.
  const std::string text = entry.dump(1, ' ', false, nlohmann::json::error_handler_t::replace);
  WriteFileAtomically(EntryPath(key), text + "\n");
}

}  // namespace bifilar

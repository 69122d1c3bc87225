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
#include "base/option_table.h"
#include "base/user_error.h"
#include "base/version.h"
#include "pipeline/records/results_json.h"

namespace bifilar {

namespace {

// "name=value;" with 17 significant digits (reads back to the same double): canonical text.
void Put(std::ostringstream& out, const std::string& name, double value) {
  char buffer[40];
  std::snprintf(buffer, sizeof(buffer), "%.17g", value);
  out << name << '=' << buffer << ';';
}

void PutText(std::ostringstream& out, const std::string& name, const std::string& value) {
  out << name << '=' << value << ';';
}

void PutOptional(std::ostringstream& out, const std::string& name,
                 const std::optional<double>& value) {
  if (value) {
    Put(out, name, *value);
  } else {
    PutText(out, name, "none");
  }
}

// The log as the fit reads it: format, ULog selection, DataFlash instance, the decompression cap
// (a .csv.gz beyond it is an error record), swing axis and mounting.
void PutLogReading(std::ostringstream& out, const CampaignConfig& config) {
  const ImuFormat& f = config.imu.format;
  PutText(out, "imu.format", ToString(f.container));
  PutText(out, "imu.time", f.time_column + "," + ToString(f.time_unit));
  PutText(out, "imu.gyro",
          f.gyro_columns[0] + "," + f.gyro_columns[1] + "," + f.gyro_columns[2] + "," +
              ToString(f.gyro_unit));
  PutText(out, "imu.accel",
          f.accel_columns[0] + "," + f.accel_columns[1] + "," + f.accel_columns[2] + "," +
              ToString(f.accel_unit));
  PutText(out, "imu.delimiter", std::string(1, f.delimiter));
  const UlogSelection& u = f.ulog;
  PutText(out, "imu.ulog",
          u.topic + "," + std::to_string(u.multi_id) + "," + u.time_field + "," + u.gyro_fields[0] +
              "," + u.gyro_fields[1] + "," + u.gyro_fields[2] + "," + u.accel_fields[0] + "," +
              u.accel_fields[1] + "," + u.accel_fields[2]);
  Put(out, "imu.dataflash.instance", config.imu.dataflash_instance);
  Put(out, "limits.max_decompressed_log_mb", config.limits.max_decompressed_log_mb);
  PutText(out, "imu.swing_axis", config.imu.swing_axis_auto ? "auto" : "fixed");
  for (int i = 0; i < 3; ++i) Put(out, "n", config.imu.swing_axis_in_imu[i]);
  for (int i = 0; i < 9; ++i) Put(out, "R", config.imu.imu_to_body(i / 3, i % 3));
}

}  // namespace

std::string FitFingerprint(const CampaignConfig& config, TraceRole role,
                           const std::optional<std::array<double, 2>>& window_s) {
  std::ostringstream out;
  Put(out, "key_format", TraceCache::kFormat);
  PutText(out, "version", ProgramVersion());
  PutText(out, "role", ToString(role));
  // The geometry of the fit (D: the calibrated one, if any) and the budget's stds in effect (the
  // assumed 1 mm on L and D without rig.uncertainties, marked: the record then carries the
  // assumption's warning).
  const RigGeometry geometry = GeometryForRole(config, role);
  Put(out, "L", geometry.filar_length_m);
  Put(out, "D", geometry.filar_separation_m);
  Put(out, "m", geometry.mass_kg);
  Put(out, "g", geometry.gravity_mps2);
  const RigUncertainties uncertainties = config.uncertainties.InEffect();
  PutText(out, "unc_assumed", config.uncertainties.Assumed() ? "true" : "false");
  Put(out, "L_std", uncertainties.filar_length_std_m);
  Put(out, "D_std", uncertainties.filar_separation_std_m);
  Put(out, "m_rig_std", uncertainties.mass_std_kg);
  if (role == TraceRole::kAircraft) Put(out, "m_aircraft_std", config.aircraft_mass_std_kg);
  Put(out, "g_std", uncertainties.gravity_std_mps2);
  Put(out, "gyro_scale_std", config.imu.gyro_scale_std);
  // A calibrated geometry (rig.calibration) changes D above, drops the L, D and g terms of the
  // budget and adds its own.
  PutText(out, "calibration", config.geometry_calibration.applied ? "applied" : "none");
  Put(out, "calibration_factor", config.geometry_calibration.factor);
  Put(out, "calibration_rel_std", config.geometry_calibration.factor_rel_std);
  // The fit: model, integrator, this file's window override, the amplitude band.
  PutText(out, "fit.model", ToString(config.fit.model));
  PutText(out, "fit.integrator", ToString(config.fit.integrator));
  PutOptional(out, "t0", window_s ? std::optional<double>((*window_s)[0]) : std::nullopt);
  PutOptional(out, "t1", window_s ? std::optional<double>((*window_s)[1]) : std::nullopt);
  PutOptional(out, "fit.max_amplitude_deg", config.fit.max_amplitude_deg);
  PutOptional(out, "fit.min_amplitude_deg", config.fit.min_amplitude_deg);
  // The fit's options structs, every field of their tables (base/option_table.h): a field added
  // to a table enters the key without an edit here.
  const FitConfig& fit = config.fit;
  out << SerialiseOptionFields("fit.quality", fit.quality, TraceQualityOptions::Fields())
      << SerialiseOptionFields("fit.amplitude_sweep", fit.sweep, AmplitudeSweepOptions::Fields())
      << SerialiseOptionFields("fit.glitch", fit.glitch, GlitchOptions::Fields());
  // The sweep's trend rule (I_0 (1 + c A^p), p in {1, 2}; Birge scale about the trend).
  PutText(out, "sweep_rule", "power12");
  PutLogReading(out, config);
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

bool TraceCache::Load(const std::string& key, const std::string& content_hash, TraceRecord* record,
                      std::string* problem) const {
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
  if (record->ok() &&
      !(record->inertia_total_kg_m2 > 0.0 && std::isfinite(record->inertia_total_kg_m2) &&
        record->inertia_total_std_kg_m2 >= 0.0 && std::isfinite(record->inertia_total_std_kg_m2))) {
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

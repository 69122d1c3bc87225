#include "pipeline/cache.h"

#include <cinttypes>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "pipeline/results_json.h"
#include "pipeline/user_error.h"

namespace bifilar {

uint64_t Fnv1a64(const void* data, size_t size, uint64_t hash) {
  const auto* bytes = static_cast<const unsigned char*>(data);
  for (size_t i = 0; i < size; ++i) {
    hash ^= bytes[i];
    hash *= 0x100000001b3ULL;
  }
  return hash;
}

uint64_t Fnv1a64(const std::string& text, uint64_t hash) {
  return Fnv1a64(text.data(), text.size(), hash);
}

std::string HashToHex(uint64_t hash) {
  char buffer[17];
  std::snprintf(buffer, sizeof(buffer), "%016" PRIx64, hash);
  return buffer;
}

bool ReadFileBytes(const std::string& path, std::string* bytes, std::string* why) {
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec)) {
    *why = path + ": is a folder, not a log file";
    return false;
  }
  std::ifstream in(path, std::ios::binary);
  if (!in) {
    *why = path + ": cannot open file for reading";
    return false;
  }
  std::ostringstream text;
  text << in.rdbuf();
  if (in.bad()) {
    *why = path + ": read error";
    return false;
  }
  *bytes = text.str();
  return true;
}

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
  const RigGeometry geometry =
      role == TraceRole::kTare ? config.TareGeometry() : config.AircraftGeometry();
  out << "version=" << ProgramVersion() << ';';
  out << "role=" << ToString(role) << ';';
  Put(out, "L", geometry.filar_length_m);
  Put(out, "D", geometry.filar_separation_m);
  Put(out, "m", geometry.mass_kg);
  Put(out, "g", geometry.gravity_mps2);
  Put(out, "L_std", config.uncertainties.filar_length_std_m);
  Put(out, "D_std", config.uncertainties.filar_separation_std_m);
  Put(out, "m_rig_std", config.uncertainties.mass_std_kg);
  if (role == TraceRole::kAircraft) Put(out, "m_aircraft_std", config.aircraft_mass_std_kg);
  Put(out, "g_std", config.uncertainties.gravity_std_mps2);
  Put(out, "gyro_scale_std", config.imu.gyro_scale_std);
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
  return out.str();
}

std::string CacheKey(const std::string& content_hash_hex, const std::string& fingerprint) {
  return HashToHex(Fnv1a64(fingerprint, Fnv1a64(content_hash_hex)));
}

TraceCache::TraceCache(std::string folder) : folder_(std::move(folder)) {}

std::string TraceCache::EntryPath(const std::string& key) const {
  return (std::filesystem::path(folder_) / (key + ".json")).string();
}

bool TraceCache::Load(const std::string& key, TraceRecord* record) const {
  std::string bytes, why;
  if (!ReadFileBytes(EntryPath(key), &bytes, &why)) return false;
  try {
    *record = TraceRecordFromJson(nlohmann::json::parse(bytes));
  } catch (const std::exception&) {
    return false;  // a damaged entry is refitted and overwritten
  }
  return true;
}

void TraceCache::Store(const std::string& key, const TraceRecord& record) const {
  std::error_code ec;
  std::filesystem::create_directories(folder_, ec);
  if (ec) throw UserError(folder_ + ": cannot create cache folder: " + ec.message());
  WriteFileAtomically(EntryPath(key), TraceRecordToJson(record, false).dump(1) + "\n");
}

}  // namespace bifilar

// Per-trace fit results cached in OUT/cache/, so that a rerun redoes only what changed.
//
// A cache entry is keyed by CacheKey = hash(content hash of the log bytes, FitFingerprint: the
// canonical text of every config value that can change that trace's fit record). In the key: the
// key format (TraceCache::kFormat) and program version; the role; L, D (the calibrated D, and the
// calibration's factor and std), the suspended mass, g; the budget's stds in effect (and whether
// they are the assumed ones), imu.gyro.scale_std; fit.model, fit.integrator, the file's
// fit.windows entry, fit.max/min_amplitude_deg; every field of fit.quality, fit.amplitude_sweep
// and fit.glitch, serialised from their option tables (base/option_table.h), so a new field
// cannot be left out; the log reading (imu format, columns and units, ulog, dataflash.instance,
// limits.max_decompressed_log_mb, swing axis, imu_to_body). Not in the key, because they change
// no fitted record (they act after the fit, before it on which files are read, or only on
// presentation): the rig inertia (value, table, tare, its std), rig.calibration's own keys (they
// act through the calibrated geometry above), aircraft.mass_kg of a tare log, aircraft.cg_m and
// cg_std_m, gravity_off_earth (a bound only), runs.* (which files; the pitch used and the
// attitude warning are set after the cache), ellipse.*, units, limits.max_log_mb (a log beyond it
// is not read, so has no key). tests/pipeline_cache_keys_test.cc changes every key in turn. The
// fit figure is stored beside it in OUT/figures/<key>.svg.
//
// Hash: FNV-1a 64 (base/hash.h).
#pragma once

#include <cstdint>
#include <string>

#include "base/hash.h"
#include "pipeline/config/config.h"
#include "pipeline/records/trace_record.h"

namespace bifilar {

// The text of every config value that affects the fit of one trace of `role` (see above),
// including the window override that applies to this file.
std::string FitFingerprint(const CampaignConfig& config, TraceRole role,
                           const std::optional<std::array<double, 2>>& window_s);

std::string CacheKey(const std::string& content_hash_hex, const std::string& fingerprint);

// Folder of cache entries (one JSON file per key). Thread-safe: entries are separate files
// written atomically.
//
// An entry proves it belongs to its key and is intact: it holds its key, the content hash of
// the log, the program version and a checksum (FNV-1a 64 of key, hash, version and the record's
// compact JSON), besides the record. This catches damage and editing (a scaled value, another
// trace's entry copied in, NaN); it is not a defence against someone who recomputes the
// checksum on purpose.
class TraceCache {
 public:
  // "bifilar_cache" of the entries written now; 3: the key is the canonical text of the options
  // (format 2 entries have other keys and are never found).
  static constexpr int kFormat = 3;

  explicit TraceCache(std::string folder);  // created on first Store
  // True and fills *record (fit fields) when the entry of `key` exists, proves it belongs to
  // `key` and `content_hash` (and this program version), its checksum matches and its values
  // are plausible (an ok record has a finite inertia > 0 and a finite std >= 0). False
  // otherwise: *problem empty when there is no entry or it is of an older schema_version
  // (base/version.h), else why the entry was refused (the caller refits and warns; the entry is
  // overwritten).
  bool Load(const std::string& key, const std::string& content_hash, TraceRecord* record,
            std::string* problem) const;
  // Throws UserError when the folder cannot be written. A record whose fit was abandoned by the
  // time guard (flag "time_guard", fit/trace_fit.h) is not stored: that outcome depends on the
  // machine's speed, and a faster run must fit the log again rather than replay it.
  void Store(const std::string& key, const std::string& content_hash,
             const TraceRecord& record) const;
  std::string EntryPath(const std::string& key) const;
  const std::string& folder() const { return folder_; }

 private:
  std::string folder_;
};

}  // namespace bifilar

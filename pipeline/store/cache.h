// Per-trace fit results cached in OUT/cache/, so that a rerun redoes only what changed.
//
// A cache entry is keyed by CacheKey = hash(content hash of the log bytes, fingerprint of every
// config value that affects that trace's fit): L, D (the calibrated D and the calibration's std
// when rig.calibration is applied), the suspended mass, g, their uncertainties (the budget), the model, the window override, the amplitude band, the IMU format, swing axis
// and mounting, the quality thresholds, the program version. Not in the key: the rig inertia
// (tare logs/value/table), the pitch source, the ellipse options, the units — changing those
// refits no trace. The fit figure is stored beside it in OUT/figures/<key>.svg.
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
  static constexpr int kFormat = 2;  // "bifilar_cache" of the entries written now

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

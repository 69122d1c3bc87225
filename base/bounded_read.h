// Reading an input file whole, bounded: every file bifilar reads (logs, configs, simulation
// specs, tables, the output folder's manifest, cache entries, results.json, figures) goes
// through ReadRegularFile with a size cap, so that no input can make a run read forever or fill
// the memory: a FIFO, a device (/dev/zero, /dev/urandom, also behind a symlink), a socket or a
// folder is refused before it is opened, and a file larger than its cap is refused with its size,
// the cap and how to raise it. The caps are listed in README.md ("Input size limits").
#pragma once

#include <cstdint>
#include <string>

namespace bifilar {

// The size cap of one kind of input.
struct InputCap {
  uint64_t max_bytes = 0;  // largest accepted size (bytes)
  const char* what = "";   // the kind of file, for messages ("config", "log", "cache entry")
  // How a user raises the cap ("raise limits.max_log_mb in the config"), or "" when the cap is
  // fixed (no real file of this kind comes near it).
  std::string raise;
};

// The fixed caps (bytes). A config or simulation spec is a few kB; a table holds one row per
// log or per moment (1e6 moments are ~40 MB); a cache entry is one trace's record (~10 kB);
// the manifest lists a run's files (~60 bytes each); results.json is ~10 kB per trace.
constexpr uint64_t kMaxConfigBytes = 4'000'000;       // configs and simulation specs
constexpr uint64_t kMaxTableBytes = 256'000'000;      // runs.table, rig and ellipse tables
constexpr uint64_t kMaxManifestBytes = 16'000'000;    // OUT/.bifilar-manifest.json
constexpr uint64_t kMaxCacheEntryBytes = 16'000'000;  // OUT/cache/<key>.json
// OUT/results.json, traces.csv, angles.csv, report.html (read back by `report` and the checks)
constexpr uint64_t kMaxOutputFileBytes = 256'000'000;
constexpr uint64_t kMaxFigureBytes = 64'000'000;  // OUT/figures/* (inlined in the report)
// The configurable caps of a log (limits.max_log_mb, limits.max_decompressed_log_mb), defaults.
constexpr double kDefaultMaxLogMb = 1000;
constexpr double kDefaultMaxDecompressedLogMb = 1000;

// The caps of a log as stored and of its text once decompressed (bytes; the config's
// limits.max_log_mb and limits.max_decompressed_log_mb times 1e6), named in their messages.
InputCap LogCap(uint64_t max_bytes);
InputCap DecompressedLogCap(uint64_t max_bytes);
InputCap ConfigCap();
// "runs table", "moments table", "moments table once decompressed"
InputCap TableCap(const char* what);
InputCap ManifestCap();
InputCap CacheEntryCap();
InputCap OutputFileCap();
InputCap FigureCap();

// Reads the regular file `path` (a symlink to one is fine) whole into *bytes. False, with *why
// starting with `path`, when it is missing or unreadable, not a regular file (a folder, FIFO,
// character or block device, socket: named), or larger than cap.max_bytes ("too large for a
// log: N bytes > cap M bytes; raise ..."). The file type is checked with stat before opening,
// the file opened with O_NONBLOCK (opening a FIFO never waits for a writer) and checked again
// with fstat; at most max_bytes + 1 bytes are read, so a file that grows while it is read is
// refused too. *bytes is left empty on failure.
bool ReadRegularFile(const std::string& path, const InputCap& cap, std::string* bytes,
                     std::string* why);

// The same, throwing UserError(*why).
std::string ReadRegularFileOrThrow(const std::string& path, const InputCap& cap);

// "too large for a log: N bytes > cap M bytes; raise ...": the message of a cap exceeded by
// `size` bytes, or "more than the cap of M bytes" when size_known is false (a stream cut off).
std::string CapExceeded(const InputCap& cap, uint64_t size, bool size_known);

}  // namespace bifilar

// One swing is one repeat (pipeline/trace/repeats.h, FindIdenticalLogs): logs judged identical by
// their samples, found by one hash per log.
#include <algorithm>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>
#include <unordered_map>

#include "base/hash.h"
#include "pipeline/logs/imu_log.h"
#include "pipeline/trace/repeats.h"

namespace bifilar {
namespace {

namespace fs = std::filesystem;

// What a log is compared by: its samples when it reads as a log, else its bytes.
struct Content {
  bool read = false;     // read as a log: `hash` is that of its samples
  bool regular = false;  // a regular file (the others are never compared)
  uint64_t hash = 0;
};

uint64_t HashVectors(const std::vector<Eigen::Vector3d>& v, uint64_t hash) {
  for (const Eigen::Vector3d& x : v) hash = Fnv1a64(x.data(), 3 * sizeof(double), hash);
  return hash;
}

// The samples' hash: the count, the times, gyro and accelerometer bit for bit. A sample is
// written out in full (the count first), so two logs hash alike only when the data do.
uint64_t HashSamples(const ImuData& data) {
  const uint64_t n = data.t_s.size(), n_accel = data.accel_in_imu.size();
  uint64_t hash = Fnv1a64(&n, sizeof(n));
  hash = Fnv1a64(&n_accel, sizeof(n_accel), hash);
  hash = Fnv1a64(data.t_s.data(), data.t_s.size() * sizeof(double), hash);
  hash = HashVectors(data.gyro_in_imu, hash);
  return HashVectors(data.accel_in_imu, hash);
}

// The bytes' hash, read in 1 MiB blocks (constant memory); 0 with *ok false when unreadable.
uint64_t HashBytes(const std::string& path, bool* ok) {
  std::ifstream in(path, std::ios::binary);
  *ok = static_cast<bool>(in);
  uint64_t hash = kFnvOffsetBasis;
  std::vector<char> block(1 << 20);
  while (in) {
    in.read(block.data(), static_cast<std::streamsize>(block.size()));
    hash = Fnv1a64(block.data(), static_cast<size_t>(in.gcount()), hash);
  }
  *ok = *ok && in.eof() && !in.bad();
  return hash;
}

// True when the two files hold the same bytes (both readable, read in 1 MiB blocks).
bool SameBytes(const std::string& a, const std::string& b) {
  std::ifstream fa(a, std::ios::binary), fb(b, std::ios::binary);
  if (!fa || !fb) return false;
  std::vector<char> ba(1 << 20), bb(1 << 20);
  while (fa && fb) {
    fa.read(ba.data(), static_cast<std::streamsize>(ba.size()));
    fb.read(bb.data(), static_cast<std::streamsize>(bb.size()));
    if (fa.gcount() != fb.gcount()) return false;
    if (!std::equal(ba.begin(), ba.begin() + fa.gcount(), bb.begin())) return false;
  }
  return fa.eof() && fb.eof() && !fa.bad() && !fb.bad();
}

bool SameVectors(const std::vector<Eigen::Vector3d>& a, const std::vector<Eigen::Vector3d>& b) {
  return a.size() == b.size() &&
         (a.empty() || std::memcmp(a.data(), b.data(), a.size() * sizeof(Eigen::Vector3d)) == 0);
}

// True when both read as logs with the same samples, bit for bit (the check behind a hash that
// met: FNV-1a is not a cryptographic hash, and a crafted log must not pass for another).
bool SameSamples(const std::string& a, const std::string& b, const ImuFormat& format,
                 const ImuLogOptions& options) {
  ImuData da, db;
  std::string why;
  if (!TryReadImuLog(a, format, options, &da, &why) ||
      !TryReadImuLog(b, format, options, &db, &why))
    return false;
  return da.t_s.size() == db.t_s.size() &&
         (da.t_s.empty() ||
          std::memcmp(da.t_s.data(), db.t_s.data(), da.t_s.size() * sizeof(double)) == 0) &&
         SameVectors(da.gyro_in_imu, db.gyro_in_imu) &&
         SameVectors(da.accel_in_imu, db.accel_in_imu);
}

Content ContentOf(const std::string& path, const ImuFormat& format, const ImuLogOptions& options) {
  Content c;
  std::error_code ec;
  c.regular = fs::is_regular_file(path, ec);
  if (!c.regular) return c;
  ImuData data;
  std::string why;
  if (TryReadImuLog(path, format, options, &data, &why)) {
    c.read = true;
    c.hash = HashSamples(data);
    return c;
  }
  // Not a log the fit can read (its fit says why): the bytes, unless above the log cap (then
  // the fit refuses it unread, and so does this).
  const uintmax_t size = fs::file_size(path, ec);
  if (ec || size > options.max_file_bytes) {
    c.regular = false;
    return c;
  }
  bool ok = false;
  c.hash = HashBytes(path, &ok);
  c.regular = ok;
  return c;
}

}  // namespace

std::vector<IdenticalLog> FindIdenticalLogs(const std::vector<std::string>& paths,
                                            const ImuFormat& format, const ImuLogOptions& options) {
  std::vector<IdenticalLog> same(paths.size());
  // (read as a log, hash) -> the first paths of each distinct content with that hash.
  std::unordered_map<uint64_t, std::vector<size_t>> firsts[2];
  std::unordered_map<std::string, size_t> first_of_path;
  for (size_t i = 0; i < paths.size(); ++i) {
    std::error_code ec;
    if (!fs::is_regular_file(paths[i], ec)) continue;
    // The same path again: no need to read it again.
    const auto [seen, inserted] = first_of_path.emplace(paths[i], i);
    if (!inserted) {
      const size_t j = seen->second;
      same[i] = same[j].first >= 0 ? same[j] : IdenticalLog{static_cast<int>(j), "given again"};
      continue;
    }
    const Content c = ContentOf(paths[i], format, options);
    if (!c.regular) continue;
    std::vector<size_t>& candidates = firsts[c.read ? 1 : 0][c.hash];
    for (size_t j : candidates) {
      if (fs::equivalent(paths[i], paths[j], ec)) {
        same[i] = {static_cast<int>(j), "the same file as"};
      } else if (SameBytes(paths[i], paths[j])) {
        same[i] = {static_cast<int>(j), "the same bytes as"};
      } else if (c.read && SameSamples(paths[i], paths[j], format, options)) {
        same[i] = {static_cast<int>(j), "the same samples as"};
      }
      if (same[i].first >= 0) break;
    }
    if (same[i].first < 0) candidates.push_back(i);
  }
  return same;
}

DistinctLogs DropIdenticalLogs(const std::vector<std::string>& paths, const ImuFormat& format,
                               const ImuLogOptions& options) {
  DistinctLogs d;
  const std::vector<IdenticalLog> same = FindIdenticalLogs(paths, format, options);
  for (size_t i = 0; i < paths.size(); ++i) {
    if (same[i].first < 0) {
      d.kept.push_back(paths[i]);
      continue;
    }
    const std::string& first = paths[same[i].first];
    d.dropped.emplace_back(paths[i], first);
    const std::string relation =
        same[i].relation == "given again" ? same[i].relation : same[i].relation + " " + first;
    const std::string differs =
        same[i].relation == "the same samples as"
            ? " (the files differ only in what the reader skips: line ends, blank or comment "
              "lines)"
            : "";
    d.warnings.push_back(
        paths[i] + ": " + relation + differs +
        ": one swing is one repeat, so it is dropped from the repeats (counted twice it would "
        "shrink the std by sqrt(2) and hide the scatter between repeats)");
  }
  return d;
}

}  // namespace bifilar

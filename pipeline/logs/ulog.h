// Reading PX4 ULog flight logs (.ulg): one topic's fields as a time series, and from them the
// same ImuData the CSV reader gives (pipeline/logs/imu_log.h).
//
// Written in-house (no ULog library is packaged for Debian) after PX4's "ULog File Format"
// specification: the 16-byte header (magic "ULog" 01 12 35, version, start time), the flag-bits
// message ('B': incompatible bits other than "data appended" are refused; appended data sections
// are read at their offsets, a message cut by the next section is dropped), format definitions
// ('F': nested types, fixed arrays, `_padding` fields skipped, a trailing padding field not
// logged), info/multi-info/parameter messages ('I', 'M', 'P', 'Q': skipped), subscriptions ('A',
// by topic name and multi_id), data ('D'), dropouts ('O': the lost samples stay gaps in time, with
// a warning), sync ('S'), logging ('L', 'C') and unknown message types (skipped). Scalars are
// little-endian.
//
// Bad input is a UserError naming the file and the byte offset, never a crash: a file shorter
// than the header, bad magic, unknown incompatible flags, a message header that cannot be one
// (size 0, type not a letter), a bad format definition (unknown or circular nested type, nesting
// deeper than kUlogMaxNestingDepth levels, a type larger than a data message can hold (65535
// bytes) or whose flattened field names exceed kUlogMaxFlatNameBytes: all checked before
// anything is allocated for the type, so a crafted file cannot make the reader allocate more
// than a few times its own size plus ~10 MB), data
// for a msg_id that was never subscribed, data of the wrong size for its format, NaN or inf in a
// requested field. A log that ends inside a message (the logger stopped mid-write) is read up to
// the last whole message, with a warning saying how many bytes (and about how many samples of
// the requested topic) that leaves unread, as the specification requires.
#pragma once

#include <cmath>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "pendulum/imu_data.h"
#include "pipeline/logs/imu_format.h"
#include "pipeline/logs/imu_log_options.h"

namespace bifilar {

// The 7 magic bytes every ULog file starts with.
inline constexpr char kUlogMagic[] = {'U', 'L', 'o', 'g', '\x01', '\x12', '\x35'};

// Nested types may be this many levels deep (the topic counts as one level; PX4's deepest topics
// use 3). Deeper definitions are refused with a message saying so.
inline constexpr int kUlogMaxNestingDepth = 64;
// The flattened field names of one type ("v[1].xy[0]", ...) may take at most this many bytes in
// all (PX4's largest topics take ~10 kB).
inline constexpr uint64_t kUlogMaxFlatNameBytes = uint64_t{4} << 20;

// True when `bytes` starts with the ULog magic.
bool LooksLikeUlog(std::string_view bytes);

// True when the IMU reader should read `bytes` as ULog: format.container is kUlog, or kAuto and
// the bytes start with the ULog magic.
bool UseUlogReader(std::string_view bytes, const ImuFormat& format);

// The field defaults of the topics commonly holding an IMU, for `topic`: sensor_combined
// (gyro_rad[0..2], accelerometer_m_s2[0..2]), vehicle_angular_velocity (xyz[0..2], no accel),
// sensor_gyro (x, y, z, no accel). False for any other topic (the fields must then be given).
bool UlogTopicDefaults(const std::string& topic, UlogSelection* selection);

// What to decode: one subscription and some of its fields (flattened names, as listed by
// UlogContents::fields: "gyro_rad[0]", nested "parent.child[1]").
struct UlogRequest {
  std::string topic;                // message name, case sensitive
  int multi_id = 0;                 // instance
  std::vector<std::string> fields;  // each must exist in the topic's format
  // Also note each subscription's first and last top-level `timestamp` (UlogSubscription), so
  // one pass lists every topic with its rate (`bifilar inspect`).
  bool topic_timestamps = false;
};

struct UlogSubscription {
  std::string topic;
  int multi_id = 0;
  int msg_id = 0;
  long samples = 0;  // data messages seen
  // With UlogRequest::topic_timestamps: the first and last value of the topic's top-level scalar
  // `timestamp` field (as stored, us); NaN when it has none or a sample is too short to hold it.
  double first_timestamp_us = NAN, last_timestamp_us = NAN;
};

struct UlogDropout {
  uint64_t byte_offset = 0;  // of the 'O' message
  int duration_ms = 0;       // lost logging time (ms)
  long samples_before = 0;   // requested samples decoded before it
};

struct UlogContents {
  int version = 0;                              // file format version (1 today)
  uint64_t start_timestamp_us = 0;              // header timestamp (us)
  std::vector<UlogSubscription> subscriptions;  // in the order of their 'A' messages
  std::vector<UlogDropout> dropouts;
  std::vector<std::string> warnings;  // cut-short tail, unknown version, ...
  long log_messages = 0;              // 'L' and 'C' (printf) messages

  // The request's topic was subscribed: `fields` lists its fields (flattened, padding left
  // out), `values` the requested fields row-major (request.fields.size() per sample, as stored:
  // integers and floats converted to double, timestamps unwrapped if narrower than 64 bits),
  // `value_offsets` the byte offset of each sample's 'D' message.
  bool found = false;
  std::vector<std::string> fields;
  std::vector<std::string> field_types;  // "float", "uint64_t", ... beside `fields`
  std::vector<double> values;
  std::vector<uint64_t> value_offsets;
  long samples() const { return static_cast<long>(value_offsets.size()); }
};

// Parses a whole ULog file held in `bytes`. `name` stands for the file in messages. Throws
// UserError "name: byte N: ..." on the bad input listed at the top; a requested field missing
// from the topic's format is an error listing the fields there are. A topic that is not
// subscribed is not an error here (found = false).
UlogContents ParseUlog(std::string_view bytes, const std::string& name, const UlogRequest& request);

// The IMU series of a ULog file, chosen by format.ulog, as ReadImuLog gives a CSV: time in s,
// the same timestamp repair, warnings and options. A topic or field that is not in the file is
// an error naming it and listing the topics (with multi_id) or fields that are.
ImuData ReadUlogImu(std::string_view bytes, const std::string& name, const ImuFormat& format,
                    const ImuLogOptions& options = ImuLogOptions());

}  // namespace bifilar

// Reading ArduPilot DataFlash logs (.bin): the messages a log defines, their counts, rates and
// instances (`bifilar inspect`), and from the IMU messages the same ImuData the CSV reader gives
// (pipeline/logs/imu_log.h). The format, with its sources (ArduPilot's AP_Logger/LogStructure.h
// and its "Onboard logs" pages), is in docs/dataflash.md; written in-house, no pymavlink.
//
// A log is a stream of messages, each "A3 95 <type>" then the fields its FMT message (type 128,
// 89 bytes) laid out: little-endian, packed, format characters b B h H i I f d n N Z c C e E L
// M q Q a (c C e E are stored x100, L as degrees x1e7). FMTU gives each field a unit and a
// multiplier id (UNIT, MULT define them); the multiplier applies to the raw stored value.
//
// What the reader accepts, as ArduPilot's own tools do (pymavlink DFReader): messages of types
// it has no use for are skipped by their FMT length; FMT may redefine a type; bytes that are not
// a message (bad sync bytes, garbage between messages) are skipped up to the next header of a
// defined type that is followed by another header, and a log cut mid-message is read to its last
// whole message: both with a warning saying how many bytes were skipped and where. After
// skipped bytes, a message is only taken when the bytes after it start another message (or end
// the file), and a type's messages are only taken unchecked once its length has framed one that
// way: so a wrong FMT length is found rather than read as data.
//
// Bad input is a UserError naming the file and what was found, never a crash: not DataFlash (no
// message anywhere), no IMU message (the messages found are listed), an FMT of the IMU message
// whose length is too short for its format or that does not match the messages in the file.
#pragma once

#include <cmath>
#include <cstdint>
#include <map>
#include <string>
#include <string_view>
#include <vector>

#include "pendulum/imu_data.h"
#include "pipeline/logs/imu_log_options.h"

namespace bifilar {

inline constexpr unsigned char kDataflashHead1 = 0xA3;
inline constexpr unsigned char kDataflashHead2 = 0x95;
inline constexpr int kDataflashFmtType = 128;   // the FMT message
inline constexpr int kDataflashFmtLength = 89;  // its length, header included
// A stream with a step this many times its mean step and longer than kIrregularGapS is not
// regular (no rate is given): dropouts of a logging stream last a fraction of a second; a
// PARM burst at the start and a change minutes later, or GPS time jumping at the fix, do not.
inline constexpr double kIrregularStepFactor = 10.0;
inline constexpr double kIrregularGapS = 1.0;
// The largest instance value (imu.dataflash.instance is in [-1, 255]; ArduPilot logs 0-2).
inline constexpr int kMaxDataflashInstance = 255;

// True when `bytes` starts with the header of a FMT message (A3 95 80), as every log does.
bool LooksLikeDataflash(std::string_view bytes);
// True when `path` ends in .bin or .bin.gz (any case).
bool NamedLikeDataflash(const std::string& path);

// Bytes of one field of format character `c` (0: not a DataFlash format character).
int DataflashFieldSize(char c);

// One message type as its (last) FMT defines it.
struct DataflashFormat {
  int type = 0;
  int length = 0;  // bytes, the 3-byte header included
  std::string name, format;
  std::vector<std::string> labels;
  std::string units, multipliers;  // FMTU: one id per field; "" when the log has none
  uint64_t byte_offset = 0;        // of its FMT message
  // The format characters are known, one label each, and fit `length`. When false, messages of
  // the type are still skipped by `length`, but not decoded; `problem` says why.
  bool decodable = false;
  std::string problem;
  std::vector<int> offsets;  // of each field in the message body (after the header)
  // When decodable: the numeric TimeUS/TimeMS and I/Instance fields (-1: none).
  int time_index = -1, instance_index = -1;
};

// What a log holds of one message name.
struct DataflashMessageInfo {
  std::string name;
  long count = 0;
  double first_time_s = NAN, last_time_s = NAN;  // from TimeUS or TimeMS; NaN when none
  std::string time_field;                        // "TimeUS", "TimeMS"; "" when none
  long timed = 0;                                // messages with a time field
  double max_step_s = 0.0;                       // largest step between consecutive ones
  long backward_steps = 0;                       // steps back in time
  std::string instance_field;                    // "I" or "Instance"; "" when none
  std::map<int, long> instances;                 // messages per instance value
  // Messages whose instance field is not an instance (NaN, negative, fractional or beyond
  // kMaxDataflashInstance: a damaged value), and the first such value as text ("1e+06", "nan").
  long invalid_instances = 0;
  std::string invalid_instance_example;
  // (count - 1) / span for a regular stream; 0 when the messages carry no time or are not
  // regular (a burst of PARM at the start and a few more later, GPS time jumping at the fix):
  // a rate there would be a number without meaning.
  double rate_hz() const;
  // Every message timed, at least 3, time increasing, no step over kIrregularStepFactor times
  // the mean step and over kIrregularGapS.
  bool regular() const;
};

// Which message to decode: `fields` by label, each as stored with the format character's scale
// (c C e E: / 100, L: / 1e7); only the messages whose `instance_field` equals `instance` when
// `instance_field` is set.
struct DataflashRequest {
  std::string message;
  std::vector<std::string> fields;
  std::string instance_field;
  int instance = 0;
};

struct DataflashContents {
  std::map<int, DataflashFormat> formats;      // by type
  std::vector<DataflashMessageInfo> messages;  // in the order first seen
  std::map<char, std::string> unit_labels;     // UNIT (and ArduPilot's table when absent)
  std::map<char, double> multiplier_values;    // MULT (and ArduPilot's table when absent)
  std::vector<std::string> warnings;           // skipped bytes, cut tail, bad FMTs, simulated
  uint64_t skipped_bytes = 0;                  // bytes that are not part of a whole message
  long messages_read = 0;
  // Headers of a decodable type whose next message was not where its length says: by type.
  std::map<int, long> misframed;

  // The request: values row-major (fields.size() per message), the byte of each message, and for
  // each field its FMTU unit label ("" unknown) and multiplier (NaN: none or unknown).
  std::vector<double> values;
  std::vector<uint64_t> value_offsets;
  std::vector<std::string> field_units;
  std::vector<double> field_multipliers;
  std::vector<char> field_chars;
  long rows() const { return static_cast<long>(value_offsets.size()); }

  const DataflashMessageInfo* Find(const std::string& name) const;
  const DataflashFormat* FormatOf(const std::string& name) const;
};

// Parses a whole DataFlash log held in `bytes`; `name` stands for the file in messages. Throws
// UserError when no message is found at all, and when the requested message's FMT cannot be
// decoded or a requested field is not in it.
DataflashContents ParseDataflash(std::string_view bytes, const std::string& name,
                                 const DataflashRequest& request = DataflashRequest());

// The IMU series of a DataFlash log, as ReadImuLog gives a CSV: time in s, gyro in rad/s,
// specific force in m/s^2, the same timestamp repair and warnings. Reads IMU (its `I` field, or
// IMU/IMU2/IMU3 in older logs; TimeUS, or TimeMS in older logs), else GYR (with ACC of the same
// instance, nearest in time) of instance options.dataflash_instance (-1: the lowest in the log).
ImuData ReadDataflashImu(std::string_view bytes, const std::string& name,
                         const ImuLogOptions& options = ImuLogOptions());

}  // namespace bifilar

// Writing PX4 ULog files (.ulg): the inverse of pipeline/logs/ulog.h, for `bifilar simulate` and
// for tests that need ULog files with dropouts, appended data, nested types or a cut-short tail.
// Follows PX4's "ULog File Format" specification: little-endian, version 1, flag bits first.
#pragma once

#include <cstdint>
#include <string>

#include "pendulum/imu_data.h"

namespace bifilar {

// A little-endian message payload.
class UlogPayload {
 public:
  UlogPayload& U8(uint8_t v);
  UlogPayload& U16(uint16_t v);
  UlogPayload& U32(uint32_t v);
  UlogPayload& I32(int32_t v);
  UlogPayload& U64(uint64_t v);
  UlogPayload& F32(float v);
  UlogPayload& F64(double v);
  UlogPayload& Bytes(const std::string& bytes);
  const std::string& str() const { return bytes_; }

 private:
  std::string bytes_;
};

// Builds a ULog file in memory, message by message. The header and the flag-bits message are
// written by the constructor; every other message is appended in call order.
class UlogWriter {
 public:
  explicit UlogWriter(uint64_t start_timestamp_us = 0);

  // 'F': "name:type field;type[n] field;..." (nested types by their format name).
  void Format(const std::string& definition);
  // 'I': an information message whose value is a string, key "char[N] name".
  void Info(const std::string& name, const std::string& value);
  // 'P': a float parameter.
  void Parameter(const std::string& name, float value);
  // 'A': subscribes `topic` (a format name) as `msg_id`.
  void AddLogged(const std::string& topic, uint8_t multi_id, uint16_t msg_id);
  // 'D': one sample of subscription `msg_id`; `payload` as its format lays it out.
  void Data(uint16_t msg_id, const std::string& payload);
  // 'O': a dropout of `duration_ms`.
  void Dropout(uint16_t duration_ms);
  // 'S': a sync message.
  void Sync();
  // 'L': a printf-style log line.
  void Logging(uint8_t level, uint64_t timestamp_us, const std::string& text);
  // Any message, e.g. a type this writer does not know (the size is taken from `body`).
  void Message(char type, const std::string& body);
  // Raw bytes, e.g. a message cut short (the logger stopped mid-write).
  void Raw(const std::string& bytes) { bytes_ += bytes; }
  // Starts an appended data section here: sets the "data appended" incompatible flag bit and the
  // first free appended offset (at most 3) to the current size. Returns false when all 3 are used.
  bool BeginAppendedSection();

  const std::string& bytes() const { return bytes_; }

 private:
  std::string bytes_;
  int appended_ = 0;
};

// The ULog bytes of an IMU log: with accelerometer, topic `sensor_combined` (timestamp,
// gyro_rad[3], accelerometer_m_s2[3] and PX4's other fields, float32 values, a trailing padding
// field); gyro-only, topic `vehicle_angular_velocity` (timestamp, timestamp_sample, xyz[3]).
// Timestamps are rounded to whole microseconds. Throws UserError on mismatched lengths or
// non-finite values. A non-empty `simulated_origin` (SimulatedLogOrigin,
// pipeline/logs/simulated_log.h) adds the information message that marks the log as simulated.
std::string FormatImuUlog(const ImuData& data, const std::string& simulated_origin = "");

// FormatImuUlog written atomically to `path` (gzip-compressed when it ends in ".gz").
void WriteImuUlog(const std::string& path, const ImuData& data,
                  const std::string& simulated_origin = "");

}  // namespace bifilar

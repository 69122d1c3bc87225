// Writing ArduPilot DataFlash logs (.bin): the inverse of pipeline/logs/dataflash.h, for
// `bifilar simulate --trace swing.bin` and for tests that need logs with every format
// character, FMTU/UNIT/MULT, several instances, garbage between messages or a cut-short tail.
// Messages are laid out as ArduPilot's AP_Logger writes them (docs/dataflash.md): "A3 95 <type>",
// then the fields packed, little-endian.
#pragma once

#include <cstdint>
#include <string>

#include "pendulum/imu_data.h"

namespace bifilar {

// A little-endian, packed message body.
class DataflashPayload {
 public:
  DataflashPayload& I8(int8_t v) { return Put(static_cast<uint8_t>(v), 1); }
  DataflashPayload& U8(uint8_t v) { return Put(v, 1); }
  DataflashPayload& I16(int16_t v) { return Put(static_cast<uint16_t>(v), 2); }
  DataflashPayload& U16(uint16_t v) { return Put(v, 2); }
  DataflashPayload& I32(int32_t v) { return Put(static_cast<uint32_t>(v), 4); }
  DataflashPayload& U32(uint32_t v) { return Put(v, 4); }
  DataflashPayload& I64(int64_t v) { return Put(static_cast<uint64_t>(v), 8); }
  DataflashPayload& U64(uint64_t v) { return Put(v, 8); }
  DataflashPayload& F32(float v);
  DataflashPayload& F64(double v);
  // A fixed-width string field (n: 4, N: 16, Z: 64), NUL-padded; longer text is cut.
  DataflashPayload& Text(const std::string& text, size_t width);
  const std::string& str() const { return bytes_; }

 private:
  DataflashPayload& Put(uint64_t v, int bytes);
  std::string bytes_;
};

// Builds a DataFlash log in memory. The constructor writes the FMT of FMT; every other message
// is appended in call order.
class DataflashWriter {
 public:
  DataflashWriter();

  // FMT: message `type` named `name` (<= 4 chars), `format` characters, comma-separated `labels`.
  // `length` 0: computed from the format (3 + the fields); another value is written as given.
  void Format(int type, const std::string& name, const std::string& format,
              const std::string& labels, int length = 0);
  // FMTU of `type` (needs the FMTU format, written by UnitFormats()), UNIT and MULT messages.
  void UnitFormats();  // the FMT of UNIT (177), FMTU (178), MULT (179)
  void FormatUnits(int type, const std::string& units, const std::string& multipliers);
  void Unit(char id, const std::string& label);
  void Multiplier(char id, double value);
  // A message of `type` with `body` (header added).
  void Message(int type, const std::string& body);
  // Raw bytes (garbage, a cut message).
  void Raw(const std::string& bytes) { bytes_ += bytes; }

  const std::string& bytes() const { return bytes_; }

 private:
  std::string bytes_;
};

// The DataFlash bytes of an IMU log as ArduPilot 4.x writes them: with accelerometer, IMU
// messages (TimeUS,I,GyrX,GyrY,GyrZ,AccX,AccY,AccZ,...; float32 values, instance 0); gyro-only,
// GYR messages (TimeUS,I,SampleUS,GyrX,GyrY,GyrZ). FMTU, UNIT and MULT as ArduPilot writes
// them. Timestamps are rounded to whole microseconds. A non-empty `simulated_origin` adds the MSG
// "simulated by <origin>" that marks the log as simulated (pipeline/logs/simulated_log.h).
// Throws UserError on mismatched lengths, non-finite values or negative times.
std::string FormatImuDataflash(const ImuData& data, const std::string& simulated_origin = "");

// FormatImuDataflash written atomically to `path` (gzip-compressed when it ends in ".gz").
void WriteImuDataflash(const std::string& path, const ImuData& data,
                       const std::string& simulated_origin = "");

}  // namespace bifilar

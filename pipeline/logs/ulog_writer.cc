#include "pipeline/logs/ulog_writer.h"

#include <cmath>
#include <cstring>

#include "base/atomic_file.h"
#include "base/gzip.h"
#include "base/user_error.h"
#include "pipeline/logs/imu_log_writer.h"
#include "pipeline/logs/simulated_log.h"
#include "pipeline/logs/ulog.h"

namespace bifilar {
namespace {

constexpr size_t kFlagBitsOffset = 16;  // the flag-bits message follows the 16-byte header

template <typename U>
void PutUnsigned(U v, std::string* out) {
  for (size_t i = 0; i < sizeof(U); ++i) out->push_back(static_cast<char>((v >> (8 * i)) & 0xFF));
}

template <typename U>
void PokeUnsigned(U v, size_t at, std::string* out) {
  for (size_t i = 0; i < sizeof(U); ++i) (*out)[at + i] = static_cast<char>((v >> (8 * i)) & 0xFF);
}

}  // namespace

UlogPayload& UlogPayload::U8(uint8_t v) {
  PutUnsigned(v, &bytes_);
  return *this;
}
UlogPayload& UlogPayload::U16(uint16_t v) {
  PutUnsigned(v, &bytes_);
  return *this;
}
UlogPayload& UlogPayload::U32(uint32_t v) {
  PutUnsigned(v, &bytes_);
  return *this;
}
UlogPayload& UlogPayload::I32(int32_t v) {
  PutUnsigned(static_cast<uint32_t>(v), &bytes_);
  return *this;
}
UlogPayload& UlogPayload::U64(uint64_t v) {
  PutUnsigned(v, &bytes_);
  return *this;
}
UlogPayload& UlogPayload::F32(float v) {
  uint32_t bits;
  std::memcpy(&bits, &v, sizeof(bits));
  return U32(bits);
}
UlogPayload& UlogPayload::F64(double v) {
  uint64_t bits;
  std::memcpy(&bits, &v, sizeof(bits));
  return U64(bits);
}
UlogPayload& UlogPayload::Bytes(const std::string& bytes) {
  bytes_ += bytes;
  return *this;
}

UlogWriter::UlogWriter(uint64_t start_timestamp_us) {
  bytes_.assign(kUlogMagic, sizeof(kUlogMagic));
  bytes_.push_back('\x01');  // version
  PutUnsigned(start_timestamp_us, &bytes_);
  Message('B', std::string(40, '\0'));  // compat[8], incompat[8], appended_offsets[3]
}

void UlogWriter::Message(char type, const std::string& body) {
  if (body.size() > 65535)
    throw UserError("ULog writer: a message of " + std::to_string(body.size()) +
                    " bytes is too long");
  PutUnsigned(static_cast<uint16_t>(body.size()), &bytes_);
  bytes_.push_back(type);
  bytes_ += body;
}

void UlogWriter::Format(const std::string& definition) { Message('F', definition); }

void UlogWriter::Info(const std::string& name, const std::string& value) {
  const std::string key = "char[" + std::to_string(value.size()) + "] " + name;
  Message('I', UlogPayload().U8(static_cast<uint8_t>(key.size())).Bytes(key).Bytes(value).str());
}

void UlogWriter::Parameter(const std::string& name, float value) {
  const std::string key = "float " + name;
  Message('P', UlogPayload().U8(static_cast<uint8_t>(key.size())).Bytes(key).F32(value).str());
}

void UlogWriter::AddLogged(const std::string& topic, uint8_t multi_id, uint16_t msg_id) {
  Message('A', UlogPayload().U8(multi_id).U16(msg_id).Bytes(topic).str());
}

void UlogWriter::Data(uint16_t msg_id, const std::string& payload) {
  Message('D', UlogPayload().U16(msg_id).Bytes(payload).str());
}

void UlogWriter::Dropout(uint16_t duration_ms) {
  Message('O', UlogPayload().U16(duration_ms).str());
}

void UlogWriter::Sync() { Message('S', "\x2F\x73\x13\x20\x25\x0C\xBB\x12"); }

void UlogWriter::Logging(uint8_t level, uint64_t timestamp_us, const std::string& text) {
  Message('L', UlogPayload().U8(level).U64(timestamp_us).Bytes(text).str());
}

bool UlogWriter::BeginAppendedSection() {
  if (appended_ >= 3) return false;
  const size_t body = kFlagBitsOffset + 3;
  bytes_[body + 8] = static_cast<char>(bytes_[body + 8] | 1);  // incompat_flags[0] bit 0
  PokeUnsigned(static_cast<uint64_t>(bytes_.size()), body + 16 + 8 * appended_, &bytes_);
  ++appended_;
  return true;
}

std::string FormatImuUlog(const ImuData& data, const std::string& simulated_origin) {
  const size_t n = data.t_s.size();
  if (data.gyro_in_imu.size() != n) throw UserError("IMU log: gyro and time lengths differ");
  const bool accel = data.has_accel();
  if (accel && data.accel_in_imu.size() != n)
    throw UserError("IMU log: accelerometer and time lengths differ");
  UlogWriter w(0);
  w.Info("sys_name", "bifilar simulate");
  if (!simulated_origin.empty()) w.Info(kSimulatedUlogInfoKey, simulated_origin);
  if (accel) {
    // PX4's sensor_combined; the trailing padding field is not logged (spec).
    w.Format(
        "sensor_combined:uint64_t timestamp;float[3] gyro_rad;uint32_t gyro_integral_dt;"
        "int32_t accelerometer_timestamp_relative;float[3] accelerometer_m_s2;"
        "uint32_t accelerometer_integral_dt;uint8_t accelerometer_clipping;"
        "uint8_t[3] _padding0;");
    w.AddLogged("sensor_combined", 0, 0);
  } else {
    w.Format(
        "vehicle_angular_velocity:uint64_t timestamp;uint64_t timestamp_sample;float[3] xyz;"
        "uint8_t[4] _padding0;");
    w.AddLogged("vehicle_angular_velocity", 0, 0);
  }
  for (size_t k = 0; k < n; ++k) {
    bool finite =
        std::isfinite(data.t_s[k]) && data.gyro_in_imu[k].allFinite() && data.t_s[k] >= 0.0;
    if (accel) finite = finite && data.accel_in_imu[k].allFinite();
    if (!finite)
      throw UserError("IMU log: sample " + std::to_string(k) +
                      " is not finite (or its time is negative)");
    const uint64_t t_us = static_cast<uint64_t>(std::llround(data.t_s[k] * 1e6));
    UlogPayload p;
    p.U64(t_us);
    if (accel) {
      const uint32_t dt_us =
          k > 0 ? static_cast<uint32_t>(std::llround((data.t_s[k] - data.t_s[k - 1]) * 1e6)) : 0;
      for (int i = 0; i < 3; ++i) p.F32(static_cast<float>(data.gyro_in_imu[k][i]));
      p.U32(dt_us).I32(0);
      for (int i = 0; i < 3; ++i) p.F32(static_cast<float>(data.accel_in_imu[k][i]));
      p.U32(dt_us).U8(0);
    } else {
      p.U64(t_us);
      for (int i = 0; i < 3; ++i) p.F32(static_cast<float>(data.gyro_in_imu[k][i]));
    }
    w.Data(0, p.str());
  }
  return w.bytes();
}

void WriteImuUlog(const std::string& path, const ImuData& data,
                  const std::string& simulated_origin) {
  const std::string bytes = FormatImuUlog(data, simulated_origin);
  const bool gzip = path.size() > 3 && path.compare(path.size() - 3, 3, ".gz") == 0;
  WriteFileAtomically(path, gzip ? GzipCompress(bytes) : bytes);
}

}  // namespace bifilar

#include "pipeline/logs/dataflash_writer.h"

#include <cmath>
#include <cstring>

#include "base/atomic_file.h"
#include "base/gzip.h"
#include "base/user_error.h"
#include "pipeline/logs/dataflash.h"

namespace bifilar {
namespace {

// Message types as ArduPilot numbers them (AP_Logger/LogStructure.h).
constexpr int kUnitType = 177, kFmtuType = 178, kMultType = 179, kMsgType = 91;
constexpr int kImuType = 48, kGyrType = 222;

}  // namespace

DataflashPayload& DataflashPayload::Put(uint64_t v, int bytes) {
  for (int i = 0; i < bytes; ++i) bytes_.push_back(static_cast<char>((v >> (8 * i)) & 0xFF));
  return *this;
}

DataflashPayload& DataflashPayload::F32(float v) {
  uint32_t bits;
  std::memcpy(&bits, &v, sizeof(bits));
  return U32(bits);
}

DataflashPayload& DataflashPayload::F64(double v) {
  uint64_t bits;
  std::memcpy(&bits, &v, sizeof(bits));
  return U64(bits);
}

DataflashPayload& DataflashPayload::Text(const std::string& text, size_t width) {
  std::string field = text.substr(0, width);
  field.resize(width, '\0');
  bytes_ += field;
  return *this;
}

DataflashWriter::DataflashWriter() {
  Format(kDataflashFmtType, "FMT", "BBnNZ", "Type,Length,Name,Format,Columns");
}

void DataflashWriter::Format(int type, const std::string& name, const std::string& format,
                             const std::string& labels, int length) {
  if (length == 0) {
    length = 3;
    for (char c : format) length += DataflashFieldSize(c);
  }
  Message(kDataflashFmtType, DataflashPayload()
                                 .U8(static_cast<uint8_t>(type))
                                 .U8(static_cast<uint8_t>(length))
                                 .Text(name, 4)
                                 .Text(format, 16)
                                 .Text(labels, 64)
                                 .str());
}

void DataflashWriter::UnitFormats() {
  Format(kUnitType, "UNIT", "QbZ", "TimeUS,Id,Label");
  Format(kFmtuType, "FMTU", "QBNN", "TimeUS,FmtType,UnitIds,MultIds");
  Format(kMultType, "MULT", "Qbd", "TimeUS,Id,Mult");
}

void DataflashWriter::FormatUnits(int type, const std::string& units,
                                  const std::string& multipliers) {
  Message(kFmtuType, DataflashPayload()
                         .U64(0)
                         .U8(static_cast<uint8_t>(type))
                         .Text(units, 16)
                         .Text(multipliers, 16)
                         .str());
}

void DataflashWriter::Unit(char id, const std::string& label) {
  Message(kUnitType, DataflashPayload().U64(0).I8(id).Text(label, 64).str());
}

void DataflashWriter::Multiplier(char id, double value) {
  Message(kMultType, DataflashPayload().U64(0).I8(id).F64(value).str());
}

void DataflashWriter::Message(int type, const std::string& body) {
  bytes_.push_back(static_cast<char>(kDataflashHead1));
  bytes_.push_back(static_cast<char>(kDataflashHead2));
  bytes_.push_back(static_cast<char>(type));
  bytes_ += body;
}

std::string FormatImuDataflash(const ImuData& data, const std::string& simulated_origin) {
  const size_t n = data.t_s.size();
  if (data.gyro_in_imu.size() != n) throw UserError("IMU log: gyro and time lengths differ");
  const bool accel = data.has_accel();
  if (accel && data.accel_in_imu.size() != n) {
    throw UserError("IMU log: accelerometer and time lengths differ");
  }
  DataflashWriter w;
  w.UnitFormats();
  w.Format(kMsgType, "MSG", "QZ", "TimeUS,Message");
  if (accel) {
    w.Format(kImuType, "IMU", "QBffffffIIfBBHH",
             "TimeUS,I,GyrX,GyrY,GyrZ,AccX,AccY,AccZ,EG,EA,T,GH,AH,GHz,AHz");
  } else {
    w.Format(kGyrType, "GYR", "QBQfff", "TimeUS,I,SampleUS,GyrX,GyrY,GyrZ");
  }
  for (const auto& [id, label] : {std::pair<char, const char*>{'-', ""},
                                  {'#', "instance"},
                                  {'E', "rad/s"},
                                  {'O', "degC"},
                                  {'o', "m/s/s"},
                                  {'s', "s"},
                                  {'z', "Hz"}}) {
    w.Unit(id, label);
  }
  for (const auto& [id, value] : {std::pair<char, double>{'-', 0.0}, {'0', 1.0}, {'F', 1e-6}}) {
    w.Multiplier(id, value);
  }
  if (accel)
    w.FormatUnits(kImuType, "s#EEEooo--O--zz", "F-000000-----00");
  else
    w.FormatUnits(kGyrType, "s#sEEE", "F-F000");
  if (!simulated_origin.empty()) {
    w.Message(kMsgType,
              DataflashPayload().U64(0).Text("simulated by " + simulated_origin, 64).str());
  }
  for (size_t k = 0; k < n; ++k) {
    bool finite =
        std::isfinite(data.t_s[k]) && data.gyro_in_imu[k].allFinite() && data.t_s[k] >= 0.0;
    if (accel) finite = finite && data.accel_in_imu[k].allFinite();
    if (!finite) {
      throw UserError("IMU log: sample " + std::to_string(k) +
                      " is not finite (or its time is negative)");
    }
    const uint64_t t_us = static_cast<uint64_t>(std::llround(data.t_s[k] * 1e6));
    DataflashPayload p;
    p.U64(t_us).U8(0);
    if (!accel) p.U64(t_us);
    for (int i = 0; i < 3; ++i) p.F32(static_cast<float>(data.gyro_in_imu[k][i]));
    if (accel) {
      for (int i = 0; i < 3; ++i) p.F32(static_cast<float>(data.accel_in_imu[k][i]));
      p.U32(0).U32(0).F32(25.0f).U8(1).U8(1).U16(1000).U16(1000);
    }
    w.Message(accel ? kImuType : kGyrType, p.str());
  }
  return w.bytes();
}

void WriteImuDataflash(const std::string& path, const ImuData& data,
                       const std::string& simulated_origin) {
  const std::string bytes = FormatImuDataflash(data, simulated_origin);
  const bool gzip = path.size() > 3 && path.compare(path.size() - 3, 3, ".gz") == 0;
  WriteFileAtomically(path, gzip ? GzipCompress(bytes) : bytes);
}

}  // namespace bifilar

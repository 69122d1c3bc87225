#include "pipeline/logs/imu_log_writer.h"

#include <cmath>
#include <cstdio>

#include "base/atomic_file.h"
#include "base/gzip.h"
#include "base/option_check.h"
#include "base/user_error.h"

namespace bifilar {
namespace {

// "%.*g" without locale surprises: snprintf uses the C locale's '.' unless the program changed
// LC_NUMERIC, which bifilar never does.
void AppendNumber(double value, int digits, std::string* out) {
  char buffer[40];
  const int len = std::snprintf(buffer, sizeof(buffer), "%.*g", digits, value);
  out->append(buffer, static_cast<size_t>(len));
}

}  // namespace

bool ImuLogWriteOptions::Check(std::string* why) const {
  CheckFailure f;
  const bool ok = CheckIn("significant_digits", significant_digits, 6, 17, Ends::kClosed, &f) &&
                  (line_end == "\n" || line_end == "\r\n" ||
                   CheckFailText("line_end", line_end, "\"\\n\" or \"\\r\\n\"", &f));
  return ok || FailWith(f, why);
}

std::string FormatImuLog(const ImuData& data, const ImuFormat& format,
                         const ImuLogWriteOptions& options) {
  std::string why;
  if (!format.Check(&why)) throw UserError("IMU format: " + why);
  if (!options.Check(&why)) throw UserError("IMU log writer: " + why);
  const size_t n = data.t_s.size();
  if (data.gyro_in_imu.size() != n) throw UserError("IMU log: gyro and time lengths differ");
  if (format.has_accel() && data.accel_in_imu.size() != n) {
    throw UserError("IMU log: the format names accelerometer columns but the data has none");
  }
  const char d = format.delimiter;
  std::string out;
  out.reserve(n * (format.has_accel() ? 7 : 4) * 16 + 64);
  out += format.time_column;
  for (const auto& c : format.gyro_columns) (out += d) += c;
  if (format.has_accel()) {
    for (const auto& c : format.accel_columns) (out += d) += c;
  }
  out += options.line_end;
  const double time_scale = 1.0 / ToSi(format.time_unit);
  const double gyro_scale = 1.0 / ToSi(format.gyro_unit);
  const double accel_scale = 1.0 / ToSi(format.accel_unit);
  const int digits = options.significant_digits;
  const int time_digits = digits > 10 ? digits : 10;  // timestamps keep >= 10 digits
  for (size_t k = 0; k < n; ++k) {
    bool finite = std::isfinite(data.t_s[k]) && data.gyro_in_imu[k].allFinite();
    if (format.has_accel()) finite = finite && data.accel_in_imu[k].allFinite();
    if (!finite) throw UserError("IMU log: sample " + std::to_string(k) + " is not finite");
    AppendNumber(data.t_s[k] * time_scale, time_digits, &out);
    for (int i = 0; i < 3; ++i) {
      out += d;
      AppendNumber(data.gyro_in_imu[k][i] * gyro_scale, digits, &out);
    }
    if (format.has_accel()) {
      for (int i = 0; i < 3; ++i) {
        out += d;
        AppendNumber(data.accel_in_imu[k][i] * accel_scale, digits, &out);
      }
    }
    out += options.line_end;
  }
  return out;
}

void WriteImuLog(const std::string& path, const ImuData& data, const ImuFormat& format,
                 const ImuLogWriteOptions& options) {
  const std::string text = FormatImuLog(data, format, options);
  const bool gzip = path.size() > 3 && path.compare(path.size() - 3, 3, ".gz") == 0;
  WriteFileAtomically(path, gzip ? GzipCompress(text) : text);
}

}  // namespace bifilar

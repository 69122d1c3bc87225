// How an IMU CSV log is laid out: column names and units. Shared by the log reader
// (pipeline/logs/imu_log.h) and the simulator's writer. Values in memory are SI
// (pendulum/imu_data.h).
#pragma once

#include <array>
#include <string>
#include <string_view>

namespace bifilar {

enum class TimeUnit { kSeconds, kMilliseconds, kMicroseconds };  // "s", "ms", "us"
enum class RateUnit { kRadPerS, kDegPerS, kMilliradPerS };       // "rad/s", "deg/s", "mrad/s"
enum class AccelUnit { kMetresPerS2, kStandardGravity };         // "m/s^2", "g"

// Parse the unit names above; false for anything else. One name table per enum
// (base/enum_names.h) gives these, ToString and the "allowed values" text of messages.
bool ParseTimeUnit(const std::string& name, TimeUnit* unit);
bool ParseRateUnit(const std::string& name, RateUnit* unit);
bool ParseAccelUnit(const std::string& name, AccelUnit* unit);
const char* ToString(TimeUnit unit);
const char* ToString(RateUnit unit);
const char* ToString(AccelUnit unit);
std::string TimeUnitAllowedValues();   // "s, ms or us"
std::string RateUnitAllowedValues();   // "rad/s, deg/s or mrad/s"
std::string AccelUnitAllowedValues();  // "m/s^2 or g"

// Multiply a file value by this to get SI (s, rad/s, m/s^2).
double ToSi(TimeUnit unit);
double ToSi(RateUnit unit);
double ToSi(AccelUnit unit);

// A name from a log's header (a CSV column, a topic) echoed in a message or on a terminal: at
// most `max_bytes` bytes of `s`, then "..."; printable ASCII and valid UTF-8 letters kept as they
// are (a column "ω_x" or "Gyro (°/s)" stays readable), and every byte that could act on the
// terminal or break the line replaced by '?': C0 and C1 controls (ESC of an escape sequence, NEL
// U+0085), DEL, the line and paragraph separators, the bidirectional and zero-width controls,
// and any byte that is not valid UTF-8. The DataFlash reader's PrintableAscii
// (base/text_format.h) does the same for its ASCII-only names.
std::string EchoedName(std::string_view s, size_t max_bytes = 80);

// What a name holds that YAML or a terminal may not keep as it is: "U+0085 (NEL) at byte 2",
// "byte 0xff at byte 3 (invalid UTF-8)", "" when every character is printable.
std::string DescribeUnprintable(std::string_view s);

// Which topic and fields of a PX4 ULog (.ulg) log hold the IMU data (pipeline/logs/ulog.h). PX4
// logs are SI already: timestamps in us (ms for a uint8_t field), rates in rad/s, specific force in
// m/s^2, so the CSV units above do not apply. Defaults: see UlogTopicDefaults in
// pipeline/logs/ulog.h.
struct UlogSelection {
  std::string topic = "sensor_combined";  // uORB topic (message name), case sensitive
  int multi_id = 0;                       // instance of the topic (0 = first); >= 0
  std::string time_field = "timestamp";   // us since boot
  std::array<std::string, 3> gyro_fields = {"gyro_rad[0]", "gyro_rad[1]", "gyro_rad[2]"};
  // All three empty: read the topic gyro-only.
  std::array<std::string, 3> accel_fields = {"accelerometer_m_s2[0]", "accelerometer_m_s2[1]",
                                             "accelerometer_m_s2[2]"};
};

// How a log file is read: by its content (ULog magic bytes, else CSV), or forced.
enum class LogContainer { kAuto, kCsv, kUlog };  // "auto", "csv", "ulog"
bool ParseLogContainer(const std::string& name, LogContainer* container);
const char* ToString(LogContainer container);
std::string LogContainerAllowedValues();  // "auto, csv or ulog"

struct ImuFormat {
  std::string time_column = "t";                                 // header name of the time column
  TimeUnit time_unit = TimeUnit::kSeconds;                       // default seconds
  std::array<std::string, 3> gyro_columns = {"gx", "gy", "gz"};  // IMU x, y, z angular rate
  RateUnit gyro_unit = RateUnit::kRadPerS;                       // default rad/s
  // IMU x, y, z specific force; all three empty means the log has no accelerometer.
  std::array<std::string, 3> accel_columns = {"ax", "ay", "az"};
  AccelUnit accel_unit = AccelUnit::kMetresPerS2;  // default m/s^2
  char delimiter = ',';                            // field separator
  LogContainer container = LogContainer::kAuto;    // `imu.format`; default auto
  UlogSelection ulog;                              // `imu.ulog`: used for .ulg logs

  bool has_accel() const { return !accel_columns[0].empty(); }
  // Column names non-empty and distinct (accelerometer: all three or none).
  bool Check(std::string* why) const;
};

}  // namespace bifilar

#include "pipeline/watch/live_source.h"

#include <cmath>
#include <cstdlib>

#include "base/text_format.h"
#include "base/user_error.h"
#include "pipeline/live/byte_stream.h"
#include "pipeline/live/mavlink.h"
#include "pipeline/live/websocket_client.h"
#include "pipeline/logs/imu_log_options.h"

namespace bifilar {
namespace {

bool HasPrefix(const std::string& s, const std::string& prefix) { return s.rfind(prefix, 0) == 0; }

// "DEVICE@BAUD" -> device and baud; "HOST:PORT" -> host and port.
void SplitAt(const std::string& spec, const std::string& text, char at, std::string* head,
             int* number) {
  const size_t i = text.rfind(at);
  char* end = nullptr;
  const long n = i == std::string::npos ? 0 : std::strtol(text.c_str() + i + 1, &end, 10);
  if (i == std::string::npos || i == 0 || end == nullptr || *end != '\0' || n <= 0 ||
      n > 10000000) {
    throw UserError("watch: source '" + PrintableAscii(spec, 200) + "': expected " +
                    (at == '@' ? "DEVICE@BAUD (serial:/dev/ttyACM0@115200)"
                               : "HOST:PORT (mavlink-udp:0.0.0.0:14550)"));
  }
  *head = text.substr(0, i);
  *number = static_cast<int>(n);
}

std::unique_ptr<live::ByteStream> OpenBytes(const std::string& spec, bool udp,
                                            const std::string& address) {
  std::string head, error;
  int number = 0;
  SplitAt(spec, address, udp ? ':' : '@', &head, &number);
  std::unique_ptr<live::ByteStream> stream =
      udp ? live::OpenUdp(head, number, &error) : live::OpenSerial(head, number, &error);
  if (!stream) throw UserError("watch: source '" + PrintableAscii(spec, 200) + "': " + error);
  return stream;
}

// Text over a serial port, or one JSON object per WebSocket message.
class TextLiveSource : public WatchSource {
 public:
  TextLiveSource(std::string spec, const WatchInputOptions& input)
      : spec_(std::move(spec)), parser_(input) {
    Open();
  }
  bool Next(std::vector<WatchSample>* samples, std::vector<RejectedLine>* rejected,
            double timeout_s, std::string* why) override {
    std::string chunk;
    bool open = true;
    if (bytes_) {
      open = bytes_->Read(&chunk, timeout_s, why);
    } else {
      open = messages_->Next(&chunk, timeout_s, why);
      if (!chunk.empty()) chunk += "\n";
    }
    if (!chunk.empty()) parser_.Feed(chunk, samples, rejected);
    if (!open) {
      parser_.Finish(samples, rejected);
      // The source named once: a WebSocket's reason already starts with its name.
      if (why->rfind(Describe() + ": ", 0) != 0) *why = Describe() + ": " + *why;
    }
    return open;
  }
  bool CanReconnect() const override { return true; }
  bool Reconnect(std::string* why) override {
    try {
      Open();
    } catch (const UserError& e) {
      *why = e.what();
      return false;
    }
    parser_.Restart();
    return true;
  }
  void ResetClock() override { parser_.ResetClock(); }
  const InputCounters& counters() const override { return parser_.counters(); }
  std::string Describe() const override {
    return bytes_ ? bytes_->Describe() : messages_ ? messages_->Describe() : spec_;
  }
  std::string simulated_marker() const override { return parser_.simulated_marker(); }
  std::string format_description() const override { return parser_.description(); }

 private:
  void Open() {
    bytes_.reset();
    messages_.reset();
    if (HasPrefix(spec_, "serial:")) {
      bytes_ = OpenBytes(spec_, false, spec_.substr(7));
      return;
    }
    std::string error;
    messages_ = live::OpenWebSocket(spec_, &error);
    if (!messages_) throw UserError("watch: source '" + PrintableAscii(spec_, 200) + "': " + error);
  }
  std::string spec_;
  SampleParser parser_;
  std::unique_ptr<live::ByteStream> bytes_;
  std::unique_ptr<live::MessageStream> messages_;
};

// MAVLink IMU frames. One IMU is kept: the message, system, component and instance of the first
// IMU frame (ArduPilot may send one IMU as RAW_IMU and SCALED_IMU).
class MavlinkSource : public WatchSource {
 public:
  MavlinkSource(std::string spec, bool udp, std::string address)
      : spec_(std::move(spec)), udp_(udp), address_(std::move(address)) {
    stream_ = OpenBytes(spec_, udp_, address_);
  }
  bool Next(std::vector<WatchSample>* samples, std::vector<RejectedLine>* rejected,
            double timeout_s, std::string* why) override {
    std::string chunk;
    const bool open = stream_->Read(&chunk, timeout_s, why);
    for (const live::MavlinkImuSample& m : decoder_.Feed(chunk)) Take(m, samples, rejected);
    counters_.bad_checksum = bad_crc_before_ + decoder_.counters().bad_crc;
    if (!open) *why = Describe() + ": " + *why;
    return open;
  }
  bool CanReconnect() const override { return true; }
  bool Reconnect(std::string* why) override {
    try {
      stream_ = OpenBytes(spec_, udp_, address_);
    } catch (const UserError& e) {
      *why = e.what();
      return false;
    }
    bad_crc_before_ += decoder_.counters().bad_crc;
    decoder_ = live::MavlinkDecoder();
    ++counters_.restarts;
    return true;
  }
  void ResetClock() override { last_t_ = -1e300; }
  const InputCounters& counters() const override { return counters_; }
  std::string Describe() const override { return "MAVLink over " + stream_->Describe(); }
  std::string format_description() const override {
    return key_.empty() ? "MAVLink IMU messages" : "MAVLink " + key_;
  }

 private:
  void Take(const live::MavlinkImuSample& m, std::vector<WatchSample>* samples,
            std::vector<RejectedLine>* rejected) {
    const std::string key = Fmt("msgid %g", m.msgid) + Fmt(" from system %g", m.sysid) +
                            Fmt(" component %g", m.compid) + Fmt(" imu %g", m.imu_instance);
    if (key_.empty()) key_ = key;
    if (key != key_) return;  // another IMU or the same one sent twice: not counted as input
    const std::string line =
        Fmt("mavlink t %.9g", m.t_s) +
        Fmt(" gyro %.9g %.9g %.9g", m.gyro_rad_per_s[0], m.gyro_rad_per_s[1], m.gyro_rad_per_s[2]);
    ++counters_.lines;
    WatchSample s;
    s.t_s = m.t_s;
    for (int k = 0; k < 3; ++k) {
      s.gyro_rad_per_s[k] = m.gyro_rad_per_s[k];
      s.accel_mps2[k] = m.accel_m_per_s2[k];
    }
    s.has_accel = true;  // the three messages carry accel fields; values as sent
    if (!std::isfinite(s.t_s) || !s.gyro_rad_per_s.allFinite() ||
        (s.has_accel && !s.accel_mps2.allFinite())) {
      ++counters_.non_finite;
      rejected->push_back({line, "non_finite"});
      return;
    }
    if (s.gyro_rad_per_s.cwiseAbs().maxCoeff() > kMaxGyroRateRadPerS ||
        (s.has_accel && s.accel_mps2.cwiseAbs().maxCoeff() > kMaxAccelMps2)) {
      ++counters_.out_of_range;
      rejected->push_back({line, "out_of_range"});
      return;
    }
    if (!(s.t_s > last_t_)) {
      ++counters_.time_back;
      rejected->push_back({line, "time_back"});
      return;
    }
    last_t_ = s.t_s;
    ++counters_.samples;
    samples->push_back(s);
  }

  std::string spec_;
  bool udp_;
  std::string address_;
  std::unique_ptr<live::ByteStream> stream_;
  live::MavlinkDecoder decoder_;
  InputCounters counters_;
  long bad_crc_before_ = 0;
  double last_t_ = -1e300;
  std::string key_;
};

}  // namespace

std::unique_ptr<WatchSource> OpenLiveSource(const std::string& spec,
                                            const WatchInputOptions& input) {
  if (HasPrefix(spec, "serial:") || HasPrefix(spec, "ws://") || HasPrefix(spec, "wss://")) {
    return std::make_unique<TextLiveSource>(spec, input);
  }
  if (HasPrefix(spec, "mavlink:")) {
    return std::make_unique<MavlinkSource>(spec, false, spec.substr(8));
  }
  if (HasPrefix(spec, "mavlink-udp:")) {
    return std::make_unique<MavlinkSource>(spec, true, spec.substr(12));
  }
  return nullptr;
}

}  // namespace bifilar

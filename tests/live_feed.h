// Feeders for the tests of pipeline/live/: a simulated swing (the example rig of
// fit/trace_synth.h, known truth) as IMU samples, CSV text and MAVLink frames.
#pragma once

#include <cmath>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "base/units.h"
#include "fit/trace_synth.h"
#include "pendulum/imu_data.h"
#include "pipeline/live/mavlink.h"
#include "pipeline/live/mavlink_writer.h"

namespace bifilar::live::testing {

// The example rig swinging at 20° about the IMU z axis for duration_s at rate_hz (jittered
// timestamps, dropped samples, noise: fit/trace_synth.h); the other axes carry a small sway
// and the accelerometer the gravity and the centripetal term, so every field has a value.
inline ImuData SimulatedSwing(double duration_s, double rate_hz, uint64_t seed) {
  SyntheticTraceOptions o = ExampleRigTraceOptions(20.0, seed);
  o.duration_s = duration_s;
  o.sample_rate_hz = rate_hz;
  TraceFitInput input;
  EXPECT_TRUE(MakeSyntheticTrace(o, &input));
  ImuData data;
  data.t_s = input.t_s;
  for (std::size_t i = 0; i < input.t_s.size(); ++i) {
    const double w = input.rate_rad_per_s[i];
    const double t = input.t_s[i];
    data.gyro_in_imu.emplace_back(0.01 * std::sin(3.1 * t), -0.02 * std::cos(1.7 * t), w);
    data.accel_in_imu.emplace_back(0.3 * w * w, -0.05 * w, -kStandardGravityMps2 + 0.1 * w);
  }
  return data;
}

inline std::vector<MavlinkImuSample> AsMavlinkSamples(const ImuData& data) {
  std::vector<MavlinkImuSample> out;
  for (std::size_t i = 0; i < data.size(); ++i) {
    MavlinkImuSample s{};
    s.t_s = data.t_s[i];
    for (int k = 0; k < 3; ++k) {
      s.gyro_rad_per_s[k] = data.gyro_in_imu[i][k];
      s.accel_m_per_s2[k] = data.accel_in_imu[i][k];
    }
    s.has_accel = true;
    s.msgid = kMavlinkMsgidHighresImu;
    s.sysid = 1;
    s.compid = 1;
    out.push_back(s);
  }
  return out;
}

// The HIGHRES_IMU frames of `samples` (accel and gyro marked new), one string per frame.
inline std::vector<std::string> HighresFrames(const std::vector<MavlinkImuSample>& samples) {
  std::vector<std::string> frames;
  MavlinkFrameOptions o;
  for (const MavlinkImuSample& s : samples) {
    frames.push_back(EncodeHighresImu(s, kHighresImuUpdatedAccel | kHighresImuUpdatedGyro, o));
    o.seq = (o.seq + 1) % 256;
  }
  return frames;
}

// What a HIGHRES_IMU frame carries of `sent`: times to the microsecond, values as floats.
inline void ExpectHighresEqual(const MavlinkImuSample& sent, const MavlinkImuSample& got) {
  EXPECT_EQ(got.msgid, kMavlinkMsgidHighresImu);
  EXPECT_DOUBLE_EQ(got.t_s, std::llround(sent.t_s * 1e6) * 1e-6);
  for (int k = 0; k < 3; ++k) {
    EXPECT_EQ(got.gyro_rad_per_s[k],
              static_cast<double>(static_cast<float>(sent.gyro_rad_per_s[k])));
    EXPECT_EQ(got.accel_m_per_s2[k],
              static_cast<double>(static_cast<float>(sent.accel_m_per_s2[k])));
  }
}

}  // namespace bifilar::live::testing

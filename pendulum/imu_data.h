// One IMU log in memory, in SI units and the IMU's own frame, whatever the file's units were.
#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>

namespace bifilar {

struct ImuData {
  std::vector<double> t_s;                    // sample times (s), strictly increasing
  std::vector<Eigen::Vector3d> gyro_in_imu;   // angular rate (rad/s), IMU axes
  std::vector<Eigen::Vector3d> accel_in_imu;  // specific force (m/s^2), IMU axes; empty if absent
  std::vector<std::string> warnings;          // repairs made while reading (skipped rows, ...)

  bool has_accel() const { return !accel_in_imu.empty(); }
  size_t size() const { return t_s.size(); }
};

}  // namespace bifilar

// The swing axis of one log and the swing rate omega_meas = gyro . n (docs/physics.md §2),
// plus the pitch measured by the accelerometer (§3) and the secondary-motion metric.
//
// Conventions: n is the unit down vertical expressed in IMU axes; the accelerometer measures
// specific force f = a - g_vec, so at rest f = -g n and n = -f/|f|. The mounting rotation
// imu_to_body maps IMU vectors to body axes (v_body = imu_to_body * v_imu; the simulator calls it
// body_from_imu). In body axes the down vertical is n_body = (-sin theta, 0, cos theta) with
// theta the pitch, nose-up positive (§3), so
//     pitch  theta = atan2(-n_x, sqrt(n_y^2 + n_z^2))   (= atan2(-n_x, n_z) when n_y = 0)
//     roll   phi   = atan2(n_y, n_z)                     (0 on a rig that only pitches)
// The roll-independent form of theta is the aircraft Euler pitch; it equals §3's formula for any
// pitch in [-90, 90] deg when the rig does not roll, and stays right when it rolls slightly.
//
// Axis sign: the sign of n does not change the fitted inertia (the model is odd in psi), but it
// is made reproducible. With the accelerometer, n is the down vertical, whose sign is physical.
// From the gyro alone (principal direction), the sign is chosen so that the axis in body axes has
// z >= 0, which agrees with the down vertical for every pitch in (-90, 90) deg.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "pendulum/imu_data.h"

namespace bifilar {

enum class SwingAxisMode {
  kAuto,   // accelerometer at rest (else at the swing's turning points in the window, else the
           // whole log), else the gyro's principal direction
  kFixed,  // SwingAxisOptions::fixed_axis_in_imu
};
enum class SwingAxisSource { kAccelAtRest, kAccelOverWindow, kGyroPrincipal, kFixed };
const char* ToString(SwingAxisMode mode);  // "auto", "fixed"
const char* ToString(
    SwingAxisSource source);  // "accel_rest", "accel_window", "gyro_principal", "fixed"

struct SwingAxisOptions {
  SwingAxisMode mode = SwingAxisMode::kAuto;
  // Swing axis in IMU axes when mode == kFixed (normalised here; any non-zero length). Default +z.
  Eigen::Vector3d fixed_axis_in_imu = Eigen::Vector3d::UnitZ();
  // Mounting rotation, v_body = imu_to_body * v_imu (orthonormal, det +1). Default identity.
  Eigen::Matrix3d imu_to_body = Eigen::Matrix3d::Identity();
  // A sample is "at rest" when |gyro - bias| stays below this over +-rest_half_width_s around it
  // (rad/s). Default 0.05 rad/s (2.9 deg/s): 10x the 0.25 deg/s gyro noise, well above a typical
  // 0.5 deg/s bias, and small enough that the lever-arm accelerations it allows (omega^2 r,
  // omega' r) tilt the measured down vector by under 0.01 deg at r = 0.3 m.
  double rest_rate_threshold_rad_per_s = 0.05;
  double rest_half_width_s = 0.5;  // (s), > 0. Default 0.5 s: longer than a turning point.
  // Fewest rest samples for kAccelAtRest (count). Default 50 (0.5 s at 100 Hz; 0.02 m/s^2 noise
  // then puts the mean down vector within 0.02 deg).
  int min_rest_samples = 50;
  // |f| at rest must be within this fraction of standard gravity for the accelerometer to be
  // trusted (units or a broken sensor). Default 0.1.
  double gravity_tolerance = 0.1;
  // An accelerometer whose mean reading is not gravity (outside gravity_tolerance) is ignored:
  // gyro-only, as with imu.accel: null, with a warning in SwingAxis::warnings that says what the
  // reading looks like. A mean reading below this many standard gravities, pointing more than
  // 60 deg away from the gyro's principal direction (the swing axis), is called an
  // accelerometer with gravity removed by the logger's firmware: what is left is the residual
  // g (n_est - n) of its tilt estimate (real logs read 0.07-0.27 g), nearly perpendicular to the
  // down vertical n. In [0, 1 - gravity_tolerance); 0 turns that diagnosis off. Default 0.5.
  double gravity_removed_below_g = 0.5;
  // True: an accelerometer that does not read gravity is an error (the caller needs the down
  // vector). Default false: ignored with a warning (a swing about the vertical needs only the
  // gyro; a campaign with runs.pitch_source: measured makes such a trace an error row).
  bool accel_required = false;
  // The SI value of one unit of the log's accelerometer as declared or guessed (1: m/s^2,
  // 9.80665: g), so that the advice of a reading that is not gravity names the other unit, not
  // the one already in use. Default 1 (m/s^2).
  double accel_unit_si = 1.0;

  bool Check(std::string* why) const;
};

// Ends every warning about an ignored accelerometer (SwingAxis::warnings), so that a caller that
// needed the accelerometer can find and quote it.
inline constexpr char kAccelIgnoredSentence[] =
    "The accelerometer is ignored (swing axis from the gyro, no measured pitch); set "
    "imu.accel: null to say so";

struct SwingAxis {
  Eigen::Vector3d axis_in_imu = Eigen::Vector3d::UnitZ();   // unit n, IMU axes
  Eigen::Vector3d axis_in_body = Eigen::Vector3d::UnitZ();  // imu_to_body * n
  SwingAxisSource source = SwingAxisSource::kFixed;
  std::vector<double> rate_rad_per_s;  // gyro . n at every sample of the log (rad/s)
  // From the accelerometer's down vector (empty without an accelerometer, or when it did not see
  // rest and no window was given), in degrees, conventions above.
  std::optional<double> pitch_measured_deg;
  std::optional<double> roll_measured_deg;
  int rest_samples = 0;            // samples used for the accelerometer down vector (0: none)
  double rest_accel_mps2 = 0.0;    // |mean f| over them (should be ~9.8)
  std::vector<std::string> notes;  // fallbacks taken (no rest -> window, ...)
  // The accelerometer did not read gravity (removed, a wrong unit, a broken sensor) and was
  // ignored: no pitch, the axis from the gyro. The sentence for the user is in `warnings`.
  bool accel_ignored = false;
  std::vector<std::string> warnings;  // for the trace's record
};

// Estimates the swing axis and the swing rate. The optional window [t0, t1] (s) is used by kAuto
// when the log shows no rest (accelerometer averaged over the window) and for the gyro principal
// direction (default: the whole log). Returns false with *why on invalid options, an empty log, a
// zero fixed axis, or (only with accel_required) an accelerometer that does not read gravity;
// without accel_required such an accelerometer is ignored with a warning (SwingAxisOptions).
bool EstimateSwingAxis(const ImuData& data, const SwingAxisOptions& options,
                       std::optional<std::pair<double, double>> window_s, SwingAxis* axis,
                       std::string* why);

// Secondary motion over [t0, t1]: RMS of the gyro component orthogonal to n divided by the RMS of
// the component along n, both after removing their mean over the window (so constant gyro bias
// does not count). 0 when there is no swing (and no other motion); never NaN.
double SecondaryMotionRatio(const ImuData& data, const Eigen::Vector3d& axis_in_imu, double t0_s,
                            double t1_s);

// Pitch and roll (deg) of the body from a down vector in body axes (conventions above).
double PitchFromDownDeg(const Eigen::Vector3d& down_in_body);
double RollFromDownDeg(const Eigen::Vector3d& down_in_body);

}  // namespace bifilar

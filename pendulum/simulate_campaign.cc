// The campaign simulation (pendulum/simulate.h): the aircraft's and the rig's true inertia at an
// attitude, the campaign spec's checks, the seeds and folder names of each log, and
// SimulateCampaign, which simulates every log of a campaign (tare, calibration, each attitude's
// trials) with SimulateTrace (simulate.cc: one trace).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <optional>
#include <sstream>

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>

#include "base/option_check.h"
#include "base/text_format.h"
#include "base/units.h"
#include "pendulum/simulate.h"
#include "pendulum/simulate_steps.h"

namespace bifilar {

double AircraftTruth::InertiaAtPitch(double pitch_rad) const {
  const double c = std::cos(pitch_rad), s = std::sin(pitch_rad);
  return iz_kg_m2 * c * c + ix_kg_m2 * s * s + ixz_kg_m2 * std::sin(2 * pitch_rad);
}

double AircraftTruth::InertiaAtAttitude(double roll_rad, double pitch_rad) const {
  if (roll_rad == 0.0 && !HasTensor()) return InertiaAtPitch(pitch_rad);
  const Eigen::Vector3d n(-std::sin(pitch_rad), std::sin(roll_rad) * std::cos(pitch_rad),
                          std::cos(roll_rad) * std::cos(pitch_rad));
  return n.dot(Tensor() * n);
}

Eigen::Matrix3d AircraftTruth::Tensor() const {
  Eigen::Matrix3d j;
  j << ix_kg_m2, -ixy_kg_m2, -ixz_kg_m2, -ixy_kg_m2, iy_kg_m2, -iyz_kg_m2, -ixz_kg_m2, -iyz_kg_m2,
      iz_kg_m2;
  return j;
}

double AircraftTruth::PrincipalInclinationRad() const {
  double tau = 0.5 * std::atan2(2 * ixz_kg_m2, iz_kg_m2 - ix_kg_m2);
  if (tau <= -kPi / 4) tau += kPi / 2;
  if (tau > kPi / 4) tau -= kPi / 2;
  return tau;
}

bool AircraftTruth::Check(std::string* why) const {
  CheckFailure f;
  if (!CheckIn("aircraft.mass_kg", mass_kg, 0.0, 1e6, Ends::kOpenClosed, &f) ||
      !CheckIn("aircraft I_x", ix_kg_m2, 0.0, 1e9, Ends::kOpenClosed, &f) ||
      !CheckIn("aircraft I_z", iz_kg_m2, 0.0, 1e9, Ends::kOpenClosed, &f) ||
      !CheckIn("aircraft I_xz", ixz_kg_m2, -1e9, 1e9, Ends::kClosed, &f)) {
    return FailWith(f, why);
  }
  if (HasTensor()) {
    if (!CheckIn("aircraft I_y", iy_kg_m2, 0.0, 1e9, Ends::kOpenClosed, &f) ||
        !CheckIn("aircraft I_xy", ixy_kg_m2, -1e9, 1e9, Ends::kClosed, &f) ||
        !CheckIn("aircraft I_yz", iyz_kg_m2, -1e9, 1e9, Ends::kClosed, &f)) {
      return FailWith(f, why);
    }
    const Eigen::Vector3d m =
        Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(Tensor()).eigenvalues();
    // Positive definite (else the products of inertia are too large), and the triangle
    // inequality of the principal moments (else no rigid body has the tensor).
    if (!CheckGt("aircraft smallest principal moment (products of inertia too large)", m(0), 0,
                 &f) ||
        !CheckLe("aircraft largest principal moment", m(2),
                 "the sum of the other two (triangle "
                 "inequality)",
                 m(0) + m(1), &f)) {
      return FailWith(f, why);
    }
  } else if (ixy_kg_m2 != 0.0 || iyz_kg_m2 != 0.0) {
    const bool xy = ixy_kg_m2 != 0.0;
    CheckFail(xy ? "aircraft I_xy" : "aircraft I_yz", xy ? ixy_kg_m2 : iyz_kg_m2,
              "0 without I_y (iy_kg_m2)", &f);
    return FailWith(f, why);
  }
  // Smallest value of I(theta) = A - sqrt(B^2 + C^2) must be positive.
  const double a = 0.5 * (ix_kg_m2 + iz_kg_m2), b = 0.5 * (iz_kg_m2 - ix_kg_m2);
  if (a - std::hypot(b, ixz_kg_m2) <= 0) {
    CheckFail("aircraft I_xz", ixz_kg_m2,
              "|I_xz| < sqrt(I_x I_z) = " + FormatCheckValue(std::sqrt(ix_kg_m2 * iz_kg_m2)) +
                  " (else the inertia about some axis would be <= 0)",
              &f);
    return FailWith(f, why);
  }
  return true;
}

bool RigTruth::InertiaAtPitch(double nominal_pitch_deg, double* inertia) const {
  if (inertia_by_pitch_kg_m2.empty()) {
    *inertia = inertia_kg_m2;
    return true;
  }
  for (const auto& entry : inertia_by_pitch_kg_m2) {
    if (std::abs(entry.first - nominal_pitch_deg) < 1e-9) {
      *inertia = entry.second;
      return true;
    }
  }
  return false;
}

bool RigTruth::Check(std::string* why) const {
  CheckFailure f;
  if (!CheckIn("rig.mass_kg", mass_kg, 0.0, 1e6, Ends::kOpenClosed, &f) ||
      !CheckIn("rig.imu_mass_kg", imu_mass_kg, 0.0, 1e3, Ends::kClosed, &f)) {
    return FailWith(f, why);
  }
  if (inertia_by_pitch_kg_m2.empty()) {
    if (!CheckIn("rig.inertia_kg_m2", inertia_kg_m2, 0.0, 1e9, Ends::kOpenClosed, &f))
      return FailWith(f, why);
  } else {
    for (const auto& entry : inertia_by_pitch_kg_m2) {
      if (!CheckIn("rig.inertia_by_pitch_kg_m2 at " + Fmt("%g", entry.first) + " deg", entry.second,
                   0.0, 1e9, Ends::kOpenClosed, &f)) {
        return FailWith(f, why);
      }
    }
  }
  return true;
}

namespace {

// Each attitude override names an attitude of the campaign and keeps the wires taut.
bool CheckAttitudeOverrides(const CampaignSpec& spec, std::string* why) {
  CheckFailure f;
  const auto fail = [&](const std::string& field, double value, const std::string& allowed) {
    CheckFail(field, value, allowed, &f);
    return FailWith(f, why);
  };
  for (const AttitudeOverride& o : spec.attitude_overrides) {
    const double length = o.true_filar_length_m > 0 ? o.true_filar_length_m : spec.TrueLengthM();
    const double separation =
        o.true_filar_separation_m > 0 ? o.true_filar_separation_m : spec.TrueSeparationM();
    const auto& all = spec.attitudes_deg;
    if (std::find(all.begin(), all.end(), o.attitude_deg) == all.end()) {
      return fail("attitude_overrides.attitude_deg (roll)", o.attitude_deg[0],
                  "an attitude of attitudes_deg");
    }
    if (!CheckFiniteGe("attitude_overrides.true_filar_length_m", o.true_filar_length_m, 0.0, &f) ||
        !CheckFiniteGe("attitude_overrides.true_filar_separation_m", o.true_filar_separation_m, 0.0,
                       &f) ||
        !CheckGt("attitude_overrides.true_filar_length_m", length,
                 "attitude_overrides.true_filar_separation_m", separation, &f) ||
        !CheckIn("attitude_overrides.inertia_scatter", o.inertia_scatter, 0.0, 0.5, Ends::kClosed,
                 &f)) {
      return FailWith(f, why);
    }
  }
  return true;
}

}  // namespace

bool CampaignSpec::Check(std::string* why) const {
  if (!aircraft.Check(why) || !rig.Check(why)) return false;
  CheckFailure f;
  const auto fail = [&](const std::string& field, double value, const std::string& allowed) {
    CheckFail(field, value, allowed, &f);
    return FailWith(f, why);
  };
  const std::string kTablePitch = "a pitch of rig.inertia_by_pitch_kg_m2";
  if (!CheckIn("filar_length_m (L)", filar_length_m, 0.0, 1000.0, Ends::kOpenClosed, &f) ||
      !CheckIn("filar_separation_m (D)", filar_separation_m, 0.0, 1000.0, Ends::kOpenClosed, &f) ||
      !CheckIn("gravity_mps2", gravity_mps2, 0.0, 100.0, Ends::kOpenClosed, &f)) {
    return FailWith(f, why);
  }
  if (!CheckSeparationBelowLength(filar_length_m, filar_separation_m, why)) return false;
  // The true geometry (0: the configured one) keeps the wires taut.
  if (!CheckFiniteGe("true_filar_length_m", true_filar_length_m, 0.0, &f) ||
      !CheckFiniteGe("true_filar_separation_m", true_filar_separation_m, 0.0, &f) ||
      !CheckGt("true_filar_length_m (0: filar_length_m)", TrueLengthM(),
               "true_filar_separation_m (0: filar_separation_m)", TrueSeparationM(), &f)) {
    return FailWith(f, why);
  }
  if (!CheckAttitudeOverrides(*this, why)) return false;
  if (calibration_logs > 0) {
    if (!CheckIn("calibration.reference_inertia_kg_m2", reference_inertia_kg_m2, 0.0, 1e9,
                 Ends::kOpenClosed, &f) ||
        !CheckIn("calibration.reference_mass_kg", reference_mass_kg, 0.0, 1e6, Ends::kOpenClosed,
                 &f)) {
      return FailWith(f, why);
    }
    if (calibration_amplitude_deg.max > 0.0 &&
        (!CheckUniformRange(calibration_amplitude_deg, "calibration.amplitude_deg", 0.0, true,
                            &f) ||
         !CheckIn("calibration.amplitude_deg.max", calibration_amplitude_deg.max, 0.0, 75.0,
                  Ends::kOpenClosed, &f))) {
      return FailWith(f, why);
    }
    double unused;
    if (!rig.InertiaAtPitch(tare_pitch_deg, &unused)) {
      return fail("tare_pitch_deg", tare_pitch_deg, kTablePitch + " (the reference swings')");
    }
  }
  if (!attitudes_deg.empty()) {
    if (!pitch_deg.empty()) {
      return fail("pitch_deg (count)", static_cast<double>(pitch_deg.size()),
                  "0 with attitudes_deg (give either, not both)");
    }
    if (!aircraft.HasTensor()) {
      return fail("aircraft iy_kg_m2", aircraft.iy_kg_m2,
                  "given with attitudes_deg: a campaign that rolls needs the whole tensor (and "
                  "ixy_kg_m2, iyz_kg_m2 when not 0)");
    }
    for (size_t i = 0; i < attitudes_deg.size(); ++i) {
      const std::array<double, 2>& a = attitudes_deg[i];
      if (!CheckIn("attitudes_deg roll", a[0], -180.0, 180.0, Ends::kClosed, &f) ||
          !CheckIn("attitudes_deg pitch", a[1], -90.0, 90.0, Ends::kClosed, &f)) {
        return FailWith(f, why);
      }
      for (size_t j = 0; j < i; ++j) {
        if (AttitudeFolder(attitudes_deg[j]) == AttitudeFolder(a)) {
          CheckFailText("attitudes_deg", "roll " + Fmt("%g", a[0]) + ", pitch " + Fmt("%g", a[1]),
                        "distinct attitudes (it appears twice)", &f);
          return FailWith(f, why);
        }
      }
      double unused;
      if (!rig.InertiaAtPitch(a[1], &unused)) {
        return fail("attitudes_deg pitch", a[1], kTablePitch);
      }
    }
    if (!CheckIn("roll_error_sigma_deg", roll_error_sigma_deg, 0.0, 10.0, Ends::kClosed, &f)) {
      return FailWith(f, why);
    }
  }
  if (pitch_deg.empty() && attitudes_deg.empty() && tare_logs == 0) {
    return fail("pitch_deg (count)", 0, "> 0 (or attitudes_deg, or tare_logs > 0)");
  }
  for (size_t i = 0; i < pitch_deg.size(); ++i) {
    if (!CheckIn("pitch_deg", pitch_deg[i], -90.0, 90.0, Ends::kClosed, &f))
      return FailWith(f, why);
    for (size_t j = 0; j < i; ++j) {
      if (FormatPitchDeg(pitch_deg[j]) == FormatPitchDeg(pitch_deg[i])) {
        return fail("pitch_deg", pitch_deg[i], "distinct (it appears twice)");
      }
    }
    double unused;
    if (!rig.InertiaAtPitch(pitch_deg[i], &unused)) {
      return fail("pitch_deg", pitch_deg[i], kTablePitch);
    }
  }
  double unused;
  if (tare_logs > 0 && !rig.InertiaAtPitch(tare_pitch_deg, &unused)) {
    return fail("tare_pitch_deg", tare_pitch_deg, kTablePitch);
  }
  return (CheckIn("trials_per_pitch", trials_per_pitch, 1.0, 1000.0, Ends::kClosed, &f) &&
          CheckIn("tare_logs", tare_logs, 0.0, 1000.0, Ends::kClosed, &f) &&
          CheckIn("calibration.logs", calibration_logs, 0.0, 1000.0, Ends::kClosed, &f) &&
          CheckIn("tare_pitch_deg", tare_pitch_deg, -90.0, 90.0, Ends::kClosed, &f) &&
          CheckIn("pitch_error_sigma_deg", pitch_error_sigma_deg, 0.0, 10.0, Ends::kClosed, &f) &&
          CheckUniformRange(amplitude_deg, "amplitude_deg", 0.0, true, &f) &&
          CheckIn("amplitude_deg.max", amplitude_deg.max, 0.0, 85.0, Ends::kOpenClosed, &f) &&
          CheckUniformRange(drag_coeff_kg_m2, "drag_coeff_kg_m2", 0.0, false, &f) &&
          CheckUniformRange(viscous_coeff_kg_m2_per_s, "viscous_coeff_kg_m2_per_s", 0.0, false,
                            &f) &&
          CheckIn("rig.tare_damping_scale", tare_damping_scale, 0.0, 1.0, Ends::kClosed, &f)) ||
         FailWith(f, why);
}

std::string AttitudeFolder(const std::array<double, 2>& roll_pitch_deg) {
  return "roll_" + FormatPitchDeg(roll_pitch_deg[0]) + "_pitch_" +
         FormatPitchDeg(roll_pitch_deg[1]);
}

std::string FormatPitchDeg(double pitch_deg) {
  char buffer[64];
  std::snprintf(buffer, sizeof(buffer), "%.6g", pitch_deg);
  std::string s = buffer;
  return s == "-0" ? "0" : s;
}

uint64_t DeriveSeed(uint64_t seed, const std::string& name) {
  uint64_t h = 1469598103934665603ULL;  // FNV-1a
  for (unsigned char c : name) {
    h ^= c;
    h *= 1099511628211ULL;
  }
  uint64_t z = seed ^ (h + 0x9E3779B97F4A7C15ULL + (seed << 6) + (seed >> 2));  // SplitMix64
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ULL;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBULL;
  return z ^ (z >> 31);
}

Eigen::Matrix3d MountingFromRollPitchYawDeg(double roll_deg, double pitch_deg, double yaw_deg) {
  return (Eigen::AngleAxisd(yaw_deg * kRadPerDeg, Eigen::Vector3d::UnitZ()) *
          Eigen::AngleAxisd(pitch_deg * kRadPerDeg, Eigen::Vector3d::UnitY()) *
          Eigen::AngleAxisd(roll_deg * kRadPerDeg, Eigen::Vector3d::UnitX()))
      .toRotationMatrix();
}

bool SimulateCampaign(const CampaignSpec& spec, const SimulationOptions& options, uint64_t seed,
                      std::vector<CampaignTrace>* out, std::string* why) {
  if (!spec.Check(why) || !options.Check(why)) return false;
  out->clear();
  enum Kind { kAircraftLog, kTareLog, kReferenceLog };
  auto make = [&](const std::string& path, Kind kind, int trial, double nominal_deg,
                  std::optional<double> nominal_roll_deg = std::nullopt) -> bool {
    const bool tare = kind != kAircraftLog;  // rig without the aircraft
    CampaignTrace ct;
    ct.relative_path = path;
    ct.is_tare = kind == kTareLog;
    ct.is_calibration = kind == kReferenceLog;
    ct.trial = trial;
    ct.nominal_pitch_deg = nominal_deg;
    Rng rng(DeriveSeed(seed, path + "#setup"));
    if (!nominal_roll_deg) {
      ct.true_pitch_deg =
          std::clamp(nominal_deg + rng.Normal(spec.pitch_error_sigma_deg), -90.0, 90.0);
    } else {
      // An attitude campaign: the roll's error from a stream of its own; a pitch set beyond
      // +-90 deg is the same attitude as 180 - pitch with the roll turned by 180 deg.
      ct.nominal_roll_deg = *nominal_roll_deg;
      double pitch = nominal_deg + rng.Normal(spec.pitch_error_sigma_deg);
      Rng roll_rng(DeriveSeed(seed, path + "#roll"));
      double roll = *nominal_roll_deg + roll_rng.Normal(spec.roll_error_sigma_deg);
      if (std::abs(pitch) > 90.0) {
        pitch = std::copysign(180.0, pitch) - pitch;
        roll += 180.0;
      }
      ct.true_pitch_deg = pitch;
      ct.true_roll_deg = std::remainder(roll, 360.0);
    }
    const double amplitude_deg =
        rng.Uniform(kind == kReferenceLog && spec.calibration_amplitude_deg.max > 0.0
                        ? spec.calibration_amplitude_deg
                        : spec.amplitude_deg);
    const double sign = rng.Uniform() < options.negative_amplitude_probability ? -1.0 : 1.0;
    const double damping_scale = tare ? spec.tare_damping_scale : 1.0;
    const double drag = damping_scale * rng.Uniform(spec.drag_coeff_kg_m2);
    const double viscous = damping_scale * rng.Uniform(spec.viscous_coeff_kg_m2_per_s);
    spec.rig.InertiaAtPitch(nominal_deg, &ct.inertia_rig_kg_m2);
    ct.inertia_aircraft_kg_m2 =
        tare ? 0.0
             : spec.aircraft.InertiaAtAttitude(ct.true_roll_deg * kRadPerDeg,
                                               ct.true_pitch_deg * kRadPerDeg);
    ct.inertia_reference_kg_m2 = kind == kReferenceLog ? spec.reference_inertia_kg_m2 : 0.0;
    TraceSetup& s = ct.setup;
    s.geometry.filar_length_m = spec.TrueLengthM();
    s.geometry.filar_separation_m = spec.TrueSeparationM();
    for (const AttitudeOverride& o : spec.attitude_overrides) {
      if (kind != kAircraftLog || !nominal_roll_deg || o.attitude_deg[0] != *nominal_roll_deg ||
          o.attitude_deg[1] != nominal_deg ||
          (!o.trials.empty() &&
           std::find(o.trials.begin(), o.trials.end(), trial) == o.trials.end())) {
        continue;
      }
      if (o.true_filar_length_m > 0) s.geometry.filar_length_m = o.true_filar_length_m;
      if (o.true_filar_separation_m > 0) s.geometry.filar_separation_m = o.true_filar_separation_m;
      if (o.inertia_scatter > 0) {
        Rng scatter_rng(DeriveSeed(seed, path + "#scatter"));
        ct.inertia_aircraft_kg_m2 *=
            std::max(0.05, 1.0 + o.inertia_scatter * scatter_rng.Normal(1.0));
      }
    }
    s.geometry.gravity_mps2 = spec.gravity_mps2;
    s.geometry.mass_kg = spec.rig.mass_kg + spec.rig.imu_mass_kg +
                         (kind == kAircraftLog ? spec.aircraft.mass_kg : 0.0) +
                         (kind == kReferenceLog ? spec.reference_mass_kg : 0.0);
    s.params.inertia_kg_m2 =
        ct.inertia_aircraft_kg_m2 + ct.inertia_rig_kg_m2 + ct.inertia_reference_kg_m2;
    s.params.drag_coeff_kg_m2 = drag;
    s.params.viscous_coeff_kg_m2_per_s = viscous;
    s.pitch_rad = ct.true_pitch_deg * kRadPerDeg;
    s.roll_rad = ct.true_roll_deg * kRadPerDeg;
    s.amplitude_rad = sign * amplitude_deg * kRadPerDeg;
    s.body_from_imu = spec.rig.body_from_imu;
    s.imu_offset_in_body_m = spec.rig.imu_offset_in_body_m;
    std::string trace_why;
    if (!SimulateTrace(s, options, DeriveSeed(seed, path), &ct.trace, &trace_why)) {
      return SetWhy(why, path + ": " + trace_why);
    }
    out->push_back(std::move(ct));
    return true;
  };
  for (double pitch : spec.pitch_deg) {
    for (int k = 1; k <= spec.trials_per_pitch; ++k) {
      if (!make("pitch_" + FormatPitchDeg(pitch) + "/trial_" + std::to_string(k) + ".csv",
                kAircraftLog, k, pitch)) {
        return false;
      }
    }
  }
  for (const std::array<double, 2>& attitude : spec.attitudes_deg) {
    for (int k = 1; k <= spec.trials_per_pitch; ++k) {
      if (!make(AttitudeFolder(attitude) + "/trial_" + std::to_string(k) + ".csv", kAircraftLog, k,
                attitude[1], attitude[0])) {
        return false;
      }
    }
  }
  for (int k = 1; k <= spec.tare_logs; ++k) {
    if (!make("tare/tare_" + std::to_string(k) + ".csv", kTareLog, k, spec.tare_pitch_deg))
      return false;
  }
  for (int k = 1; k <= spec.calibration_logs; ++k) {
    if (!make("calibration/reference_" + std::to_string(k) + ".csv", kReferenceLog, k,
              spec.tare_pitch_deg)) {
      return false;
    }
  }
  return true;
}

}  // namespace bifilar

#include "pipeline/config/plausibility.h"

#include <cmath>
#include <cstdio>

#include "base/option_check.h"
#include "base/units.h"
#include "pendulum/model.h"

namespace bifilar {
namespace {

struct UnitGuess {
  const char* name;  // as the user would write it: "mm", "g", "kg cm^2"
  double to_si;      // value in that unit * to_si = SI
};

constexpr UnitGuess kLengthUnits[] = {
    {"mm", 1e-3}, {"cm", 1e-2}, {"inches", 0.0254}, {"feet", 0.3048}};
constexpr UnitGuess kMassUnits[] = {{"g", 1e-3}, {"lb", 0.45359237}};
constexpr UnitGuess kInertiaUnits[] = {{"kg cm^2", 1e-4},
                                       {"kg mm^2", 1e-6},
                                       {"g cm^2", 1e-7},
                                       {"lb in^2", 2.9263965e-4},
                                       {"slug ft^2", kKgM2PerSlugFt2}};

std::string Num(double value) {
  char buffer[64];
  std::snprintf(buffer, sizeof(buffer), "%.4g", value);
  return buffer;
}

// "; if this is in mm, write 0.594; if in cm, 5.94" for (at most two of) the units whose
// conversion lands where `fits` says; "" when none does.
template <size_t N, typename Fits>
std::string Suggestion(const UnitGuess (&units)[N], double value, const Fits& fits) {
  std::string text;
  int found = 0;
  for (const UnitGuess& u : units) {
    const double si = value * u.to_si;
    if (found < 2 && fits(si)) {
      text += found == 0 ? ": if this is in " + std::string(u.name) + ", write " + Num(si)
                         : "; if in " + std::string(u.name) + ", " + Num(si);
      ++found;
    }
  }
  return text;
}

}  // namespace

std::string ImplausibleValue(const std::string& key, const char* quantity, double value, double min,
                             double max) {
  if (value >= min && value <= max) return "";
  const bool length = std::string(quantity) == "length";
  const char* unit = length ? "m" : "kg";
  // "rig.filar_length_m = 594; must be in [0.05, 20] (m), a lab rig's range: if this is in mm, ..."
  const std::string text = CheckMessage(
      key, value,
      "in " + IntervalText(min, max, Ends::kClosed) + " (" + unit + "), a lab rig's range");
  const auto fits = [&](double si) { return si >= min && si <= max; };
  const std::string hint =
      length ? Suggestion(kLengthUnits, value, fits) : Suggestion(kMassUnits, value, fits);
  return text + (hint.empty() ? "; values are SI (" + std::string(unit) + ")" : hint);
}

std::string ImplausibleRigInertia(const std::string& key, double inertia_kg_m2, double rig_mass_kg,
                                  double filar_separation_m) {
  if (!(rig_mass_kg > 0.0) || !(filar_separation_m > 0.0) || !(inertia_kg_m2 >= 0.0)) return "";
  const double max_radius_m = kMaxRigGyrationOverSeparation * filar_separation_m;
  const double radius_m = std::sqrt(inertia_kg_m2 / rig_mass_kg);
  if (radius_m <= max_radius_m) return "";
  // A likely unit puts the radius of gyration within the fit's plausible band around D/2.
  const double half = 0.5 * filar_separation_m;
  const auto fits = [&](double si) {
    const double r = std::sqrt(si / rig_mass_kg);
    return r >= half / kGyrationFactor && r <= kGyrationFactor * half;
  };
  const std::string hint = Suggestion(kInertiaUnits, inertia_kg_m2, fits);
  // The bound: the inertia at which sqrt(I/m) reaches its largest plausible value.
  const double max_inertia_kg_m2 = rig_mass_kg * max_radius_m * max_radius_m;
  return CheckMessage(key, inertia_kg_m2,
                      "<= " + Num(max_inertia_kg_m2) +
                          " (kg m^2), where the rig's radius of "
                          "gyration sqrt(I / rig.mass_kg) (rig.mass_kg " +
                          Num(rig_mass_kg) + " kg) is " + Num(kMaxRigGyrationOverSeparation) +
                          " times the wire separation D = " + Num(filar_separation_m) +
                          " m; this I gives " + Num(radius_m) + " m: no lab rig") +
         (hint.empty() ? "; values are SI (kg m^2)" : hint);
}

std::string SeparationNotBelowLength(double filar_length_m, double filar_separation_m) {
  std::string why;
  if (CheckSeparationBelowLength(filar_length_m, filar_separation_m, &why)) return "";
  const auto fits = [&](double si) { return si >= kMinFilarSeparationM && si < filar_length_m; };
  const std::string hint = Suggestion(kLengthUnits, filar_separation_m, fits);
  return "'rig.filar_separation_m': " + why + (hint.empty() ? "" : hint);
}

std::vector<std::string> FitPlausibilityWarnings(double inertia_kg_m2, double mass_kg,
                                                 double filar_separation_m, double filar_length_m,
                                                 double amplitude_deg, RateUnit gyro_unit) {
  std::vector<std::string> warnings;
  char buffer[600];
  if (std::isfinite(amplitude_deg) && amplitude_deg < kMinPlausibleAmplitudeDeg) {
    if (gyro_unit == RateUnit::kDegPerS) {
      std::snprintf(buffer, sizeof(buffer),
                    "the largest fitted amplitude is %.2g deg, below any hand release (5-60 deg): "
                    "if the gyro logs rad/s, set imu.gyro.unit: rad/s (rad/s read as deg/s is 57 "
                    "times too small, and so is the amplitude correction of I)",
                    amplitude_deg);
    } else {
      std::snprintf(buffer, sizeof(buffer),
                    "the largest fitted amplitude is %.2g deg, below any hand release (5-60 deg): "
                    "check imu.gyro.unit and imu.gyro.columns",
                    amplitude_deg);
    }
    warnings.push_back(buffer);
  }
  if (inertia_kg_m2 > 0.0 && mass_kg > 0.0 && filar_separation_m > 0.0 && filar_length_m > 0.0) {
    const double radius_m = std::sqrt(inertia_kg_m2 / mass_kg);
    const double ratio = radius_m / (0.5 * filar_separation_m);
    if (!(ratio >= 1.0 / kGyrationFactor && ratio <= kGyrationFactor)) {
      std::snprintf(buffer, sizeof(buffer),
                    "the radius of gyration sqrt(I/m) = %.3g m is %.3g times the wire "
                    "half-separation D/2 = %.3g m (real rigs: 0.5-2.3; plausible within %g times "
                    "either way): the period is %.3g times that of a simple pendulum of length "
                    "L = %.4g m, so check rig.filar_length_m and imu.time.unit (D and the mass "
                    "cancel in this ratio)",
                    radius_m, ratio, 0.5 * filar_separation_m, kGyrationFactor, ratio,
                    filar_length_m);
      warnings.push_back(buffer);
    }
  }
  return warnings;
}

std::string ImpossibleAmplitude(double largest_amplitude_deg, double smallest_amplitude_deg,
                                RateUnit gyro_unit) {
  if (!(largest_amplitude_deg > kMaxSwingAmplitudeDeg)) return "";
  char buffer[400];
  if (gyro_unit == RateUnit::kRadPerS) {
    const double scale = kRadPerDeg;  // deg/s read as rad/s is 57.3 times too large
    std::snprintf(
        buffer, sizeof(buffer),
        "the swing reaches %.4g deg, beyond the 180 deg where a bifilar's wires cross: if "
        "the gyro logs deg/s, set imu.gyro.unit: deg/s (the amplitudes are then %.3g to "
        "%.3g deg)",
        largest_amplitude_deg, largest_amplitude_deg * scale, smallest_amplitude_deg * scale);
  } else {
    std::snprintf(buffer, sizeof(buffer),
                  "the swing reaches %.4g deg, beyond the 180 deg where a bifilar's wires cross: "
                  "check imu.gyro.unit and imu.gyro.columns",
                  largest_amplitude_deg);
  }
  return buffer;
}

std::string TimeUnitHint(const std::vector<double>& t_s, const std::vector<double>& rate_rad_per_s,
                         const WindowOptions& options, TimeUnit declared) {
  // Scale 1000: the log's unit is 1000 times the declared one (s declared ms); 1/1000: the reverse.
  struct Try {
    double scale;
    TimeUnit from, to;
  };
  const Try tries[] = {{1e3, TimeUnit::kMilliseconds, TimeUnit::kSeconds},
                       {1e3, TimeUnit::kMicroseconds, TimeUnit::kMilliseconds},
                       {1e-3, TimeUnit::kSeconds, TimeUnit::kMilliseconds},
                       {1e-3, TimeUnit::kMilliseconds, TimeUnit::kMicroseconds}};
  for (const Try& t : tries) {
    if (t.from != declared) continue;
    std::vector<double> scaled(t_s.size());
    for (size_t k = 0; k < t_s.size(); ++k) scaled[k] = t.scale * t_s[k];
    const FreeOscillationWindow w = FindFreeOscillationWindow(scaled, rate_rad_per_s, options, "");
    if (!w.IsUsable()) continue;
    char buffer[400];
    std::snprintf(buffer, sizeof(buffer),
                  "; read with imu.time.unit: %s instead of %s, the log shows a swing of period "
                  "%.3g s: check imu.time.unit",
                  ToString(t.to), ToString(t.from), w.period_s);
    return buffer;
  }
  return "";
}

}  // namespace bifilar

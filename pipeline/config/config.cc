// The campaign config's types (pipeline/config/config.h): names of the pitch sources, the
// geometries a config gives each role, and every check of the values (CampaignConfig::Check,
// FitConfig::Check, EllipseConfig::Check, gravity, plausibility). Reading the YAML file is
// config_load.cc's job.
#include "pipeline/config/config.h"

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <string>

#include "base/enum_names.h"
#include "base/option_table.h"
#include "base/text_format.h"
#include "base/units.h"
#include "fit/ellipse.h"
#include "pipeline/config/plausibility.h"

namespace bifilar {

namespace fs = std::filesystem;

constexpr EnumName<PitchSource> kPitchSourceNames[] = {{PitchSource::kNominal, "nominal"},
                                                       {PitchSource::kMeasured, "measured"}};

const char* ToString(PitchSource source) { return EnumToString(kPitchSourceNames, source, "?"); }
bool ParsePitchSource(const std::string& name, PitchSource* source) {
  return ParseEnum(kPitchSourceNames, name, source);
}
std::string PitchSourceAllowedValues() { return EnumAllowedValues(kPitchSourceNames); }

std::string ResolvePath(const std::string& folder, const std::string& path) {
  fs::path p(path);
  if (p.is_relative()) p = fs::path(folder) / p;
  return p.lexically_normal().string();
}

double CampaignConfig::EffectiveSeparationM() const {
  return filar_separation_m * std::sqrt(geometry_calibration.factor);  // sqrt(1) = 1 exactly
}

RigGeometry CampaignConfig::AircraftGeometry() const {
  RigGeometry g;
  g.filar_length_m = filar_length_m;
  g.filar_separation_m = EffectiveSeparationM();
  g.mass_kg = rig_mass_kg + aircraft_mass_kg;
  g.gravity_mps2 = gravity_mps2;
  return g;
}

RigUncertainties RigUncertainties::InEffect() const {
  if (!Assumed()) return *this;
  RigUncertainties assumed = *this;
  assumed.filar_length_std_m = kAssumedLengthStdM;
  assumed.filar_separation_std_m = kAssumedLengthStdM;
  return assumed;
}

RigGeometry CampaignConfig::TareGeometry() const {
  RigGeometry g = AircraftGeometry();
  g.mass_kg = rig_mass_kg;
  return g;
}

RigGeometry CampaignConfig::CalibrationGeometry() const {
  RigGeometry g = AircraftGeometry();
  g.mass_kg = rig_mass_kg + calibration.reference_mass_kg;
  return g;
}

bool CheckGravity(double gravity_mps2, bool off_earth, std::string* why) {
  CheckFailure f;
  if (off_earth) {
    if (CheckIn("gravity_mps2", gravity_mps2, 0, kMaxOffEarthGravityMps2, Ends::kOpenClosed, &f)) {
      return true;
    }
    f.allowed += " (gravity_off_earth: true)";
    return FailWith(f, why);
  }
  if (CheckIn("gravity_mps2", gravity_mps2, kMinEarthGravityMps2, kMaxEarthGravityMps2,
              Ends::kClosed, &f)) {
    return true;
  }
  f.allowed +=
      ", a gravity found on Earth (from the equator's mountains to the poles); check "
      "for a typo (" +
      Fmt("%g", kStandardGravityMps2) +
      " is standard gravity), or set "
      "'gravity_off_earth: true' for a rig elsewhere";
  return FailWith(f, why);
}

bool CampaignConfig::Check(std::string* why) const {
  std::string reason;
  CheckFailure f;
  if (calibration.enabled) {
    const RigCalibrationSpec& c = calibration;
    const bool ok =
        (!c.log_patterns.empty() ||
         CheckFail("rig.calibration.logs (files)", 0, "a list of at least one file", &f)) &&
        CheckGt("rig.calibration.reference_inertia_kg_m2", c.reference_inertia_kg_m2, 0, &f) &&
        CheckGt("rig.calibration.reference_mass_kg", c.reference_mass_kg, 0, &f) &&
        CheckGe("rig.calibration.reference_inertia_std_kg_m2", c.reference_inertia_std_kg_m2, 0,
                &f) &&
        CheckLt("rig.calibration.reference_inertia_std_kg_m2", c.reference_inertia_std_kg_m2,
                "rig.calibration.reference_inertia_kg_m2", c.reference_inertia_kg_m2, &f);
    if (!ok) return FailWith(f, why);
  }
  if (!CheckFiniteGt("rig.calibration factor", geometry_calibration.factor, 0, &f) ||
      !CheckFiniteGe("rig.calibration factor_rel_std", geometry_calibration.factor_rel_std, 0,
                     &f)) {
    return FailWith(f, why);
  }
  if (!CheckGravity(gravity_mps2, gravity_off_earth, why)) return false;
  if (!AircraftGeometry().Check(&reason)) {
    *why = "rig/aircraft: " + reason;
    return false;
  }
  if (!imu.format.Check(&reason)) {
    *why = "imu: " + reason;
    return false;
  }
  if (!CheckPlausible(&reason)) {
    *why = reason;
    return false;
  }
  // A standard uncertainty is below the quantity it qualifies (a 100 % uncertainty says nothing;
  // 1e308 overflowed the budget into a "non-finite value" naming no key).
  const struct {
    const char* key;
    double std, of;
  } stds[] = {
      {"rig.uncertainties.filar_length_std_m", uncertainties.filar_length_std_m, filar_length_m},
      {"rig.uncertainties.filar_separation_std_m", uncertainties.filar_separation_std_m,
       filar_separation_m},
      {"rig.uncertainties.mass_std_kg", uncertainties.mass_std_kg, rig_mass_kg},
      {"rig.uncertainties.gravity_std_mps2", uncertainties.gravity_std_mps2, gravity_mps2},
      {"aircraft.mass_std_kg", aircraft_mass_std_kg,
       aircraft_mass_kg > 0 ? aircraft_mass_kg : INFINITY},
      {"imu.gyro.scale_std", imu.gyro_scale_std, 1.0},
      {"rig.inertia.inertia_std_kg_m2", rig_inertia.inertia_std_kg_m2, kMaxRigInertiaStdKgM2},
  };
  for (const auto& s : stds) {
    // "below 0.5 (the quantity it qualifies)": the bound is the quantity's value.
    if (!CheckGe(s.key, s.std, 0, &f) ||
        !(s.std < s.of ||
          CheckFail(s.key, s.std, "< " + FormatCheckValue(s.of) + " (the quantity it qualifies)",
                    &f))) {
      return FailWith(f, why);
    }
  }
  return fit.Check(why) && ellipse.Check(why);
}

bool CampaignConfig::CheckPlausible(std::string* why) const {
  const struct {
    const char* key;
    const char* quantity;
    double value, min, max;
  } values[] = {
      {"rig.filar_length_m", "length", filar_length_m, kMinFilarLengthM, kMaxFilarLengthM},
      {"rig.filar_separation_m", "length", filar_separation_m, kMinFilarSeparationM,
       kMaxFilarSeparationM},
      {"rig.mass_kg", "mass", rig_mass_kg, 0.0, kMaxMassKg},
      {"aircraft.mass_kg", "mass", aircraft_mass_kg, 0.0, kMaxMassKg},
      {"rig.mass_kg + aircraft.mass_kg", "mass", rig_mass_kg + aircraft_mass_kg,
       kMinSuspendedMassKg, 2 * kMaxMassKg},
  };
  for (const auto& v : values) {
    *why = ImplausibleValue(v.key, v.quantity, v.value, v.min, v.max);
    if (!why->empty()) return false;
  }
  *why = SeparationNotBelowLength(filar_length_m, filar_separation_m);
  if (!why->empty()) return false;
  if (rig_inertia.kind == RigInertiaSpec::Kind::kValue) {
    *why = ImplausibleRigInertia("rig.inertia.inertia_kg_m2", rig_inertia.inertia_kg_m2,
                                 rig_mass_kg, filar_separation_m);
  }
  for (const auto& [pitch_deg, value] : rig_inertia.table_kg_m2) {
    if (!why->empty()) break;
    char key[96];
    std::snprintf(key, sizeof(key), "rig.inertia.table (pitch %g deg)", pitch_deg);
    *why = ImplausibleRigInertia(key, value, rig_mass_kg, filar_separation_m);
  }
  return why->empty();
}

namespace {

// failure->field, a member of `Options` (named by the struct's own Check), as its YAML key below
// `fit`: "<section>.<key>" from the struct's table. Returns false.
template <class Options>
bool FailIn(const char* section, const OptionFields<Options>& fields, CheckFailure* failure) {
  if (failure != nullptr) {
    const OptionField<Options>* row = FindOptionField(fields, failure->field);
    failure->field = std::string(section) + "." + (row != nullptr ? row->key : failure->field);
  }
  return false;
}

}  // namespace

bool FitConfig::Check(CheckFailure* failure) const {
  const double max_deg = max_amplitude_deg.value_or(kMaxMaxAmplitudeDeg);
  if (max_amplitude_deg && !CheckIn("max_amplitude_deg", *max_amplitude_deg, kMinMaxAmplitudeDeg,
                                    kMaxMaxAmplitudeDeg, Ends::kClosed, failure)) {
    return false;
  }
  if (min_amplitude_deg &&
      !(CheckGe("min_amplitude_deg", *min_amplitude_deg, 0, failure) &&
        CheckLt("min_amplitude_deg", *min_amplitude_deg, "max_amplitude_deg", max_deg, failure))) {
    return false;
  }
  if (!quality.Check(failure)) return FailIn("quality", TraceQualityOptions::Fields(), failure);
  if (!sweep.Check(failure)) {
    return FailIn("amplitude_sweep", AmplitudeSweepOptions::Fields(), failure);
  }
  if (!glitch.Check(failure)) return FailIn("glitch", GlitchOptions::Fields(), failure);
  return true;
}

bool FitConfig::Check(std::string* why) const {
  CheckFailure failure;
  if (Check(&failure)) return true;
  return SetWhy(why, CheckMessage("fit." + failure.field, failure.value, failure.allowed));
}

bool EllipseConfig::Check(CheckFailure* failure) const {
  if (bootstrap != 0 &&
      !(bootstrap >= kMinBootstrapReplicates && bootstrap <= kMaxBootstrapReplicates)) {
    return CheckFail("bootstrap", bootstrap,
                     "0 (off) or in " + IntervalText(kMinBootstrapReplicates,
                                                     kMaxBootstrapReplicates, Ends::kClosed),
                     failure);
  }
  return CheckIn("confidence", confidence, 0, 1, Ends::kOpen, failure) &&
         CheckIn("min_angles", min_angles, 3, kMaxMinAngles, Ends::kClosed, failure);
}

bool EllipseConfig::Check(std::string* why) const {
  CheckFailure failure;
  if (Check(&failure)) return true;
  return SetWhy(why, CheckMessage("ellipse." + failure.field, failure.value, failure.allowed));
}

ImuLogOptions CampaignConfig::LogOptions() const {
  ImuLogOptions options = limits.LogOptions();
  options.dataflash_instance = imu.dataflash_instance;
  return options;
}

ImuLogOptions InputLimits::LogOptions() const {
  ImuLogOptions options;
  options.max_file_bytes = static_cast<uint64_t>(max_log_mb * 1e6);
  options.max_decompressed_bytes = static_cast<uint64_t>(max_decompressed_log_mb * 1e6);
  return options;
}

}  // namespace bifilar

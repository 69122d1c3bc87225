#include "pipeline/commands/simulate_spec.h"

#include <Eigen/Eigenvalues>
#include <cmath>
#include <limits>
#include <cstdio>
#include <filesystem>
#include <sstream>

#include <nlohmann/json.hpp>

#include "base/atomic_file.h"
#include "base/gzip.h"
#include "base/option_check.h"
#include "base/units.h"
#include "base/user_error.h"
#include "base/version.h"
#include "pendulum/model.h"
#include "pipeline/config/yaml_reader.h"
#include "pipeline/logs/simulated_log.h"
#include "pipeline/logs/dataflash.h"
#include "pipeline/logs/dataflash_writer.h"
#include "pipeline/logs/ulog_writer.h"

namespace bifilar {
namespace {
constexpr int kFooterRows = 4;                  // blank line + 3 summary rows (format.footer)

// root.Child(key), safe when the section is absent (yaml-cpp's const operator[] returns an
// invalid "zombie" node for a missing key, on which IsMap() throws).
YamlMap Section(YamlMap& root, const std::string& key) {
  if (root.Has(key)) return root.Child(key);
  root.Optional(key);
  return YamlMap(YAML::Node(YAML::NodeType::Null), root.file(), root.KeyPath(key));
}

std::string Num(double value) {
  char buffer[64];
  std::snprintf(buffer, sizeof(buffer), "%g", value);
  return buffer;
}

// The interval (lower, upper] or [lower, upper]; open at an infinite upper end.
std::string RangeText(double lower, bool lower_open, double upper) {
  const bool upper_open = std::isinf(upper);
  return IntervalText(lower, upper,
                      lower_open ? (upper_open ? Ends::kOpen : Ends::kOpenClosed)
                                 : (upper_open ? Ends::kClosedOpen : Ends::kClosed));
}

// Reads a number that must lie in a range; the message names the key, line, value and range
// (base/option_check.h's format).
double ReadValue(YamlMap& map, const std::string& key, double fallback, double lower,
                 bool lower_open, double upper) {
  const YAML::Node node = map.Optional(key);
  if (!map.Given(node, key, "a number")) return fallback;
  const double value = map.AsDouble(node, key);
  const bool ok = (lower_open ? value > lower : value >= lower) && value <= upper;
  if (!ok) {
    throw UserError(
        map.Where(node) + ": " +
        CheckMessage(map.KeyPath(key), value, "in " + RangeText(lower, lower_open, upper)));
  }
  return value;
}

std::optional<double> ReadOptionalValue(YamlMap& map, const std::string& key, double lower,
                                        bool lower_open, double upper) {
  if (!map.Has(key)) {
    map.Optional(key);
    return std::nullopt;
  }
  return ReadValue(map, key, 0.0, lower, lower_open, upper);
}

// A range: a number (fixed) or a list [min, max].
UniformRange ReadRange(YamlMap& map, const std::string& key, UniformRange fallback, double lower,
                       bool lower_open, double upper) {
  const YAML::Node node = map.Optional(key);
  if (!map.Given(node, key, "a number or a list [min, max]")) return fallback;
  UniformRange r;
  if (node.IsSequence()) {
    if (node.size() != 2) {
      throw UserError(map.Where(node) + ": '" + map.KeyPath(key) +
                      "' must be a number or a list [min, max]");
    }
    r.min = map.AsDouble(node[0], key);
    r.max = map.AsDouble(node[1], key);
  } else {
    r.min = r.max = map.AsDouble(node, key);
  }
  const bool ok = (lower_open ? r.min > lower : r.min >= lower) && r.max <= upper && r.min <= r.max;
  if (!ok) {
    throw UserError(map.Where(node) + ": " + map.KeyPath(key) + " = [" + FormatCheckValue(r.min) +
                    ", " + FormatCheckValue(r.max) + "]; must be min <= max, both in " +
                    RangeText(lower, lower_open, upper));
  }
  return r;
}

Eigen::Vector3d ReadVector3(YamlMap& map, const std::string& key, Eigen::Vector3d fallback) {
  const YAML::Node node = map.Optional(key);
  if (!map.Given(node, key, "a list of 3 numbers")) return fallback;
  if (!node.IsSequence() || node.size() != 3) {
    throw UserError(map.Where(node) + ": '" + map.KeyPath(key) + "' must be a list of 3 numbers");
  }
  Eigen::Vector3d v;
  for (int i = 0; i < 3; ++i) v[i] = map.AsDouble(node[i], key);
  return v;
}

std::array<std::string, 3> ReadColumns(YamlMap& map, const std::string& key,
                                       const std::array<std::string, 3>& fallback) {
  const YAML::Node node = map.Optional(key);
  if (!node.IsDefined() || node.IsNull()) return fallback;
  if (!node.IsSequence() || node.size() != 3) {
    throw UserError(map.Where(node) + ": '" + map.KeyPath(key) +
                    "' must be a list of 3 column names (x, y, z)");
  }
  std::array<std::string, 3> out;
  for (int i = 0; i < 3; ++i) out[i] = map.AsString(node[i], key);
  return out;
}

template <typename Unit, typename Parse>
Unit ReadUnit(YamlMap& map, const std::string& key, Unit fallback, Parse parse, const std::string& allowed) {
  const YAML::Node node = map.Optional(key);
  if (!node.IsDefined() || node.IsNull()) return fallback;
  const std::string name = map.AsString(node, key);
  Unit unit = fallback;
  if (!parse(name, &unit)) {
    throw UserError(map.Where(node) + ": unknown unit '" + name + "' for '" + map.KeyPath(key) +
                    "'; allowed " + allowed);
  }
  return unit;
}

void ReadFormat(YamlMap map, SimulateSpec* spec) {
  ImuFormat& f = spec->format;
  f.time_column = map.OptionalString("time_column", f.time_column);
  f.time_unit = ReadUnit(map, "time_unit", f.time_unit,
                         [](const std::string& n, TimeUnit* u) { return ParseTimeUnit(n, u); },
                         TimeUnitAllowedValues());
  f.gyro_columns = ReadColumns(map, "gyro_columns", f.gyro_columns);
  f.gyro_unit = ReadUnit(map, "gyro_unit", f.gyro_unit,
                         [](const std::string& n, RateUnit* u) { return ParseRateUnit(n, u); },
                         RateUnitAllowedValues());
  f.accel_columns = ReadColumns(map, "accel_columns", f.accel_columns);
  f.accel_unit = ReadUnit(map, "accel_unit", f.accel_unit,
                          [](const std::string& n, AccelUnit* u) { return ParseAccelUnit(n, u); },
                          AccelUnitAllowedValues());
  const YAML::Node delim = map.Optional("delimiter");
  if (delim.IsDefined() && !delim.IsNull()) {
    const std::string d = map.AsString(delim, "delimiter");
    if (d.size() != 1 || d == "\"" || d == "\n" || d == "\r" || std::isalnum(static_cast<unsigned char>(d[0])) ||
        d == "." || d == "-" || d == "+") {
      throw UserError(map.Where(delim) + ": 'format.delimiter' must be one character such as "
                      "',', ';' or a tab");
    }
    f.delimiter = d[0];
  }
  spec->write.significant_digits =
      static_cast<int>(ReadValue(map, "significant_digits", 9, 6, false, 17));
  spec->ulog = map.OptionalBool("ulog", false);
  spec->gzip = map.OptionalBool("gzip", false);
  spec->footer = map.OptionalBool("footer", false);
  map.Finish();
  std::string why;
  if (!f.Check(&why)) throw UserError(map.Where(YAML::Node()) + ": format: " + why);
}

void ReadTimeline(YamlMap map, TimelineOptions* t) {
  const double inf = INFINITY;
  t->rest_before_s = ReadRange(map, "rest_before_s", t->rest_before_s, 0, false, 3600);
  t->twist_s = ReadRange(map, "twist_s", t->twist_s, 0, true, 60);
  t->hold_s = ReadRange(map, "hold_s", t->hold_s, 0, false, 600);
  t->tremor_deg = ReadValue(map, "tremor_deg", t->tremor_deg, 0, false, 5);
  t->tremor_hz = ReadRange(map, "tremor_hz", t->tremor_hz, 0, true, 50);
  t->release_rate_sigma_deg_per_s =
      ReadValue(map, "release_rate_sigma_deg_per_s", t->release_rate_sigma_deg_per_s, 0, false, 90);
  t->free_s = ReadRange(map, "free_s", t->free_s, 0, true, 86400);
  t->stop_probability = ReadValue(map, "stop_probability", t->stop_probability, 0, false, 1);
  t->stop_time_constant_s =
      ReadValue(map, "stop_time_constant_s", t->stop_time_constant_s, 0, true, 10);
  t->rest_after_s = ReadRange(map, "rest_after_s", t->rest_after_s, 0, false, 3600);
  (void)inf;
  map.Finish();
}

void ReadSensor(YamlMap map, SensorOptions* s, bool* time_jitter_given) {
  s->sample_rate_hz = ReadValue(map, "sample_rate_hz", s->sample_rate_hz, 0, true, 100000);
  {
    const YAML::Node steps = map.Optional("sample_steps");
    if (steps.IsDefined() && !steps.IsNull()) {
      const std::string name = map.AsString(steps, "sample_steps");
      if (!ParseSampleSteps(name, &s->sample_steps)) {
        throw UserError(map.Where(steps) + ": unknown value '" + name + "' for '" +
                        map.KeyPath("sample_steps") + "'; allowed " + SampleStepsAllowedValues());
      }
    }
  }
  s->step_log_sigma = ReadValue(map, "step_log_sigma", s->step_log_sigma, 0, false, 3);
  s->step_range_s = ReadRange(map, "step_range_s", s->step_range_s, 0, true, 3600);
  *time_jitter_given = map.Has("time_jitter_sigma_s");
  if (*time_jitter_given) {
    const YAML::Node jitter = map.Optional("time_jitter_sigma_s");
    const double value = map.AsDouble(jitter, "time_jitter_sigma_s");
    if (value > 1.0 / s->sample_rate_hz) {
      throw UserError(map.Where(jitter) + ": '" + map.KeyPath("time_jitter_sigma_s") + "' = " +
                      Num(value) + " s is more than one sample period (1/" +
                      map.KeyPath("sample_rate_hz") + " = " + Num(1.0 / s->sample_rate_hz) +
                      " s); lower it or the sample rate");
    }
  }
  s->time_jitter_sigma_s = ReadValue(map, "time_jitter_sigma_s",
                                     DefaultTimeJitterSigmaS(s->sample_rate_hz), 0, false,
                                     1.0 / s->sample_rate_hz);
  s->drop_fraction = ReadValue(map, "drop_fraction", s->drop_fraction, 0, false, 0.5);
  s->drop_burst_probability =
      ReadValue(map, "drop_burst_probability", s->drop_burst_probability, 0, false, 1);
  s->drop_burst_max_samples = static_cast<int>(
      ReadValue(map, "drop_burst_max_samples", s->drop_burst_max_samples, 2, false, 100000));
  s->start_time_s = ReadRange(map, "start_time_s", s->start_time_s, -1e9, false, 1e9);
  s->gyro_noise_sigma_deg_per_s =
      ReadValue(map, "gyro_noise_sigma_deg_per_s", s->gyro_noise_sigma_deg_per_s, 0, false, 100);
  s->gyro_noise_ar1_phi = ReadValue(map, "gyro_noise_ar1_phi", s->gyro_noise_ar1_phi, 0, false, 0.99);
  s->gyro_bias_walk_deg_per_s_per_sqrt_s =
      ReadValue(map, "gyro_bias_walk_deg_per_s_per_sqrt_s", s->gyro_bias_walk_deg_per_s_per_sqrt_s,
                0, false, 10);
  s->spike_count = static_cast<int>(ReadValue(map, "spike_count", s->spike_count, 0, false, 1000));
  {
    const YAML::Node count = map.Optional("spike_count");
    if (count.IsDefined() && !count.IsNull() &&
        map.AsDouble(count, "spike_count") != static_cast<double>(s->spike_count)) {
      throw UserError(map.Where(count) + ": '" + map.KeyPath("spike_count") +
                      "' must be a whole number in [0, 1000]");
    }
  }
  s->spike_rate_rad_per_s =
      ReadValue(map, "spike_rate_rad_per_s", s->spike_rate_rad_per_s, 0, true, 1e4);
  s->gyro_bias_sigma_deg_per_s =
      ReadValue(map, "gyro_bias_sigma_deg_per_s", s->gyro_bias_sigma_deg_per_s, 0, false, 100);
  s->gyro_scale_error_sigma =
      ReadValue(map, "gyro_scale_error_sigma", s->gyro_scale_error_sigma, 0, false, 0.2);
  {
    // true (specific force), false (no accelerometer columns) or gravity_removed.
    const YAML::Node accel = map.Optional("accelerometer");
    if (accel.IsDefined() && !accel.IsNull()) {
      bool present = true;
      if (accel.IsScalar() && accel.Scalar() == "gravity_removed") {
        s->accelerometer = true;
        s->accel_gravity_removed = true;
      } else if (accel.IsScalar() && YAML::convert<bool>::decode(accel, present)) {
        s->accelerometer = present;
        s->accel_gravity_removed = false;
      } else {
        throw UserError(map.Where(accel) + ": '" + map.KeyPath("accelerometer") +
                        "' must be true, false or gravity_removed");
      }
    }
  }
  s->gravity_removal_error_deg =
      ReadRange(map, "gravity_removal_error_deg", s->gravity_removal_error_deg, 0, false, 30);
  s->accel_noise_sigma_mps2 =
      ReadValue(map, "accel_noise_sigma_mps2", s->accel_noise_sigma_mps2, 0, false, 10);
  s->accel_bias_sigma_mps2 =
      ReadValue(map, "accel_bias_sigma_mps2", s->accel_bias_sigma_mps2, 0, false, 10);
  s->rocking_max_deg = ReadValue(map, "rocking_max_deg", s->rocking_max_deg, 0, false, 10);
  s->rocking_frequency_hz =
      ReadValue(map, "rocking_frequency_hz", s->rocking_frequency_hz, 0, false, s->sample_rate_hz / 4);
  s->rocking_decay_s = ReadValue(map, "rocking_decay_s", s->rocking_decay_s, 0, true, 1e6);
  map.Finish();
}

// Moments of inertia given either in kg m^2 or in slug ft^2 (exactly one of the two keys).
double ReadInertia(YamlMap& map, const std::string& stem, bool required, double lower,
                   bool lower_open) {
  const std::string si = stem + "_kg_m2", imperial = stem + "_slug_ft2";
  const bool has_si = map.Has(si), has_imperial = map.Has(imperial);
  if (has_si && has_imperial) {
    throw UserError(map.Where(map.Optional(imperial)) + ": give either '" + map.KeyPath(si) +
                    "' or '" + map.KeyPath(imperial) + "', not both");
  }
  if (has_imperial) {
    map.Optional(si);
    return kKgM2PerSlugFt2 * ReadValue(map, imperial, 0, lower, lower_open, 1e9);
  }
  map.Optional(imperial);
  if (!has_si && required) {
    throw UserError(map.file() + ": missing required key '" + map.KeyPath(si) + "' (or '" +
                    map.KeyPath(imperial) + "')");
  }
  return ReadValue(map, si, 0.0, lower, lower_open, 1e9);
}

void ReadGeometry(YamlMap map, std::optional<double>* length, std::optional<double>* separation,
                  double* gravity, std::optional<double>* true_length,
                  std::optional<double>* true_separation) {
  const double inf = INFINITY;
  const YAML::Node length_node = map.Optional("filar_length_m");
  *length = ReadOptionalValue(map, "filar_length_m", 0, true, 1000);
  *separation = ReadOptionalValue(map, "filar_separation_m", 0, true, 1000);
  *gravity = ReadValue(map, "gravity_mps2", *gravity, 0, true, 100);
  // A mis-measured rig (campaign only): the geometry the logs are simulated with.
  *true_length = ReadOptionalValue(map, "true_filar_length_m", 0, true, 1000);
  *true_separation = ReadOptionalValue(map, "true_filar_separation_m", 0, true, 1000);
  (void)inf;
  std::string why;
  if (length->has_value() && separation->has_value() &&
      !CheckSeparationBelowLength(**length, **separation, &why)) {
    throw UserError(map.Where(length_node) + ": '" + map.KeyPath("filar_separation_m") + "': " +
                    why);
  }
  map.Finish();
}

// `seed`: a non-negative integer that fits 64 bits.
void ReadSeed(YamlMap& root, SimulateSpec* spec) {
  const YAML::Node seed = root.Optional("seed");
  if (root.Given(seed, "seed", "an integer")) {
    unsigned long long value = 0;
    if (!seed.IsScalar() || (!seed.Scalar().empty() && seed.Scalar()[0] == '-') ||
        !YAML::convert<unsigned long long>::decode(seed, value)) {
      throw UserError(root.Where(seed) + ": 'seed' must be an integer in [0, " +
                      std::to_string(std::numeric_limits<uint64_t>::max()) + "]");
    }
    spec->seed = value;
  }
}

// `model` and `integrator`: the pendulum model and the ODE solver of the simulation.
void ReadModelAndIntegrator(YamlMap& root, SimulateSpec* spec) {
  {
    const YAML::Node model = root.Optional("model");
    if (model.IsDefined() && !model.IsNull()) {
      const std::string name = root.AsString(model, "model");
      if (!ParsePendulumModel(name, &spec->options.model)) {
        throw UserError(root.Where(model) + ": unknown model '" + name +
                        "' for 'model'; allowed " + PendulumModelAllowedValues());
      }
    }
  }
  {
    const YAML::Node method = root.Optional("integrator");
    if (method.IsDefined() && !method.IsNull()) {
      const std::string name = root.AsString(method, "integrator");
      if (!ParseIntegratorMethod(name, &spec->options.integrator.method)) {
        throw UserError(root.Where(method) + ": unknown integrator '" + name +
                        "' for 'integrator'; allowed " +
                        IntegratorMethodAllowedValues() + " (default " +
                        ToString(spec->options.integrator.method) + ")");
      }
    }
  }
}

// The `geometry` section's values (ReadGeometry).
struct SpecGeometry {
  std::optional<double> length, separation, true_length, true_separation;
  double gravity = kStandardGravityMps2;
};

// `swing`: amplitudes, damping and the departures from the ideal model.
void ReadSwing(YamlMap swing, SimulateSpec* spec) {
  const double inf = INFINITY;
  CampaignSpec& c = spec->campaign;
  c.amplitude_deg = ReadRange(swing, "amplitude_deg", c.amplitude_deg, 0, true, 85);
  spec->options.negative_amplitude_probability =
      ReadValue(swing, "negative_amplitude_probability",
                spec->options.negative_amplitude_probability, 0, false, 1);
  c.drag_coeff_kg_m2 = ReadRange(swing, "drag_coeff_kg_m2", c.drag_coeff_kg_m2, 0, false, inf);
  c.viscous_coeff_kg_m2_per_s =
      ReadRange(swing, "viscous_coeff_kg_m2_per_s", c.viscous_coeff_kg_m2_per_s, 0, false, inf);
  spec->options.sway_coupling_at_60deg =
      ReadValue(swing, "sway_coupling_percent_at_60deg", 0.0, 0, false, 50) / 100.0;
  spec->options.softening_at_30deg =
      ReadValue(swing, "softening_percent_at_30deg", 0.0, 0, false, 50) / 100.0;
  spec->options.softening_exponent =
      ReadValue(swing, "softening_exponent", spec->options.softening_exponent, 1, false, 4);
  swing.Finish();
}

// `aircraft`: mass and inertia tensor of the simulated aircraft.
void ReadAircraft(YamlMap aircraft, const std::string& file, AircraftTruth* a) {
  a->mass_kg = aircraft.RequiredDouble("mass_kg");
  a->mass_kg = ReadValue(aircraft, "mass_kg", 0, 0, true, 1e6);
  a->ix_kg_m2 = ReadInertia(aircraft, "ix", true, 0, true);
  a->iz_kg_m2 = ReadInertia(aircraft, "iz", true, 0, true);
  a->ixz_kg_m2 = ReadInertia(aircraft, "ixz", true, -1e9, false);
  // The rest of the tensor (campaigns that roll): optional, 0 when absent.
  a->iy_kg_m2 = ReadInertia(aircraft, "iy", false, 0, false);
  a->ixy_kg_m2 = ReadInertia(aircraft, "ixy", false, -1e9, false);
  a->iyz_kg_m2 = ReadInertia(aircraft, "iyz", false, -1e9, false);
  aircraft.Finish();
  std::string why;
  if (!a->Check(&why)) throw UserError(file + ": aircraft: " + why);
}

// `rig.inertia_by_pitch_kg_m2` (a mapping pitch_deg: inertia) or `rig.inertia_kg_m2`.
void ReadRigInertia(YamlMap& rig, CampaignSpec* c) {
  const bool has_table = rig.Has("inertia_by_pitch_kg_m2");
  if (has_table) {
    const YAML::Node table = rig.Optional("inertia_by_pitch_kg_m2");
    if (!table.IsMap()) {
      throw UserError(rig.Where(table) + ": '" + rig.KeyPath("inertia_by_pitch_kg_m2") +
                      "' must be a mapping pitch_deg: inertia_kg_m2");
    }
    for (const auto& item : table) {
      const double pitch = rig.AsDouble(item.first, "inertia_by_pitch_kg_m2 (pitch)");
      const double inertia = rig.AsDouble(item.second, "inertia_by_pitch_kg_m2");
      if (!(inertia > 0)) {
        throw UserError(rig.Where(item.second) + ": " +
                        CheckMessage(rig.KeyPath("inertia_by_pitch_kg_m2") + " at " +
                                         FormatCheckValue(pitch) + " deg",
                                     inertia, "> 0"));
      }
      c->rig.inertia_by_pitch_kg_m2.emplace_back(pitch, inertia);
    }
    if (rig.Has("inertia_kg_m2")) {
      throw UserError(rig.Where(rig.Optional("inertia_kg_m2")) + ": give either '" +
                      rig.KeyPath("inertia_kg_m2") + "' or '" +
                      rig.KeyPath("inertia_by_pitch_kg_m2") + "', not both");
    }
    rig.Optional("inertia_kg_m2");
  } else {
    rig.Optional("inertia_by_pitch_kg_m2");
    c->rig.inertia_kg_m2 = rig.RequiredDouble("inertia_kg_m2");
    c->rig.inertia_kg_m2 = ReadValue(rig, "inertia_kg_m2", 0, 0, true, 1e9);
  }
}

// `rig`: mass, inertia, tare logs and the IMU's place on the rig.
void ReadRig(YamlMap rig, CampaignSpec* c) {
  c->rig.mass_kg = rig.RequiredDouble("mass_kg");
  c->rig.mass_kg = ReadValue(rig, "mass_kg", 0, 0, true, 1e6);
  c->rig.imu_mass_kg = ReadValue(rig, "imu_mass_kg", 0.0, 0, false, 1e3);
  ReadRigInertia(rig, c);
  c->tare_logs = static_cast<int>(ReadValue(rig, "tare_logs", 0, 0, false, 1000));
  c->tare_pitch_deg = ReadValue(rig, "tare_pitch_deg", 0, -90, false, 90);
  c->tare_damping_scale = ReadValue(rig, "tare_damping_scale", c->tare_damping_scale, 0, false, 1);
  c->rig.imu_offset_in_body_m =
      ReadVector3(rig, "imu_offset_m", Eigen::Vector3d(0.15, 0.10, -0.05));
  const Eigen::Vector3d rpy = ReadVector3(rig, "imu_mounting_rpy_deg", Eigen::Vector3d::Zero());
  c->rig.body_from_imu = MountingFromRollPitchYawDeg(rpy[0], rpy[1], rpy[2]);
  rig.Finish();
}

// `campaign.attitude_overrides`: attitudes whose logs were made otherwise (pendulum/simulate.h,
// AttitudeOverride): [{attitude_deg: [roll, pitch], true_filar_length_m, true_filar_separation_m,
// trials: [1, 2], inertia_scatter}], each key but attitude_deg optional.
void ReadAttitudeOverrides(YamlMap& campaign, CampaignSpec* c) {
  const YAML::Node list = campaign.Optional("attitude_overrides");
  if (!list.IsDefined() || list.IsNull()) return;
  if (!list.IsSequence()) {
    throw UserError(campaign.Where(list) + ": '" + campaign.KeyPath("attitude_overrides") +
                    "' must be a list of {attitude_deg: [roll, pitch], ...}");
  }
  for (size_t k = 0; k < list.size(); ++k) {
    YamlMap item(list[k], campaign.file(),
                 campaign.KeyPath("attitude_overrides") + "[" + std::to_string(k) + "]");
    AttitudeOverride o;
    const std::vector<double> attitude = item.OptionalDoubleList("attitude_deg", {});
    if (attitude.size() != 2) {
      throw UserError(item.Where(item.Optional("attitude_deg")) + ": '" +
                      item.KeyPath("attitude_deg") + "' must be [roll_deg, pitch_deg]");
    }
    o.attitude_deg = {attitude[0], attitude[1]};
    o.true_filar_length_m = ReadValue(item, "true_filar_length_m", 0.0, 0.0, false, 1000.0);
    o.true_filar_separation_m = ReadValue(item, "true_filar_separation_m", 0.0, 0.0, false, 1000.0);
    o.inertia_scatter = ReadValue(item, "inertia_scatter", 0.0, 0.0, false, 0.5);
    for (double t : item.OptionalDoubleList("trials", {})) o.trials.push_back(static_cast<int>(t));
    item.Finish();
    c->attitude_overrides.push_back(o);
  }
}

// `campaign`: the attitudes (pitch_deg, or attitudes_deg for a tensor campaign) and trials.
void ReadCampaignPlan(YamlMap campaign, CampaignSpec* c) {
  // attitudes_deg: [[roll, pitch], ...] (a tensor campaign) instead of pitch_deg.
  const YAML::Node attitudes = campaign.Optional("attitudes_deg");
  if (attitudes.IsDefined() && !attitudes.IsNull()) {
    if (!attitudes.IsSequence() || attitudes.size() == 0) {
      throw UserError(campaign.Where(attitudes) + ": '" + campaign.KeyPath("attitudes_deg") +
                      "' must be a list of [roll_deg, pitch_deg] pairs");
    }
    for (const auto& item : attitudes) {
      if (!item.IsSequence() || item.size() != 2) {
        throw UserError(campaign.Where(item) + ": '" + campaign.KeyPath("attitudes_deg") +
                        "' entries are [roll_deg, pitch_deg] pairs");
      }
      const double roll = campaign.AsDouble(item[0], "attitudes_deg");
      const double pitch = campaign.AsDouble(item[1], "attitudes_deg");
      if (roll < -180 || roll > 180 || pitch < -90 || pitch > 90) {
        throw UserError(campaign.Where(item) + ": '" + campaign.KeyPath("attitudes_deg") +
                        "' has roll " + Num(roll) + ", pitch " + Num(pitch) +
                        "; allowed roll [-180, 180], pitch [-90, 90]");
      }
      c->attitudes_deg.push_back({roll, pitch});
    }
  }
  const YAML::Node pitch_node =
      c->attitudes_deg.empty() ? campaign.Required("pitch_deg") : campaign.Optional("pitch_deg");
  c->pitch_deg = campaign.OptionalDoubleList("pitch_deg", {});
  for (double p : c->pitch_deg) {
    if (p < -90 || p > 90) {
      throw UserError(campaign.Where(pitch_node) + ": '" + campaign.KeyPath("pitch_deg") +
                      "' has " + Num(p) + "; allowed [-90, 90]");
    }
  }
  c->trials_per_pitch =
      static_cast<int>(ReadValue(campaign, "trials_per_pitch", 3, 1, false, 1000));
  c->pitch_error_sigma_deg =
      ReadValue(campaign, "pitch_error_sigma_deg", c->pitch_error_sigma_deg, 0, false, 10);
  c->roll_error_sigma_deg =
      ReadValue(campaign, "roll_error_sigma_deg", c->pitch_error_sigma_deg, 0, false, 10);
  ReadAttitudeOverrides(campaign, c);
  campaign.Finish();
}

// `calibration`: reference swings for rig.calibration (a reference object on the rig).
void ReadCalibration(YamlMap& root, CampaignSpec* c) {
  YamlMap calibration = Section(root, "calibration");
  if (root.Has("calibration")) {
    c->calibration_logs = static_cast<int>(ReadValue(calibration, "logs", 3, 1, false, 1000));
    c->reference_inertia_kg_m2 = ReadInertia(calibration, "reference_inertia", true, 0, true);
    c->reference_mass_kg = calibration.RequiredDouble("reference_mass_kg");
    c->reference_mass_kg = ReadValue(calibration, "reference_mass_kg", 0, 0, true, 1e6);
    c->calibration_amplitude_deg =
        ReadRange(calibration, "amplitude_deg", c->amplitude_deg, 0, true, 75);
  }
  calibration.Finish();
}

// A campaign (`aircraft`, `rig`, `campaign`, optional `calibration`), when any of them is given.
void ReadCampaignSections(YamlMap& root, const SpecGeometry& g, SimulateSpec* spec) {
  CampaignSpec& c = spec->campaign;
  const bool has_aircraft = root.Has("aircraft"), has_rig = root.Has("rig"),
             has_campaign = root.Has("campaign");
  spec->has_campaign = has_aircraft || has_rig || has_campaign;
  if (spec->has_campaign) {
    YamlMap aircraft = Section(root, "aircraft");
    if (!has_aircraft) root.Required("aircraft");
    ReadAircraft(aircraft, spec->file, &c.aircraft);
    YamlMap rig = Section(root, "rig");
    if (!has_rig) root.Required("rig");
    ReadRig(rig, &c);
    YamlMap campaign = Section(root, "campaign");
    if (!has_campaign) root.Required("campaign");
    ReadCampaignPlan(campaign, &c);

    if (!g.length || !g.separation) {
      throw UserError(spec->file +
                      ": missing required key 'geometry.filar_length_m' or "
                      "'geometry.filar_separation_m' (a campaign needs both)");
    }
    c.filar_length_m = *g.length;
    c.filar_separation_m = *g.separation;
    c.gravity_mps2 = g.gravity;
    c.true_filar_length_m = g.true_length.value_or(0.0);
    c.true_filar_separation_m = g.true_separation.value_or(0.0);
    ReadCalibration(root, &c);
    std::string why;
    if (!c.Check(&why)) throw UserError(spec->file + ": " + why);
  } else if (g.true_length || g.true_separation || root.Has("calibration")) {
    throw UserError(spec->file +
                    ": 'geometry.true_filar_*' and 'calibration' describe a "
                    "campaign's rig: they need the 'aircraft', 'rig' and 'campaign' sections");
  }
}

// `trace`: one simulated log (`bifilar simulate` without a campaign).
void ReadTraceSection(YamlMap trace, TraceRequest* request) {
  TraceRequest& t = *request;
  const double inf = INFINITY;
  t.inertia_kg_m2 = ReadOptionalValue(trace, "inertia_kg_m2", 0, true, 1e9);
  t.mass_kg = ReadOptionalValue(trace, "mass_kg", 0, true, 1e6);
  t.pitch_deg = ReadValue(trace, "pitch_deg", t.pitch_deg, -90, false, 90);
  const YAML::Node amp = trace.Optional("amplitude_deg");
  t.amplitude_deg = ReadValue(trace, "amplitude_deg", t.amplitude_deg, -85, false, 85);
  if (t.amplitude_deg == 0) {
    throw UserError(trace.Where(amp) +
                    ": 'trace.amplitude_deg' must not be 0; allowed "
                    "0 < |amplitude| <= 85");
  }
  t.drag_coeff_kg_m2 = ReadValue(trace, "drag_coeff_kg_m2", t.drag_coeff_kg_m2, 0, false, inf);
  t.viscous_coeff_kg_m2_per_s =
      ReadValue(trace, "viscous_coeff_kg_m2_per_s", t.viscous_coeff_kg_m2_per_s, 0, false, inf);
  t.imu_offset_m = ReadVector3(trace, "imu_offset_m", t.imu_offset_m);
  t.imu_mounting_rpy_deg = ReadVector3(trace, "imu_mounting_rpy_deg", t.imu_mounting_rpy_deg);
  trace.Finish();
}

SimulateSpec ParseSpec(YamlMap root) {
  SimulateSpec spec;
  spec.file = root.file();
  ReadSeed(root, &spec);
  ReadModelAndIntegrator(root, &spec);
  SpecGeometry g;
  ReadGeometry(Section(root, "geometry"), &g.length, &g.separation, &g.gravity, &g.true_length,
               &g.true_separation);
  ReadFormat(Section(root, "format"), &spec);
  ReadTimeline(Section(root, "timeline"), &spec.options.timeline);
  ReadSensor(Section(root, "sensor"), &spec.options.sensor, &spec.time_jitter_given);
  ReadSwing(Section(root, "swing"), &spec);
  ReadCampaignSections(root, g, &spec);

  spec.has_trace = root.Has("trace");
  TraceRequest& t = spec.trace;
  t.filar_length_m = g.length;
  t.filar_separation_m = g.separation;
  t.gravity_mps2 = g.gravity;
  ReadTraceSection(Section(root, "trace"), &t);
  root.Finish();
  std::string why;
  if (!spec.options.Check(&why)) throw UserError(spec.file + ": " + why);
  return spec;
}

nlohmann::json Vec(const Eigen::Vector3d& v, double scale = 1.0) {
  return nlohmann::json::array({v[0] * scale, v[1] * scale, v[2] * scale});
}

nlohmann::json Range(const UniformRange& r) { return nlohmann::json::array({r.min, r.max}); }

nlohmann::json OptionsJson(const SimulateSpec& spec) {
  const SimulationOptions& o = spec.options;
  const TimelineOptions& t = o.timeline;
  const SensorOptions& s = o.sensor;
  nlohmann::json j;
  j["model"] = ToString(o.model);
  j["integrator"] = ToString(o.integrator.method);
  j["integrator_rel_tol"] = o.integrator.rel_tol;
  j["integrator_abs_tol"] = o.integrator.abs_tol;
  j["sway_coupling_percent_at_60deg"] = 100.0 * o.sway_coupling_at_60deg;
  j["negative_amplitude_probability"] = o.negative_amplitude_probability;
  j["timeline"] = {{"rest_before_s", Range(t.rest_before_s)},
                   {"twist_s", Range(t.twist_s)},
                   {"hold_s", Range(t.hold_s)},
                   {"tremor_deg", t.tremor_deg},
                   {"tremor_hz", Range(t.tremor_hz)},
                   {"release_rate_sigma_deg_per_s", t.release_rate_sigma_deg_per_s},
                   {"free_s", Range(t.free_s)},
                   {"stop_probability", t.stop_probability},
                   {"stop_time_constant_s", t.stop_time_constant_s},
                   {"rest_after_s", Range(t.rest_after_s)}};
  j["sensor"] = {{"sample_rate_hz", s.sample_rate_hz},
                 {"time_jitter_sigma_s", s.time_jitter_sigma_s},
                 {"drop_fraction", s.drop_fraction},
                 {"drop_burst_probability", s.drop_burst_probability},
                 {"drop_burst_max_samples", s.drop_burst_max_samples},
                 {"start_time_s", Range(s.start_time_s)},
                 {"gyro_noise_sigma_deg_per_s", s.gyro_noise_sigma_deg_per_s},
                 {"gyro_bias_sigma_deg_per_s", s.gyro_bias_sigma_deg_per_s},
                 {"gyro_scale_error_sigma", s.gyro_scale_error_sigma},
                 {"accelerometer", s.accelerometer},
                 {"accel_noise_sigma_mps2", s.accel_noise_sigma_mps2},
                 {"accel_bias_sigma_mps2", s.accel_bias_sigma_mps2},
                 {"rocking_max_deg", s.rocking_max_deg},
                 {"rocking_frequency_hz", s.rocking_frequency_hz},
                 {"rocking_decay_s", s.rocking_decay_s}};
  // Realism settings are recorded when they are on (absent = off), so that a spec without them
  // gives the same truth.json bytes as before they existed.
  const SensorOptions off;
  if (s.sample_steps != off.sample_steps) {
    j["sensor"]["sample_steps"] = ToString(s.sample_steps);
    j["sensor"]["step_median_s"] = 1.0 / s.sample_rate_hz;
    j["sensor"]["step_log_sigma"] = s.step_log_sigma;
    j["sensor"]["step_range_s"] = Range(s.step_range_s);
  }
  if (s.gyro_noise_ar1_phi != off.gyro_noise_ar1_phi) {
    j["sensor"]["gyro_noise_ar1_phi"] = s.gyro_noise_ar1_phi;
  }
  if (s.gyro_bias_walk_deg_per_s_per_sqrt_s != off.gyro_bias_walk_deg_per_s_per_sqrt_s) {
    j["sensor"]["gyro_bias_walk_deg_per_s_per_sqrt_s"] = s.gyro_bias_walk_deg_per_s_per_sqrt_s;
  }
  if (s.spike_count != off.spike_count) {
    j["sensor"]["spike_count"] = s.spike_count;
    j["sensor"]["spike_rate_rad_per_s"] = s.spike_rate_rad_per_s;
  }
  if (s.accelerometer && s.accel_gravity_removed) {
    j["sensor"]["accelerometer"] = "gravity_removed";
    j["sensor"]["gravity_removal_error_deg"] = Range(s.gravity_removal_error_deg);
  }
  if (o.softening_at_30deg > 0) {
    j["softening_percent_at_30deg"] = 100.0 * o.softening_at_30deg;
    j["softening_exponent"] = o.softening_exponent;
    j["softening_k_per_rad_p"] = SofteningCoefficient(o.softening_at_30deg, o.softening_exponent);
    j["softening_harmonic_constant"] = SofteningHarmonicConstant(o.softening_exponent);
  }
  const ImuFormat& f = spec.format;
  j["format"] = {{"time_column", f.time_column},
                 {"time_unit", ToString(f.time_unit)},
                 {"gyro_columns", f.gyro_columns},
                 {"gyro_unit", ToString(f.gyro_unit)},
                 {"accel_columns", f.has_accel() && s.accelerometer
                                       ? nlohmann::json(f.accel_columns)
                                       : nlohmann::json::array()},
                 {"accel_unit", ToString(f.accel_unit)},
                 {"delimiter", std::string(1, f.delimiter)},
                 {"significant_digits", spec.write.significant_digits},
                 {"gzip", spec.gzip}};
  if (spec.footer) j["format"]["footer"] = true;
  return j;
}

nlohmann::json TraceJson(const CampaignTrace& ct, const SimulateSpec& spec) {
  const TraceTruth& t = ct.trace.truth;
  const TraceSetup& s = ct.setup;
  const SensorOptions& so = spec.options.sensor;
  nlohmann::json j;
  j["file"] = ct.relative_path;
  j["kind"] = ct.is_calibration ? "calibration" : ct.is_tare ? "tare" : "aircraft";
  if (ct.is_calibration) j["inertia_reference_kg_m2"] = ct.inertia_reference_kg_m2;
  j["trial"] = ct.trial;
  j["nominal_pitch_deg"] = ct.nominal_pitch_deg;
  j["true_pitch_deg"] = ct.true_pitch_deg;
  if (!spec.campaign.attitudes_deg.empty()) {
    j["nominal_roll_deg"] = ct.nominal_roll_deg;
    j["true_roll_deg"] = ct.true_roll_deg;
    const double p = ct.true_pitch_deg * kRadPerDeg, r = ct.true_roll_deg * kRadPerDeg;
    j["swing_axis_in_body"] = Vec(Eigen::Vector3d(-std::sin(p), std::sin(r) * std::cos(p),
                                                  std::cos(r) * std::cos(p)));
  }
  j["mass_kg"] = s.geometry.mass_kg;
  j["inertia_total_kg_m2"] = s.params.inertia_kg_m2;
  j["inertia_aircraft_kg_m2"] = ct.inertia_aircraft_kg_m2;
  j["inertia_rig_kg_m2"] = ct.inertia_rig_kg_m2;
  j["drag_coeff_kg_m2"] = s.params.drag_coeff_kg_m2;
  j["viscous_coeff_kg_m2_per_s"] = s.params.viscous_coeff_kg_m2_per_s;
  j["small_angle_period_s"] = SmallAnglePeriod(s.geometry, s.params.inertia_kg_m2);
  j["amplitude_deg"] = t.amplitude_rad / kRadPerDeg;
  j["release_rate_deg_per_s"] = t.release_rate_rad_per_s / kRadPerDeg;
  j["amplitude_at_end_deg"] = t.amplitude_at_stop_rad / kRadPerDeg;
  j["start_time_s"] = t.start_time_s;
  j["t_twist_s"] = t.t_twist_s;
  j["t_release_s"] = t.t_release_s;
  j["stopped_by_hand"] = t.stopped;
  j["t_stop_s"] = t.stopped ? nlohmann::json(t.t_stop_s) : nlohmann::json(nullptr);
  j["t_free_end_s"] = t.t_stop_s;
  j["t_end_s"] = t.t_end_s;
  j["samples"] = ct.trace.imu.size();
  j["samples_nominal"] = t.samples_nominal;
  j["samples_dropped"] = t.samples_dropped;
  j["free_samples"] = t.free_samples;
  j["swing_axis_in_imu"] = Vec(t.swing_axis_in_imu);
  j["gyro_bias_deg_per_s"] = Vec(t.gyro_bias_rad_per_s, 1.0 / kRadPerDeg);
  j["gyro_scale_error"] = Vec(t.gyro_scale_error);
  j["gyro_noise_sigma_deg_per_s"] = so.gyro_noise_sigma_deg_per_s;
  if (so.accelerometer) {
    j["accel_bias_mps2"] = Vec(t.accel_bias_mps2);
    j["accel_noise_sigma_mps2"] = so.accel_noise_sigma_mps2;
  }
  j["rocking_amplitude_deg"] = t.rocking_amplitude_rad / kRadPerDeg;
  j["rocking_frequency_hz"] = t.rocking_frequency_hz;
  j["rocking_axis_in_body"] = Vec(t.rocking_axis_in_body);
  // Realism, recorded when on (see OptionsJson).
  if (so.gyro_bias_walk_deg_per_s_per_sqrt_s > 0) {
    j["gyro_bias_end_deg_per_s"] = Vec(t.gyro_bias_end_rad_per_s, 1.0 / kRadPerDeg);
  }
  if (so.gyro_noise_ar1_phi > 0) j["gyro_noise_ar1_phi"] = so.gyro_noise_ar1_phi;
  if (so.accelerometer && so.accel_gravity_removed) {
    j["accelerometer"] = "gravity_removed";
    j["gravity_removal_error_deg"] = t.gravity_removal_error_rad / kRadPerDeg;
  }
  if (!t.spikes.empty()) {
    nlohmann::json spikes = nlohmann::json::array();
    for (const auto& spike : t.spikes) {
      spikes.push_back({{"sample", spike.sample},
                        {"t_s", spike.t_s},
                        {"axis", std::string(1, "xyz"[spike.axis])},
                        {"column", spec.format.gyro_columns[spike.axis]},
                        {"rate_rad_per_s", spike.rate_rad_per_s}});
    }
    j["spikes"] = spikes;
  }
  if (t.softening_k > 0) {
    // What a fit of the ideal model would find at the release amplitude (harmonic balance); the
    // true inertia stays inertia_total_kg_m2 (the small-amplitude limit).
    const double p = spec.options.softening_exponent;
    j["softening_k_per_rad_p"] = t.softening_k;
    j["apparent_inertia_excess_at_release"] = ApparentInertiaExcess(t.softening_k, p, t.amplitude_rad);
    j["apparent_inertia_at_release_kg_m2"] =
        s.params.inertia_kg_m2 * (1.0 + ApparentInertiaExcess(t.softening_k, p, t.amplitude_rad));
  }
  if (spec.footer) j["footer_rows"] = kFooterRows;
  return j;
}

// The footer of a log that ends like the Crazyflie logs: a blank line, then summary rows whose
// time column is numeric again (smaller than the last time) and whose last column is text.
std::string Footer(const SimulatedTrace& trace, const ImuFormat& format, const std::string& eol) {
  const char d = format.delimiter;
  const int columns = format.has_accel() ? 7 : 4;
  const double time_scale = 1.0 / ToSi(format.time_unit);
  auto row = [&](const std::string& time, const std::string& middle, const std::string& text) {
    std::string r = time;
    for (int c = 1; c < columns - 1; ++c) (r += d) += middle;
    (r += d) += text;
    return r + eol;
  };
  char release[64];
  std::snprintf(release, sizeof(release), "%.6g",
                (trace.truth.t_release_s - trace.truth.start_time_s) * time_scale);
  return eol + row("", "", "Rollout Completed: swing logged") + row(release, "0", "Flip Data") +
         row("0", "0", "Impact Data");
}

// Every log simulate writes carries the mark of a simulated log with its seed
// (pipeline/logs/simulated_log.h): the CSV's first line, a ULog information message, or a
// DataFlash MSG message.
void WriteTrace(const std::string& path, const SimulatedTrace& trace, const SimulateSpec& spec) {
  const std::string origin = SimulatedLogOrigin(spec.seed);
  if (NamedLikeDataflash(path)) {  // pipeline/logs/dataflash_writer.h
    ImuData imu = trace.imu;
    if (!spec.options.sensor.accelerometer) imu.accel_in_imu.clear();
    return WriteImuDataflash(path, imu, origin);
  }
  if (spec.ulog || path.find(".ulg") != std::string::npos) {  // pipeline/logs/ulog_writer.h
    ImuData imu = trace.imu;
    if (!spec.options.sensor.accelerometer) imu.accel_in_imu.clear();
    return WriteImuUlog(path, imu, origin);
  }
  ImuFormat format = spec.format;
  if (!spec.options.sensor.accelerometer) format.accel_columns = {"", "", ""};
  std::string text = SimulatedCsvMarkerLine(origin) + spec.write.line_end +
                     FormatImuLog(trace.imu, format, spec.write);
  if (spec.footer) text += Footer(trace, format, spec.write.line_end);
  const bool gzip = path.size() > 3 && path.compare(path.size() - 3, 3, ".gz") == 0;
  WriteFileAtomically(path, gzip ? GzipCompress(text) : text);
}

}  // namespace

double DefaultTimeJitterSigmaS(double sample_rate_hz) {
  const double fallback = SensorOptions().time_jitter_sigma_s;  // 1 ms
  return 0.1 / sample_rate_hz < fallback ? 0.1 / sample_rate_hz : fallback;
}

void ApplySimulateOverrides(const SimulateOverrides& o, bool single_trace,
                            SimulateSpec* spec) {
  if (o.seed) spec->seed = *o.seed;
  if (o.no_accel) spec->options.sensor.accelerometer = false;
  if (o.duration_s) spec->options.timeline.free_s = {*o.duration_s, *o.duration_s};
  if (!single_trace) {
    if (o.length_m) spec->campaign.filar_length_m = *o.length_m;
    if (o.separation_m) spec->campaign.filar_separation_m = *o.separation_m;
    if (o.gravity_mps2) spec->campaign.gravity_mps2 = *o.gravity_mps2;
    return;
  }
  TraceRequest& t = spec->trace;
  if (o.inertia_kg_m2) t.inertia_kg_m2 = *o.inertia_kg_m2;
  if (o.mass_kg) t.mass_kg = *o.mass_kg;
  if (o.length_m) t.filar_length_m = *o.length_m;
  if (o.separation_m) t.filar_separation_m = *o.separation_m;
  if (o.gravity_mps2) t.gravity_mps2 = *o.gravity_mps2;
  if (o.amplitude_deg) t.amplitude_deg = *o.amplitude_deg;
  if (o.pitch_deg) t.pitch_deg = *o.pitch_deg;
}

SimulateCommandResult RunSimulate(const SimulateCommandOptions& a) {
  const SimulateOverrides& o = a.o;
  const SimulateSettingNames& n = a.names;
  auto positive = [](const std::optional<double>& v, const std::string& name) {
    if (v && !(*v > 0)) throw UserError(CheckMessage(name, *v, "> 0"));
  };
  positive(o.duration_s, n.duration);
  positive(a.sample_rate, n.sample_rate);
  positive(o.inertia_kg_m2, n.inertia);
  positive(o.mass_kg, n.mass);
  positive(o.length_m, n.length);
  positive(o.separation_m, n.separation);
  positive(o.gravity_mps2, n.gravity);
  if (!a.trace_csv.empty() && !a.out_dir.empty()) {
    throw UserError("give either " + n.out + " or " + n.trace + ", not both");
  }
  SimulateSpec spec = a.spec_file.empty() ? ParseSimulateSpec("{}", "<defaults>")
                                          : ReadSimulateSpec(a.spec_file);
  if (a.spec_file.empty()) spec.file.clear();
  if (!a.model.empty() && !ParsePendulumModel(a.model, &spec.options.model)) {
    throw UserError(n.model + ": unknown model '" + a.model + "'; allowed " +
                    PendulumModelAllowedValues());
  }
  if (a.sample_rate) SetSampleRateFromFlag(&spec, *a.sample_rate, n.sample_rate);
  if (!a.trace_csv.empty()) {
    if (spec.has_campaign) {
      throw UserError(a.spec_file + ": has campaign sections (aircraft, rig, campaign); simulate "
                      "it with " + n.out + ", or use a spec without them with " + n.trace);
    }
    ApplySimulateOverrides(o, true, &spec);
    const TraceRequest& t = spec.trace;
    for (const auto& [value, name] : {std::make_pair(&t.inertia_kg_m2, &n.inertia),
                                      std::make_pair(&t.mass_kg, &n.mass),
                                      std::make_pair(&t.filar_length_m, &n.length),
                                      std::make_pair(&t.filar_separation_m, &n.separation)}) {
      if (!*value) throw UserError("give " + *name + " (or its spec key) for a single trace");
    }
    std::string why;
    if (!spec.options.Check(&why)) throw UserError(why);
    return {RunSimulateTrace(spec, a.trace_csv, a.truth_json, a.force), a.trace_csv, spec.format};
  }
  if (a.out_dir.empty()) {
    throw UserError("nothing to do: give SPEC.yaml and " + n.out + " (campaign) or " + n.trace +
                    " (one trace); see bifilar simulate --help");
  }
  if (a.spec_file.empty()) throw UserError(n.out + " needs a campaign spec file SPEC.yaml");
  if (o.inertia_kg_m2 || o.mass_kg || o.amplitude_deg || o.pitch_deg || !a.truth_json.empty()) {
    throw UserError(n.inertia + ", " + n.mass + ", " + n.amplitude + ", " + n.pitch + " and " +
                    n.truth + " apply to " + n.trace + " only; a campaign takes them from the spec");
  }
  ApplySimulateOverrides(o, false, &spec);
  std::string why;
  if (!spec.campaign.Check(&why) || !spec.options.Check(&why)) throw UserError(why);
  return {RunSimulateCampaign(spec, a.out_dir, a.force), a.out_dir, spec.format};
}

void SetSampleRateFromFlag(SimulateSpec* spec, double rate_hz, const std::string& flag) {
  if (!(rate_hz > 0 && rate_hz <= 100000)) {
    throw UserError(CheckMessage(flag, rate_hz, "in (0, 100000]"));
  }
  SensorOptions& s = spec->options.sensor;
  const std::string from = spec->file.empty() ? std::string("the spec") : spec->file;
  if (!spec->time_jitter_given) {
    s.time_jitter_sigma_s = DefaultTimeJitterSigmaS(rate_hz);
  } else if (s.time_jitter_sigma_s > 1.0 / rate_hz) {
    throw UserError(flag + " " + Num(rate_hz) + ": 'sensor.time_jitter_sigma_s' = " +
                    Num(s.time_jitter_sigma_s) + " s in " + from +
                    " is more than one sample period at that rate (" + Num(1.0 / rate_hz) +
                    " s); lower it in the spec (or remove it: the default follows the rate), or "
                    "lower " + flag);
  }
  if (s.rocking_frequency_hz > rate_hz / 4) {
    throw UserError(flag + " " + Num(rate_hz) + ": 'sensor.rocking_frequency_hz' = " +
                    Num(s.rocking_frequency_hz) + " Hz in " + from +
                    " is above a quarter of that rate; raise " + flag + " to at least " +
                    Num(4 * s.rocking_frequency_hz) + " or lower the rocking frequency");
  }
  s.sample_rate_hz = rate_hz;
}

void CheckOutputFileTarget(const std::string& path, const std::string& what) {
  namespace fs = std::filesystem;
  std::error_code ec;
  const fs::file_status status = fs::status(path, ec);  // follows symlinks
  if (fs::exists(status)) {
    if (fs::is_directory(status)) {
      throw UserError(what + " " + path + ": is a folder, expected a file name");
    }
    if (!fs::is_regular_file(status)) {
      throw UserError(what + " " + path +
                      ": exists and is not a regular file (a device, FIFO or socket); "
                      "simulate only writes regular files: choose another path");
    }
  }
  try {
    CheckFileTarget(path);  // a symbolic link, a name too long (base/atomic_file.h)
  } catch (const UserError& e) {
    throw UserError(what + " " + e.what());
  }
  if (fs::exists(status)) return;
  // A missing file: its nearest existing ancestor must be a folder.
  for (fs::path parent = fs::path(path).parent_path(); !parent.empty();
       parent = parent.parent_path()) {
    const fs::file_status ps = fs::status(parent, ec);
    if (fs::exists(ps)) {
      if (!fs::is_directory(ps)) {
        throw UserError(what + " " + path + ": " + parent.string() +
                        " exists and is not a folder");
      }
      break;
    }
    if (parent == parent.parent_path()) break;
  }
}

SimulateSpec ReadSimulateSpec(const std::string& file) {
  return ParseSpec(YamlMap::LoadFile(file));
}

SimulateSpec ParseSimulateSpec(const std::string& yaml_text, const std::string& name) {
  return ParseSpec(YamlMap::LoadText(yaml_text, name));
}

std::string SimulateRunSummary::BriefReport() const {
  std::ostringstream os;
  os << files_written << " log" << (files_written == 1 ? "" : "s") << ", " << samples_written
     << " samples (" << samples_dropped << " dropped), truth in " << truth_path;
  return os.str();
}

std::string CampaignTruthJson(const SimulateSpec& spec, const std::vector<CampaignTrace>& traces) {
  const CampaignSpec& c = spec.campaign;
  nlohmann::json j;
  j["generator"] = std::string("bifilar simulate ") + ProgramVersion();
  j["seed"] = spec.seed;
  j["spec"] = spec.file;
  j["geometry"] = {{"filar_length_m", c.filar_length_m},
                   {"filar_separation_m", c.filar_separation_m},
                   {"gravity_mps2", c.gravity_mps2}};
  // A mis-measured rig: the logs follow the true geometry, a user measured the one above.
  if (c.true_filar_length_m > 0 || c.true_filar_separation_m > 0) {
    j["geometry"]["true_filar_length_m"] = c.TrueLengthM();
    j["geometry"]["true_filar_separation_m"] = c.TrueSeparationM();
    j["geometry"]["true_d2_over_l_factor"] =
        (c.TrueSeparationM() * c.TrueSeparationM() / c.TrueLengthM()) /
        (c.filar_separation_m * c.filar_separation_m / c.filar_length_m);
  }
  if (c.calibration_logs > 0) {
    j["calibration"] = {{"logs", c.calibration_logs},
                        {"reference_inertia_kg_m2", c.reference_inertia_kg_m2},
                        {"reference_mass_kg", c.reference_mass_kg},
                        {"rig_pitch_deg", c.tare_pitch_deg},
                        {"amplitude_deg", Range(c.calibration_amplitude_deg)}};
  }
  const double tau = c.aircraft.PrincipalInclinationRad();
  j["aircraft"] = {{"mass_kg", c.aircraft.mass_kg},
                   {"ix_kg_m2", c.aircraft.ix_kg_m2},
                   {"iz_kg_m2", c.aircraft.iz_kg_m2},
                   {"ixz_kg_m2", c.aircraft.ixz_kg_m2},
                   {"tau_deg", tau / kRadPerDeg},
                   {"ix_slug_ft2", c.aircraft.ix_kg_m2 / kKgM2PerSlugFt2},
                   {"iz_slug_ft2", c.aircraft.iz_kg_m2 / kKgM2PerSlugFt2},
                   {"ixz_slug_ft2", c.aircraft.ixz_kg_m2 / kKgM2PerSlugFt2}};
  // Principal moments: I(theta) at theta = tau (z principal) and tau + 90 deg (x principal).
  j["aircraft"]["izp_kg_m2"] = c.aircraft.InertiaAtPitch(tau);
  j["aircraft"]["ixp_kg_m2"] = c.aircraft.InertiaAtPitch(tau + kPi / 2);
  nlohmann::json rig = {{"mass_kg", c.rig.mass_kg},
                        {"imu_mass_kg", c.rig.imu_mass_kg},
                        {"imu_offset_m", Vec(c.rig.imu_offset_in_body_m)},
                        {"tare_logs", c.tare_logs},
                        {"tare_pitch_deg", c.tare_pitch_deg},
                        {"tare_damping_scale", c.tare_damping_scale}};
  if (c.rig.inertia_by_pitch_kg_m2.empty()) {
    rig["inertia_kg_m2"] = c.rig.inertia_kg_m2;
  } else {
    nlohmann::json table = nlohmann::json::object();
    for (const auto& e : c.rig.inertia_by_pitch_kg_m2) table[FormatPitchDeg(e.first)] = e.second;
    rig["inertia_by_pitch_kg_m2"] = table;
  }
  nlohmann::json mounting = nlohmann::json::array();
  for (int r = 0; r < 3; ++r) {
    mounting.push_back({c.rig.body_from_imu(r, 0), c.rig.body_from_imu(r, 1), c.rig.body_from_imu(r, 2)});
  }
  rig["body_from_imu"] = mounting;
  j["rig"] = rig;
  if (c.aircraft.HasTensor()) {
    // The whole tensor (docs/physics.md §3.5; products positive, the tensor holds -Ixy ...).
    const Eigen::Matrix3d tensor = c.aircraft.Tensor();
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(tensor);
    nlohmann::json axes = nlohmann::json::array();
    for (int k = 0; k < 3; ++k) {
      Eigen::Vector3d axis = eig.eigenvectors().col(k);
      int largest = 0;
      axis.cwiseAbs().maxCoeff(&largest);
      if (axis(largest) < 0) axis = -axis;
      axes.push_back(Vec(axis));
    }
    j["aircraft"]["iy_kg_m2"] = c.aircraft.iy_kg_m2;
    j["aircraft"]["ixy_kg_m2"] = c.aircraft.ixy_kg_m2;
    j["aircraft"]["iyz_kg_m2"] = c.aircraft.iyz_kg_m2;
    j["aircraft"]["tensor"] = {
        {"Ixx_kg_m2", c.aircraft.ix_kg_m2}, {"Iyy_kg_m2", c.aircraft.iy_kg_m2},
        {"Izz_kg_m2", c.aircraft.iz_kg_m2}, {"Ixy_kg_m2", c.aircraft.ixy_kg_m2},
        {"Ixz_kg_m2", c.aircraft.ixz_kg_m2}, {"Iyz_kg_m2", c.aircraft.iyz_kg_m2},
        {"tensor_kg_m2", {Vec(tensor.row(0).transpose()), Vec(tensor.row(1).transpose()),
                          Vec(tensor.row(2).transpose())}},
        {"principal_moments_kg_m2", Vec(eig.eigenvalues())},
        {"principal_axes", axes}};
  }
  j["campaign"] = {{"pitch_deg", c.pitch_deg},
                   {"trials_per_pitch", c.trials_per_pitch},
                   {"pitch_error_sigma_deg", c.pitch_error_sigma_deg},
                   {"amplitude_deg", Range(c.amplitude_deg)},
                   {"drag_coeff_kg_m2", Range(c.drag_coeff_kg_m2)},
                   {"viscous_coeff_kg_m2_per_s", Range(c.viscous_coeff_kg_m2_per_s)}};
  if (!c.attitudes_deg.empty()) {
    nlohmann::json list = nlohmann::json::array();
    for (const auto& a : c.attitudes_deg) list.push_back({a[0], a[1]});
    j["campaign"]["attitudes_deg"] = list;
    j["campaign"]["roll_error_sigma_deg"] = c.roll_error_sigma_deg;
  }
  j["options"] = OptionsJson(spec);
  nlohmann::json list = nlohmann::json::array();
  for (const auto& ct : traces) list.push_back(TraceJson(ct, spec));
  j["traces"] = list;
  return j.dump(2, ' ', false, nlohmann::json::error_handler_t::replace) + "\n";
}

SimulateRunSummary RunSimulateCampaign(const SimulateSpec& spec, const std::string& out_dir,
                                       bool force) {
  namespace fs = std::filesystem;
  if (!spec.has_campaign) {
    throw UserError((spec.file.empty() ? std::string("spec") : spec.file) +
                    ": a campaign needs the 'aircraft', 'rig' and 'campaign' sections");
  }
  if (out_dir.empty()) throw UserError("--out: empty output folder name");
  std::error_code ec;
  if (fs::exists(out_dir, ec) && !fs::is_directory(out_dir, ec)) {
    throw UserError(out_dir + ": output path exists and is not a folder");
  }
  CheckOutputFileTarget((fs::path(out_dir) / "truth.json").string(), "--out");  // fail early
  RefuseToReplace((fs::path(out_dir) / "truth.json").string(), "simulate --out", force);
  std::vector<CampaignTrace> traces;
  std::string why;
  if (!SimulateCampaign(spec.campaign, spec.options, spec.seed, &traces, &why)) {
    throw UserError((spec.file.empty() ? std::string("simulate") : spec.file) + ": " + why);
  }
  if (spec.ulog) {
    for (auto& ct : traces) ct.relative_path.replace(ct.relative_path.size() - 4, 4, ".ulg");
  }
  if (spec.gzip) {
    for (auto& ct : traces) ct.relative_path += ".gz";
  }
  const std::string truth = CampaignTruthJson(spec, traces);
  // Every target is checked before the first file is written: a regular file or nothing, and
  // nothing at all without --force (issue 23: the logs of a real campaign in OUT/pitch_0/).
  std::vector<std::string> targets;
  for (const auto& ct : traces) targets.push_back((fs::path(out_dir) / ct.relative_path).string());
  targets.push_back((fs::path(out_dir) / "truth.json").string());
  for (const std::string& target : targets) CheckOutputFileTarget(target, "--out");
  if (!force) {
    int existing = 0;
    std::string first;
    for (const std::string& target : targets) {
      if (fs::exists(fs::symlink_status(target, ec))) {
        if (existing++ == 0) first = target;
      }
    }
    if (existing > 0) {
      throw UserError("simulate --out: " + first + " exists" +
                      (existing > 1 ? " (and " + std::to_string(existing - 1) +
                                          " more of the files this campaign writes)"
                                    : std::string()) +
                      "; simulate writes over no file without --force: choose another "
                      "folder, or add --force to overwrite them");
    }
  }
  SimulateRunSummary summary;
  for (const auto& ct : traces) {
    WriteTrace((fs::path(out_dir) / ct.relative_path).string(), ct.trace, spec);
    ++summary.files_written;
    summary.samples_written += static_cast<long>(ct.trace.imu.size());
    summary.samples_dropped += ct.trace.truth.samples_dropped;
  }
  summary.truth_path = (fs::path(out_dir) / "truth.json").string();
  WriteFileAtomically(summary.truth_path, truth);
  return summary;
}

SimulateRunSummary RunSimulateTrace(const SimulateSpec& spec, const std::string& csv_path,
                                    const std::string& truth_path_in, bool force) {
  const TraceRequest& r = spec.trace;
  auto need = [](const std::optional<double>& v, const char* name, const char* flag) {
    if (!v) {
      throw UserError(std::string("missing ") + name + ": give " + flag +
                      " (or the spec key) for a single trace");
    }
    return *v;
  };
  const double inertia = need(r.inertia_kg_m2, "the whole suspended inertia", "--inertia-kg-m2");
  const double mass = need(r.mass_kg, "the whole suspended mass", "--mass-kg");
  const double length = need(r.filar_length_m, "the filar length L", "-L/--filar-length-m");
  const double separation = need(r.filar_separation_m, "the filar separation D", "-D/--filar-separation-m");
  if (csv_path.empty()) throw UserError("--trace: empty output file name");
  std::string truth_path = truth_path_in;
  if (truth_path.empty()) {
    truth_path = csv_path;
    const std::string ext = ".csv";
    if (truth_path.size() > ext.size() &&
        truth_path.compare(truth_path.size() - ext.size(), ext.size(), ext) == 0) {
      truth_path.resize(truth_path.size() - ext.size());
    }
    truth_path += ".truth.json";
  }
  {
    namespace fs = std::filesystem;
    CheckOutputFileTarget(csv_path, "--trace");
    CheckOutputFileTarget(truth_path, "--truth");
    RefuseToReplace(csv_path, "simulate --trace", force);
    RefuseToReplace(truth_path, "simulate --truth", force);
    // The same file under two spellings: compare normalised absolute paths (symlinks resolved
    // where they exist), then, when both exist, the files themselves (hard links).
    std::error_code ec;
    auto normal = [&ec](const std::string& p) {
      return fs::weakly_canonical(fs::absolute(p, ec), ec).lexically_normal();
    };
    const bool same = normal(csv_path) == normal(truth_path) ||
                      (fs::exists(csv_path, ec) && fs::exists(truth_path, ec) &&
                       fs::equivalent(csv_path, truth_path, ec));
    if (same) {
      throw UserError("--truth " + truth_path + " and --trace " + csv_path +
                      " are the same file; give the truth JSON another name (default: the CSV "
                      "name with .truth.json)");
    }
  }
  CampaignTrace ct;
  ct.relative_path = std::filesystem::path(csv_path).filename().string();
  ct.nominal_pitch_deg = ct.true_pitch_deg = r.pitch_deg;
  ct.trial = 1;
  TraceSetup& s = ct.setup;
  s.geometry.filar_length_m = length;
  s.geometry.filar_separation_m = separation;
  s.geometry.mass_kg = mass;
  s.geometry.gravity_mps2 = r.gravity_mps2;
  s.params.inertia_kg_m2 = inertia;
  s.params.drag_coeff_kg_m2 = r.drag_coeff_kg_m2;
  s.params.viscous_coeff_kg_m2_per_s = r.viscous_coeff_kg_m2_per_s;
  s.pitch_rad = r.pitch_deg * kRadPerDeg;
  s.amplitude_rad = r.amplitude_deg * kRadPerDeg;
  s.imu_offset_in_body_m = r.imu_offset_m;
  s.body_from_imu = MountingFromRollPitchYawDeg(r.imu_mounting_rpy_deg[0], r.imu_mounting_rpy_deg[1],
                                                r.imu_mounting_rpy_deg[2]);
  ct.inertia_aircraft_kg_m2 = 0.0;
  ct.inertia_rig_kg_m2 = 0.0;
  std::string why;
  if (!SimulateTrace(s, spec.options, spec.seed, &ct.trace, &why)) {
    throw UserError("simulate: " + why);
  }
  nlohmann::json j;
  j["generator"] = std::string("bifilar simulate ") + ProgramVersion();
  j["seed"] = spec.seed;
  j["spec"] = spec.file;
  j["geometry"] = {{"filar_length_m", length},
                   {"filar_separation_m", separation},
                   {"gravity_mps2", r.gravity_mps2}};
  j["imu_offset_m"] = Vec(r.imu_offset_m);
  j["imu_mounting_rpy_deg"] = Vec(r.imu_mounting_rpy_deg);
  j["options"] = OptionsJson(spec);
  nlohmann::json trace = TraceJson(ct, spec);
  trace.erase("inertia_aircraft_kg_m2");
  trace.erase("inertia_rig_kg_m2");
  trace.erase("kind");
  trace["file"] = csv_path;
  j["traces"] = nlohmann::json::array({trace});
  WriteTrace(csv_path, ct.trace, spec);
  WriteFileAtomically(truth_path, j.dump(2, ' ', false, nlohmann::json::error_handler_t::replace) + "\n");
  SimulateRunSummary summary;
  summary.files_written = 1;
  summary.samples_written = static_cast<long>(ct.trace.imu.size());
  summary.samples_dropped = ct.trace.truth.samples_dropped;
  summary.truth_path = truth_path;
  return summary;
}

}  // namespace bifilar

// `bifilar simulate`'s YAML spec reader: the strict sections (seed, model, geometry, format,
// timeline, sensor, swing, aircraft, rig, campaign, calibration, trace), each value checked against
// its range with the key, line and column in the message. The run is simulate_run.cc, the truth
// JSON simulate_truth.cc.
#include "pipeline/commands/simulate_spec.h"

#include <cctype>
#include <cmath>
#include <limits>

#include "base/option_check.h"
#include "base/text_format.h"
#include "base/units.h"
#include "base/user_error.h"
#include "pendulum/model.h"
#include "pipeline/config/yaml_reader.h"

namespace bifilar {
namespace {
// root.Child(key), safe when the section is absent (yaml-cpp's const operator[] returns an
// invalid "zombie" node for a missing key, on which IsMap() throws).
YamlMap Section(YamlMap& root, const std::string& key) {
  if (root.Has(key)) return root.Child(key);
  root.Optional(key);
  return YamlMap(YAML::Node(YAML::NodeType::Null), root.file(), root.KeyPath(key));
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
Unit ReadUnit(YamlMap& map, const std::string& key, Unit fallback, Parse parse,
              const std::string& allowed) {
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
  f.time_unit = ReadUnit(
      map, "time_unit", f.time_unit,
      [](const std::string& n, TimeUnit* u) { return ParseTimeUnit(n, u); },
      TimeUnitAllowedValues());
  f.gyro_columns = ReadColumns(map, "gyro_columns", f.gyro_columns);
  f.gyro_unit = ReadUnit(
      map, "gyro_unit", f.gyro_unit,
      [](const std::string& n, RateUnit* u) { return ParseRateUnit(n, u); },
      RateUnitAllowedValues());
  f.accel_columns = ReadColumns(map, "accel_columns", f.accel_columns);
  f.accel_unit = ReadUnit(
      map, "accel_unit", f.accel_unit,
      [](const std::string& n, AccelUnit* u) { return ParseAccelUnit(n, u); },
      AccelUnitAllowedValues());
  const YAML::Node delim = map.Optional("delimiter");
  if (delim.IsDefined() && !delim.IsNull()) {
    const std::string d = map.AsString(delim, "delimiter");
    if (d.size() != 1 || d == "\"" || d == "\n" || d == "\r" ||
        std::isalnum(static_cast<unsigned char>(d[0])) || d == "." || d == "-" || d == "+") {
      throw UserError(map.Where(delim) +
                      ": 'format.delimiter' must be one character such as "
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
      throw UserError(map.Where(jitter) + ": '" + map.KeyPath("time_jitter_sigma_s") +
                      "' = " + Fmt("%g", value) + " s is more than one sample period (1/" +
                      map.KeyPath("sample_rate_hz") + " = " + Fmt("%g", 1.0 / s->sample_rate_hz) +
                      " s); lower it or the sample rate");
    }
  }
  s->time_jitter_sigma_s =
      ReadValue(map, "time_jitter_sigma_s", DefaultTimeJitterSigmaS(s->sample_rate_hz), 0, false,
                1.0 / s->sample_rate_hz);
  s->drop_fraction = ReadValue(map, "drop_fraction", s->drop_fraction, 0, false, 0.5);
  s->drop_burst_probability =
      ReadValue(map, "drop_burst_probability", s->drop_burst_probability, 0, false, 1);
  s->drop_burst_max_samples = static_cast<int>(
      ReadValue(map, "drop_burst_max_samples", s->drop_burst_max_samples, 2, false, 100000));
  s->start_time_s = ReadRange(map, "start_time_s", s->start_time_s, -1e9, false, 1e9);
  s->gyro_noise_sigma_deg_per_s =
      ReadValue(map, "gyro_noise_sigma_deg_per_s", s->gyro_noise_sigma_deg_per_s, 0, false, 100);
  s->gyro_noise_ar1_phi =
      ReadValue(map, "gyro_noise_ar1_phi", s->gyro_noise_ar1_phi, 0, false, 0.99);
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
  s->rocking_frequency_hz = ReadValue(map, "rocking_frequency_hz", s->rocking_frequency_hz, 0,
                                      false, s->sample_rate_hz / 4);
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
    throw UserError(map.Where(length_node) + ": '" + map.KeyPath("filar_separation_m") +
                    "': " + why);
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
        throw UserError(root.Where(model) + ": unknown model '" + name + "' for 'model'; allowed " +
                        PendulumModelAllowedValues());
      }
    }
  }
  {
    const YAML::Node method = root.Optional("integrator");
    if (method.IsDefined() && !method.IsNull()) {
      const std::string name = root.AsString(method, "integrator");
      if (!ParseIntegratorMethod(name, &spec->options.integrator.method)) {
        throw UserError(root.Where(method) + ": unknown integrator '" + name +
                        "' for 'integrator'; allowed " + IntegratorMethodAllowedValues() +
                        " (default " + ToString(spec->options.integrator.method) + ")");
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
                        "' has roll " + Fmt("%g", roll) + ", pitch " + Fmt("%g", pitch) +
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
                      "' has " + Fmt("%g", p) + "; allowed [-90, 90]");
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

}  // namespace

SimulateSpec ReadSimulateSpec(const std::string& file) {
  return ParseSpec(YamlMap::LoadFile(file));
}

SimulateSpec ParseSimulateSpec(const std::string& yaml_text, const std::string& name) {
  return ParseSpec(YamlMap::LoadText(yaml_text, name));
}

}  // namespace bifilar

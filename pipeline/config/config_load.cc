// The YAML loader of the campaign config (pipeline/config/config.h LoadCampaignConfig): reads
// each section of the file into CampaignConfig, with an error naming the file, line and key for a
// missing, blank, unknown or out-of-range value, then CampaignConfig::Check. The types, their
// bounds and their checks are in config.cc; the options structs of the fit (fit.quality,
// fit.amplitude_sweep, fit.glitch) are read from their tables (base/option_table.h).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <set>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "base/bounded_read.h"
#include "base/option_table.h"
#include "base/text_format.h"
#include "base/units.h"
#include "base/user_error.h"
#include "fit/ellipse.h"
#include "pipeline/config/config.h"
#include "pipeline/config/plausibility.h"
#include "pipeline/config/yaml_reader.h"
#include "pipeline/logs/ulog.h"

namespace bifilar {
namespace {

namespace fs = std::filesystem;

// map.Child(key), safe when the key is absent (YamlMap::Child on an absent key keeps an invalid
// yaml-cpp node whose type queries throw; an empty mapping is what we mean).
YamlMap Sub(YamlMap& map, const std::string& key) {
  if (map.Has(key)) return map.Child(key);
  map.Optional(key);
  return YamlMap(YAML::Node(YAML::NodeType::Null), map.file(), map.KeyPath(key));
}

std::string ReadText(const std::string& path) { return ReadRegularFileOrThrow(path, ConfigCap()); }

// Positive finite number, or throw naming the key.
double Positive(YamlMap& map, const std::string& key) {
  YAML::Node node = map.Required(key);
  const double value = map.AsDouble(node, key);
  if (!(value > 0.0)) {
    throw UserError(map.Where(node) + ": " + CheckMessage(map.KeyPath(key), value, "> 0"));
  }
  return value;
}

double NonNegative(YamlMap& map, const std::string& key, double fallback) {
  YAML::Node node = map.Optional(key);
  if (!map.Given(node, key, "a number >= 0")) return fallback;
  const double value = map.AsDouble(node, key);
  if (value < 0.0) {
    throw UserError(map.Where(node) + ": " + CheckMessage(map.KeyPath(key), value, ">= 0"));
  }
  return value;
}

std::array<std::string, 3> ThreeColumns(YamlMap& map, const std::string& key) {
  YAML::Node node = map.Required(key);
  if (!node.IsSequence() || node.size() != 3) {
    throw UserError(map.Where(node) + ": '" + map.KeyPath(key) +
                    "' must be a list of 3 column names (x, y, z)");
  }
  std::array<std::string, 3> columns;
  for (int i = 0; i < 3; ++i) columns[i] = map.AsString(node[i], key);
  return columns;
}

Eigen::Vector3d ThreeVector(const YamlMap& map, const YAML::Node& node, const std::string& key) {
  if (!node.IsSequence() || node.size() != 3) {
    throw UserError(map.Where(node) + ": '" + map.KeyPath(key) + "' must be a list of 3 numbers");
  }
  return Eigen::Vector3d(map.AsDouble(node[0], key), map.AsDouble(node[1], key),
                         map.AsDouble(node[2], key));
}

// `imu.format` and `imu.ulog`: which reader a log gets and, for PX4 ULog logs, which topic and
// fields (pipeline/logs/ulog.h).
void ReadLogContainer(YamlMap& imu, ImuFormat* format) {
  const std::string container = imu.OptionalString("format", "auto");
  if (!ParseLogContainer(container, &format->container)) {
    throw UserError(imu.Where(imu.Optional("format")) + ": 'imu.format' must be " +
                    LogContainerAllowedValues() + ", not '" + container + "'");
  }
  YamlMap ulog = Sub(imu, "ulog");
  UlogSelection& sel = format->ulog;
  const std::string topic = ulog.OptionalString("topic", sel.topic);
  const bool known = UlogTopicDefaults(topic, &sel);
  if (topic.empty())
    throw UserError(ulog.Where(ulog.Optional("topic")) + ": 'imu.ulog.topic' is empty");
  const YAML::Node multi = ulog.Optional("multi_id");
  sel.multi_id = ulog.OptionalInt("multi_id", 0);
  if (sel.multi_id < 0 || sel.multi_id > 255) {
    throw UserError(ulog.Where(multi) + ": " +
                    CheckMessage("imu.ulog.multi_id", sel.multi_id, "in [0, 255]"));
  }
  sel.time_field = ulog.OptionalString("time_field", sel.time_field);
  if (ulog.Has("gyro_fields")) {
    sel.gyro_fields = ThreeColumns(ulog, "gyro_fields");
  } else if (!known) {
    throw UserError(
        ulog.Where(ulog.Optional("topic")) + ": 'imu.ulog.gyro_fields' is needed for topic '" +
        topic + "' (defaults exist for sensor_combined, vehicle_angular_velocity and sensor_gyro)");
  }
  if (ulog.Has("accel_fields") && ulog.Optional("accel_fields").IsNull()) {
    sel.accel_fields = {"", "", ""};
  } else if (ulog.Has("accel_fields")) {
    sel.accel_fields = ThreeColumns(ulog, "accel_fields");
  } else if (!known || !format->has_accel()) {
    sel.accel_fields = {"", "", ""};  // unknown topic, or `imu.accel: null`: gyro only
  }
  std::vector<std::string> names = {sel.time_field, sel.gyro_fields[0], sel.gyro_fields[1],
                                    sel.gyro_fields[2]};
  if (!sel.accel_fields[0].empty())
    names.insert(names.end(), sel.accel_fields.begin(), sel.accel_fields.end());
  const std::set<std::string> distinct(names.begin(), names.end());
  if (distinct.count("") || distinct.size() != names.size()) {
    throw UserError(ulog.Where(YAML::Node()) +
                    ": 'imu.ulog' field names must be non-empty and distinct");
  }
  ulog.Finish();
}

// `imu.time`, `imu.gyro`, `imu.accel`, `imu.format`/`imu.ulog`: the columns and units of a log.
void ReadImuColumns(YamlMap& imu, ImuConfig* out) {
  ImuFormat& format = out->format;
  {
    YamlMap time = Sub(imu, "time");
    format.time_column = time.OptionalString("column", format.time_column);
    const std::string unit = time.OptionalString("unit", ToString(format.time_unit));
    if (!ParseTimeUnit(unit, &format.time_unit)) {
      throw UserError(time.Where(time.Optional("unit")) + ": '" + time.KeyPath("unit") +
                      "' must be " + TimeUnitAllowedValues() + ", not '" + unit + "'");
    }
    time.Finish();
  }
  {
    YamlMap gyro = Sub(imu, "gyro");
    if (gyro.Has("columns")) format.gyro_columns = ThreeColumns(gyro, "columns");
    out->gyro_scale_std = NonNegative(gyro, "scale_std", 0.0);
    const std::string unit = gyro.OptionalString("unit", ToString(format.gyro_unit));
    if (!ParseRateUnit(unit, &format.gyro_unit)) {
      throw UserError(gyro.Where(gyro.Optional("unit")) + ": '" + gyro.KeyPath("unit") +
                      "' must be " + RateUnitAllowedValues() + ", not '" + unit + "'");
    }
    gyro.Finish();
  }
  if (imu.Has("accel") && imu.Optional("accel").IsNull()) {
    format.accel_columns = {"", "", ""};  // `accel: null`: the log has no accelerometer
  } else {
    YamlMap accel = Sub(imu, "accel");
    if (accel.Has("columns")) format.accel_columns = ThreeColumns(accel, "columns");
    const std::string unit = accel.OptionalString("unit", ToString(format.accel_unit));
    if (!ParseAccelUnit(unit, &format.accel_unit)) {
      throw UserError(accel.Where(accel.Optional("unit")) + ": '" + accel.KeyPath("unit") +
                      "' must be " + AccelUnitAllowedValues() + ", not '" + unit + "'");
    }
    accel.Finish();
  }
  ReadLogContainer(imu, &format);
  std::string why;
  if (!format.Check(&why)) throw UserError(imu.file() + ": imu: " + why);
}

// `imu.swing_axis` (auto or a vector in IMU axes) and `imu.imu_to_body` (matrix or Euler angles).
void ReadImuMounting(YamlMap& imu, ImuConfig* out) {
  YAML::Node axis = imu.Optional("swing_axis");
  if (!axis.IsDefined() || axis.IsNull() || (axis.IsScalar() && axis.Scalar() == "auto")) {
    out->swing_axis_auto = true;
  } else {
    const Eigen::Vector3d v = ThreeVector(imu, axis, "swing_axis");
    // A direction, normalised here: its length must be neither 0 nor overflow the norm (1e300
    // gave an infinite norm and a zero axis, so every trace failed instead of the config).
    const double length = v.cwiseAbs().maxCoeff() > kMaxSwingAxisLength ? HUGE_VAL : v.norm();
    if (!(length >= kMinSwingAxisLength && length <= kMaxSwingAxisLength)) {
      char range[96];
      std::snprintf(range, sizeof(range), "[%g, %g]", kMinSwingAxisLength, kMaxSwingAxisLength);
      throw UserError(imu.Where(axis) +
                      ": 'imu.swing_axis' must be auto or a direction in IMU "
                      "axes of length in " +
                      range + ", e.g. [0, 0, 1] (it is normalised)");
    }
    out->swing_axis_auto = false;
    out->swing_axis_in_imu = v.normalized();
  }

  if (imu.Has("imu_to_body")) {
    YamlMap mount = Sub(imu, "imu_to_body");
    const bool has_matrix = mount.Has("matrix"), has_euler = mount.Has("euler_deg");
    if (has_matrix == has_euler) {
      throw UserError(mount.Where(imu.Optional("imu_to_body")) +
                      ": 'imu.imu_to_body' needs exactly one of 'matrix' or 'euler_deg'");
    }
    if (has_euler) {
      YAML::Node node = mount.Optional("euler_deg");
      const Eigen::Vector3d rpy = ThreeVector(mount, node, "euler_deg") * kRadPerDeg;
      // Body-from-IMU rotation R = Rz(yaw) Ry(pitch) Rx(roll) (aerospace ZYX order).
      out->imu_to_body = (Eigen::AngleAxisd(rpy.z(), Eigen::Vector3d::UnitZ()) *
                          Eigen::AngleAxisd(rpy.y(), Eigen::Vector3d::UnitY()) *
                          Eigen::AngleAxisd(rpy.x(), Eigen::Vector3d::UnitX()))
                             .toRotationMatrix();
    } else {
      YAML::Node node = mount.Optional("matrix");
      if (!node.IsSequence() || node.size() != 3) {
        throw UserError(mount.Where(node) + ": 'imu.imu_to_body.matrix' must be 3 rows of 3");
      }
      Eigen::Matrix3d m;
      for (int r = 0; r < 3; ++r) m.row(r) = ThreeVector(mount, node[r], "matrix").transpose();
      if (!((m * m.transpose() - Eigen::Matrix3d::Identity()).norm() < 1e-3 &&
            m.determinant() > 0.0)) {
        throw UserError(mount.Where(node) +
                        ": 'imu.imu_to_body.matrix' must be a rotation (orthonormal, det +1)");
      }
      out->imu_to_body = m;
    }
    mount.Finish();
  }
}

// `imu`: columns and units, then how the IMU hangs.
void ReadImu(YamlMap imu, ImuConfig* out) {
  ReadImuColumns(imu, out);
  {
    YamlMap dataflash = Sub(imu, "dataflash");  // pipeline/logs/dataflash.h
    const YAML::Node node = dataflash.Optional("instance");
    out->dataflash_instance = dataflash.OptionalInt("instance", -1);
    if (dataflash.Has("instance") &&
        (out->dataflash_instance < 0 || out->dataflash_instance > 255)) {
      throw UserError(dataflash.Where(node) + ": " +
                      CheckMessage("imu.dataflash.instance", out->dataflash_instance,
                                   "in [0, 255] (the IMU instance of an ArduPilot log; leave it "
                                   "out for the lowest)"));
    }
    dataflash.Finish();
  }
  ReadImuMounting(imu, out);
  imu.Finish();
}

// `logs` of a tare or calibration section: a pattern or a list of them, resolved against the
// config folder; an empty list is an error naming the key.
std::vector<std::string> ReadLogPatterns(YamlMap& map, const std::string& folder) {
  std::vector<std::string> patterns;
  YAML::Node logs = map.Required("logs");
  if (logs.IsScalar()) {
    patterns = {ResolvePath(folder, logs.Scalar())};
  } else {
    for (const std::string& p : map.OptionalStringList("logs", {})) {
      patterns.push_back(ResolvePath(folder, p));
    }
  }
  if (patterns.empty()) {
    throw UserError(map.Where(logs) + ": '" + map.KeyPath("logs") + "' lists no file");
  }
  return patterns;
}

// `rig.calibration`: the reference swings and the reference's inertia, its std and its mass.
void ReadRigCalibration(YamlMap cal, const std::string& folder, RigCalibrationSpec* out) {
  out->enabled = true;
  out->log_patterns = ReadLogPatterns(cal, folder);
  out->reference_inertia_kg_m2 = Positive(cal, "reference_inertia_kg_m2");
  const YAML::Node std_node = cal.Required("reference_inertia_std_kg_m2");
  out->reference_inertia_std_kg_m2 = NonNegative(cal, "reference_inertia_std_kg_m2", 0.0);
  if (!(out->reference_inertia_std_kg_m2 < out->reference_inertia_kg_m2)) {
    throw UserError(
        cal.Where(std_node) + ": " +
        CheckMessage(
            cal.KeyPath("reference_inertia_std_kg_m2"), out->reference_inertia_std_kg_m2,
            "< reference_inertia_kg_m2 = " + FormatCheckValue(out->reference_inertia_kg_m2) +
                " (the quantity it qualifies)"));
  }
  out->reference_mass_kg = Positive(cal, "reference_mass_kg");
  out->rig_pitch_deg = cal.OptionalDouble("rig_pitch_deg", 0.0);
  if (!(std::abs(out->rig_pitch_deg) <= 180.0)) {
    throw UserError(
        cal.Where(cal.Optional("rig_pitch_deg")) + ": " +
        CheckMessage(cal.KeyPath("rig_pitch_deg"), out->rig_pitch_deg, "in [-180, 180]"));
  }
  cal.Finish();
}

void ReadRigInertia(YamlMap inertia, const std::string& folder, RigInertiaSpec* out) {
  const int ways = inertia.Has("inertia_kg_m2") + inertia.Has("table") + inertia.Has("tare");
  if (ways != 1) {
    throw UserError(inertia.Where(inertia.Optional("__none__")) +
                    ": 'rig.inertia' needs exactly one of 'inertia_kg_m2', 'table' or 'tare'");
  }
  out->inertia_std_kg_m2 = NonNegative(inertia, "inertia_std_kg_m2", 0.0);
  if (inertia.Has("inertia_kg_m2")) {
    out->kind = RigInertiaSpec::Kind::kValue;
    YAML::Node value = inertia.Required("inertia_kg_m2");  // blank or ~: an error, never 0
    out->inertia_kg_m2 = inertia.AsDouble(value, "inertia_kg_m2");
    if (out->inertia_kg_m2 < 0.0) {
      throw UserError(inertia.Where(value) + ": " +
                      CheckMessage("rig.inertia.inertia_kg_m2", out->inertia_kg_m2, ">= 0"));
    }
  } else if (inertia.Has("table")) {
    out->kind = RigInertiaSpec::Kind::kTable;
    YAML::Node table = inertia.Optional("table");
    if (!table.IsMap() || table.size() == 0) {
      throw UserError(inertia.Where(table) +
                      ": 'rig.inertia.table' must map pitch_deg to inertia_kg_m2, e.g. {0: 0.12}");
    }
    std::map<double, YAML::Node> first_key;  // "0" and "0.0" are one pitch: both lines named
    for (const auto& item : table) {
      const double pitch = inertia.AsDouble(item.first, "table");
      const double value = inertia.AsDouble(item.second, "table");
      if (value < 0.0) {
        throw UserError(
            inertia.Where(item.second) + ": " +
            CheckMessage("rig.inertia.table (pitch " + FormatCheckValue(pitch) + " deg)", value,
                         ">= 0"));
      }
      auto [it, inserted] = first_key.emplace(pitch, item.first);
      if (!inserted) {
        throw UserError(inertia.Where(item.first) + ": 'rig.inertia.table' gives pitch " +
                        item.first.Scalar() + " deg twice (first at " + inertia.Where(it->second) +
                        ")");
      }
      out->table_kg_m2[pitch] = value;
    }
  } else {
    out->kind = RigInertiaSpec::Kind::kTare;
    YamlMap tare = Sub(inertia, "tare");
    out->tare_patterns = ReadLogPatterns(tare, folder);
    tare.Finish();
  }
  inertia.Finish();
}

// ---- The steps of LoadCampaignConfig, in the order of the file's sections ---------------------

// The file itself: its absolute path, folder (relative paths in it are relative to this) and
// text (kept for the results).
void ReadConfigFile(const std::string& path, CampaignConfig* config) {
  std::error_code ec;
  if (fs::is_directory(path, ec)) throw UserError(path + ": is a folder, not a config file");
  config->file = fs::absolute(path).lexically_normal().string();
  config->folder = fs::path(config->file).parent_path().string();
  config->text = ReadText(path);
}

// `rig` values no lab rig can have (pipeline/config/plausibility.h): an error at the key's line
// that names the unit the value was probably written in.
void CheckRigPlausible(YamlMap& rig, const CampaignConfig& c) {
  const struct {
    const char* key;
    const char* quantity;
    double value, min, max;
  } values[] = {
      {"filar_length_m", "length", c.filar_length_m, kMinFilarLengthM, kMaxFilarLengthM},
      {"filar_separation_m", "length", c.filar_separation_m, kMinFilarSeparationM,
       kMaxFilarSeparationM},
      {"mass_kg", "mass", c.rig_mass_kg, 0.0, kMaxMassKg},
  };
  for (const auto& v : values) {
    const std::string why = ImplausibleValue(rig.KeyPath(v.key), v.quantity, v.value, v.min, v.max);
    if (!why.empty()) throw UserError(rig.Where(rig.Optional(v.key)) + ": " + why);
  }
  const std::string why = SeparationNotBelowLength(c.filar_length_m, c.filar_separation_m);
  if (!why.empty()) throw UserError(rig.Where(rig.Optional("filar_separation_m")) + ": " + why);
}

// `rig.inertia.inertia_kg_m2` or a `table` value that would make the rig far wider than its wires.
void CheckRigInertiaPlausible(YamlMap inertia, const CampaignConfig& c) {
  const RigInertiaSpec& spec = c.rig_inertia;
  std::string why;
  if (spec.kind == RigInertiaSpec::Kind::kValue) {
    why = ImplausibleRigInertia(inertia.KeyPath("inertia_kg_m2"), spec.inertia_kg_m2, c.rig_mass_kg,
                                c.filar_separation_m);
    if (!why.empty()) {
      throw UserError(inertia.Where(inertia.Optional("inertia_kg_m2")) + ": " + why);
    }
  } else if (spec.kind == RigInertiaSpec::Kind::kTable) {
    for (const auto& [pitch_deg, value] : spec.table_kg_m2) {
      char key[96];
      std::snprintf(key, sizeof(key), "%s (pitch %g deg)", inertia.KeyPath("table").c_str(),
                    pitch_deg);
      why = ImplausibleRigInertia(key, value, c.rig_mass_kg, c.filar_separation_m);
      if (!why.empty()) throw UserError(inertia.Where(inertia.Optional("table")) + ": " + why);
    }
  }
}

// `rig`: geometry and mass, how its inertia is known (rig.inertia), its uncertainties.
void ReadRig(YamlMap& root, const std::string& path, const ConfigLoadOptions& options,
             CampaignConfig* config) {
  YamlMap rig = Sub(root, "rig");
  if (!root.Has("rig")) throw UserError(path + ": missing required key 'rig'");
  config->filar_length_m = Positive(rig, "filar_length_m");
  config->filar_separation_m = Positive(rig, "filar_separation_m");
  config->rig_mass_kg = Positive(rig, "mass_kg");
  CheckRigPlausible(rig, *config);
  if (rig.Has("inertia")) {
    ReadRigInertia(Sub(rig, "inertia"), config->folder, &config->rig_inertia);
    CheckRigInertiaPlausible(Sub(rig, "inertia"), *config);
  } else if (options.require_runs && root.Has("aircraft")) {
    throw UserError(path +
                    ": missing required key 'rig.inertia' (or leave out 'aircraft' too: "
                    "then rig.mass_kg is everything that hangs and no rig inertia is subtracted)");
  } else {
    config->rig_inertia_given = false;  // nothing subtracted: the moments of all that hangs
  }
  if (rig.Has("calibration")) {
    if (!rig.Has("inertia")) {
      throw UserError(rig.Where(rig.Optional("calibration")) +
                      ": 'rig.calibration' needs 'rig.inertia' (the reference swings measure rig "
                      "+ reference: the rig's own inertia is needed to calibrate)");
    }
    ReadRigCalibration(Sub(rig, "calibration"), config->folder, &config->calibration);
  }
  YamlMap unc = Sub(rig, "uncertainties");
  RigUncertainties& u = config->uncertainties;
  u.configured = rig.Has("uncertainties");
  u.filar_length_std_m = NonNegative(unc, "filar_length_std_m", 0.0);
  u.filar_separation_std_m = NonNegative(unc, "filar_separation_std_m", 0.0);
  u.mass_std_kg = NonNegative(unc, "mass_std_kg", 0.0);
  u.gravity_std_mps2 = NonNegative(unc, "gravity_std_mps2", 0.0);
  unc.Finish();
  rig.Finish();
}

// `aircraft.cg_m` and `aircraft.cg_std_m`: 3 finite numbers each (m), the std >= 0.
AircraftCg ReadAircraftCg(YamlMap& aircraft) {
  AircraftCg cg;
  const YAML::Node at = aircraft.Optional("cg_m");
  if (aircraft.Given(at, "cg_m", "a list of 3 numbers (m)")) {
    const Eigen::Vector3d v = ThreeVector(aircraft, at, "cg_m");
    for (int i = 0; i < 3; ++i) cg.cg_m[i] = v[i];
  }
  const YAML::Node std_node = aircraft.Optional("cg_std_m");
  if (aircraft.Given(std_node, "cg_std_m", "a list of 3 numbers (m)")) {
    const Eigen::Vector3d v = ThreeVector(aircraft, std_node, "cg_std_m");
    if (!cg.Given()) {
      throw UserError(aircraft.Where(std_node) + ": 'aircraft.cg_std_m' without aircraft.cg_m");
    }
    for (int i = 0; i < 3; ++i) cg.cg_std_m[i] = v[i];
  }
  for (int i = 0; i < 3; ++i) {
    if (cg.Given() && (!std::isfinite(cg.cg_m[i]) || std::abs(cg.cg_m[i]) > 1e3)) {
      throw UserError(aircraft.Where(at) +
                      ": 'aircraft.cg_m' must be 3 finite numbers within "
                      "1000 m of the model origin");
    }
    if (!std::isnan(cg.cg_std_m[i]) && !(std::isfinite(cg.cg_std_m[i]) && cg.cg_std_m[i] >= 0)) {
      throw UserError(aircraft.Where(std_node) + ": 'aircraft.cg_std_m' must be 3 numbers >= 0");
    }
  }
  return cg;
}

// `aircraft` (mass and its std) and `gravity_mps2`.
void ReadAircraftAndGravity(YamlMap& root, const std::string& path,
                            const ConfigLoadOptions& options, CampaignConfig* config) {
  YamlMap aircraft = Sub(root, "aircraft");
  if (root.Has("aircraft")) {
    config->aircraft_mass_kg = Positive(aircraft, "mass_kg");
    const std::string why =
        ImplausibleValue("aircraft.mass_kg", "mass", config->aircraft_mass_kg, 0.0, kMaxMassKg);
    if (!why.empty()) throw UserError(aircraft.Where(aircraft.Optional("mass_kg")) + ": " + why);
    const YAML::Node std_node = aircraft.Optional("mass_std_kg");
    config->aircraft_mass_std_given = std_node.IsDefined() && !std_node.IsNull();
    config->aircraft_mass_std_kg = NonNegative(aircraft, "mass_std_kg", 0.0);
    config->aircraft_cg = ReadAircraftCg(aircraft);
  } else if (options.require_runs && config->rig_inertia_given) {
    throw UserError(path +
                    ": missing required key 'aircraft' (or leave out 'rig.inertia' too: "
                    "then rig.mass_kg is everything that hangs and no rig inertia is subtracted)");
  }
  aircraft.Finish();
  // g is bounded to what is found on Earth (a typo such as 98.0665 would scale every moment);
  // `gravity_off_earth: true` allows (0, 100] for a rig elsewhere.
  config->gravity_off_earth = root.OptionalBool("gravity_off_earth", false);
  YAML::Node g = root.Optional("gravity_mps2");
  if (root.Given(g, "gravity_mps2", "a number (m/s^2)")) {
    config->gravity_mps2 = root.AsDouble(g, "gravity_mps2");
  }
  std::string why;
  if (!CheckGravity(config->gravity_mps2, config->gravity_off_earth, &why)) {
    throw UserError((g.IsDefined() ? root.Where(g) : path) + ": " + why);
  }
}

// `runs`: where the aircraft logs are (root + pattern, which may not leave the root, or a
// table) and which pitch the ellipse uses.
void ReadRuns(YamlMap& root, const std::string& path, const ConfigLoadOptions& options,
              CampaignConfig* config) {
  if (!root.Has("runs")) {
    if (options.require_runs) throw UserError(path + ": missing required key 'runs'");
    return;
  }
  YamlMap runs = Sub(root, "runs");
  RunsConfig& r = config->runs;
  if (!options.runs_root.empty()) {
    runs.Optional("root");  // read (not an unknown key), replaced by --runs-root
    r.root = fs::absolute(options.runs_root).lexically_normal().string();
  } else {
    r.root = ResolvePath(config->folder, runs.RequiredString("root"));
  }
  const bool has_pattern = runs.Has("pattern"), has_table = runs.Has("table");
  if (has_pattern == has_table) {
    throw UserError(runs.Where(root.Optional("runs")) +
                    ": 'runs' needs exactly one of 'pattern' or 'table'");
  }
  if (has_pattern) {
    r.pattern = runs.RequiredString("pattern");
    if (fs::path(r.pattern).is_absolute()) {
      throw UserError(runs.Where(runs.Optional("pattern")) +
                      ": 'runs.pattern' must be relative to runs.root");
    }
    for (const char* placeholder : {"{pitch_deg}", "{roll_deg}"}) {
      const size_t first = r.pattern.find(placeholder);
      if (first != std::string::npos &&
          r.pattern.find(placeholder, first + 1) != std::string::npos) {
        throw UserError(runs.Where(runs.Optional("pattern")) + ": 'runs.pattern' may hold " +
                        placeholder + " only once, not in two components");
      }
    }
    for (const auto& part : fs::path(r.pattern)) {
      if (part == "..") {
        throw UserError(runs.Where(runs.Optional("pattern")) +
                        ": 'runs.pattern' must stay inside runs.root (no '..'): set runs.root "
                        "to the folder that holds the logs instead");
      }
    }
  } else {
    r.table = ResolvePath(config->folder, runs.RequiredString("table"));
  }
  const std::string source = runs.OptionalString("pitch_source", "nominal");
  if (!ParsePitchSource(source, &r.pitch_source)) {
    throw UserError(runs.Where(runs.Optional("pitch_source")) + ": 'runs.pitch_source' must be " +
                    PitchSourceAllowedValues() + ", not '" + source + "'");
  }
  const YAML::Node tolerance = runs.Optional("attitude_tolerance_deg");
  if (tolerance.IsDefined() && !tolerance.IsNull()) {
    r.attitude_tolerance_deg = runs.AsDouble(tolerance, "attitude_tolerance_deg");
    if (!(r.attitude_tolerance_deg > 0.0 && r.attitude_tolerance_deg <= 180.0)) {
      throw UserError(
          runs.Where(tolerance) + ": " +
          CheckMessage("runs.attitude_tolerance_deg", r.attitude_tolerance_deg, "in (0, 180]"));
    }
  }
  if (r.pitch_source == PitchSource::kMeasured && !config->imu.format.has_accel()) {
    throw UserError(path +
                    ": 'runs.pitch_source: measured' needs accelerometer columns (imu.accel)");
  }
  runs.Finish();
}

// `fit.windows`: file -> [t0_s, t1_s].
void ReadFitWindows(YamlMap& fit, FitConfig* out) {
  YAML::Node windows = fit.Optional("windows");
  if (!windows.IsDefined() || windows.IsNull()) return;
  if (!windows.IsMap()) {
    throw UserError(fit.Where(windows) + ": 'fit.windows' must map file to [t0_s, t1_s]");
  }
  for (const auto& item : windows) {
    const std::string key = "windows." + item.first.Scalar();
    if (!item.second.IsSequence() || item.second.size() != 2) {
      throw UserError(fit.Where(item.second) + ": 'fit." + key + "' must be [t0_s, t1_s]");
    }
    const double t0 = fit.AsDouble(item.second[0], key), t1 = fit.AsDouble(item.second[1], key);
    if (!(t1 > t0)) {
      throw UserError(fit.Where(item.second) + ": 'fit." + key + "' needs t0 < t1");
    }
    out->windows_s[item.first.Scalar()] = {t0, t1};
  }
}

// An options struct's section (`fit.quality`, `fit.amplitude_sweep`, `fit.glitch`) read from its
// table (base/option_table.h): one optional key per row, the struct's default when absent. Every
// row's key is marked read, so a key no row has is still reported by Finish() as unknown. The
// bounds are checked afterwards, by the struct's own Check (FitConfig::Check, in ReadFit).
template <class Options>
void ReadOptionFields(YamlMap& section, const OptionFields<Options>& fields, Options* options) {
  for (const OptionField<Options>& row : fields) {
    if (row.real) {
      options->*row.real = section.OptionalDouble(row.key, options->*row.real);
    } else if (row.whole) {
      options->*row.whole = section.OptionalInt(row.key, options->*row.whole);
    } else {
      options->*row.flag = section.OptionalBool(row.key, options->*row.flag);
    }
  }
  section.Finish();
}

// `fit.quality`, `fit.amplitude_sweep` and `fit.glitch`, from their tables. One default depends on
// another key: a config that raises only max_secondary_motion_ratio above the rejection level
// raises reject_secondary_motion_ratio with it (it must be >= the warning level).
void ReadFitOptionSections(YamlMap& fit, FitConfig* out) {
  YamlMap quality = Sub(fit, "quality");
  const bool reject_given = quality.Has("reject_secondary_motion_ratio");
  ReadOptionFields(quality, TraceQualityOptions::Fields(), &out->quality);
  if (!reject_given) {
    out->quality.reject_secondary_motion_ratio = std::max(
        out->quality.reject_secondary_motion_ratio, out->quality.max_secondary_motion_ratio);
  }
  YamlMap sweep = Sub(fit, "amplitude_sweep");
  ReadOptionFields(sweep, AmplitudeSweepOptions::Fields(), &out->sweep);
  YamlMap glitch = Sub(fit, "glitch");
  ReadOptionFields(glitch, GlitchOptions::Fields(), &out->glitch);
}

// The node an error about `key_path` below `map` names ("quality.whiteness_lags" below `fit`):
// the key's value, else its section, else the key in `map` itself.
YAML::Node FailureNode(YamlMap& map, const std::string& key_path) {
  const size_t dot = key_path.find('.');
  if (dot == std::string::npos) return map.Optional(key_path);
  const YAML::Node section = map.Optional(key_path.substr(0, dot));
  const std::string key = key_path.substr(dot + 1);
  if (section.IsDefined() && section.IsMap() && section[key].IsDefined()) return section[key];
  return section;
}

// `fit`: model, integrator, windows, amplitude limits, quality, sweep, glitch; then
// FitConfig::Check, its failure named by key and line.
void ReadFit(YamlMap fit, FitConfig* out) {
  // Defaults: FitConfig's own (full, rk853), named through the enums' tables.
  const std::string model = fit.OptionalString("model", ToString(out->model));
  if (!ParsePendulumModel(model, &out->model)) {
    throw UserError(fit.Where(fit.Optional("model")) + ": 'fit.model' must be " +
                    PendulumModelAllowedValues() + ", not '" + model + "'");
  }
  const std::string integrator = fit.OptionalString("integrator", ToString(out->integrator));
  if (!ParseIntegratorMethod(integrator, &out->integrator)) {
    throw UserError(fit.Where(fit.Optional("integrator")) + ": 'fit.integrator' must be " +
                    IntegratorMethodAllowedValues() + ", not '" + integrator + "'");
  }
  ReadFitWindows(fit, out);
  if (fit.Has("max_amplitude_deg"))
    out->max_amplitude_deg = fit.RequiredDouble("max_amplitude_deg");
  if (fit.Has("min_amplitude_deg"))
    out->min_amplitude_deg = fit.RequiredDouble("min_amplitude_deg");
  ReadFitOptionSections(fit, out);
  CheckFailure failure;
  if (!out->Check(&failure)) {
    throw UserError(fit.Where(FailureNode(fit, failure.field)) + ": " +
                    CheckMessage("fit." + failure.field, failure.value, failure.allowed));
  }
  fit.Finish();
}

// `ellipse`: bootstrap, seed, confidence, covariance, min_angles; then EllipseConfig::Check.
void ReadEllipse(YamlMap ellipse, EllipseConfig* e) {
  e->bootstrap = ellipse.OptionalInt("bootstrap", e->bootstrap);
  e->seed = static_cast<unsigned>(
      ellipse.OptionalIntIn("seed", e->seed, 0, std::numeric_limits<unsigned>::max()));
  e->confidence = ellipse.OptionalDouble("confidence", e->confidence);
  const std::string covariance =
      ellipse.OptionalString("covariance", EllipseCovarianceName(e->covariance));
  if (!ParseEllipseCovariance(covariance, &e->covariance)) {
    throw UserError(ellipse.Where(ellipse.Optional("covariance")) +
                    ": 'ellipse.covariance' must be " + EllipseCovarianceAllowedValues() +
                    ", not '" + covariance + "'");
  }
  e->min_angles = ellipse.OptionalInt("min_angles", e->min_angles);
  CheckFailure failure;
  if (!e->Check(&failure)) {
    throw UserError(ellipse.Where(FailureNode(ellipse, failure.field)) + ": " +
                    CheckMessage("ellipse." + failure.field, failure.value, failure.allowed));
  }
  ellipse.Finish();
}

// `units`: si or imperial (display only; files stay SI).
DisplayUnits ReadUnits(YamlMap& root) {
  const std::string units = root.OptionalString("units", "si");
  DisplayUnits parsed;
  if (ParseDisplayUnits(units, &parsed)) return parsed;
  throw UserError(root.Where(root.Optional("units")) + ": 'units' must be " +
                  DisplayUnitsAllowedValues() + ", not '" + units + "'");
}

// `limits`: the size caps of the logs, MB in [1, kMaxLimitMb].
InputLimits ReadLimits(YamlMap limits) {
  InputLimits l;
  for (auto [key, value] : {std::pair<const char*, double*>{"max_log_mb", &l.max_log_mb},
                            {"max_decompressed_log_mb", &l.max_decompressed_log_mb}}) {
    YAML::Node node = limits.Optional(key);
    if (!node.IsDefined()) continue;
    const double mb = limits.AsDouble(node, key);
    if (!(mb >= 1 && mb <= kMaxLimitMb)) {
      throw UserError(limits.Where(node) + ": " +
                      CheckMessage(limits.KeyPath(key), mb,
                                   "in " + IntervalText(1, kMaxLimitMb, Ends::kClosed) + " (MB)"));
    }
    *value = mb;
  }
  limits.Finish();
  return l;
}

}  // namespace
// read the file -> rig -> aircraft, gravity -> imu -> runs -> fit -> ellipse -> units -> no
// unknown key -> the ranges that involve several keys (CampaignConfig::Check).
CampaignConfig LoadCampaignConfig(const std::string& path, const ConfigLoadOptions& options) {
  CampaignConfig config;
  ReadConfigFile(path, &config);
  return LoadCampaignConfigText(config.text, path, options);
}

CampaignConfig LoadCampaignConfigText(const std::string& text, const std::string& path,
                                      const ConfigLoadOptions& options) {
  CampaignConfig config;
  config.file = fs::absolute(path).lexically_normal().string();
  config.folder = fs::path(config.file).parent_path().string();
  config.text = text;
  YamlMap root = YamlMap::LoadText(text, path);
  ReadRig(root, path, options, &config);
  ReadAircraftAndGravity(root, path, options, &config);
  ReadImu(Sub(root, "imu"), &config.imu);
  ReadRuns(root, path, options, &config);
  ReadFit(Sub(root, "fit"), &config.fit);
  ReadEllipse(Sub(root, "ellipse"), &config.ellipse);
  config.units = ReadUnits(root);
  config.limits = ReadLimits(Sub(root, "limits"));
  root.Finish();
  std::string why;
  if (!config.Check(&why)) throw UserError(path + ": " + why);
  return config;
}

}  // namespace bifilar

namespace bifilar {

AircraftCg ReadAircraftCgText(const std::string& text, const std::string& name) {
  YamlMap root = YamlMap::LoadText(text, name);
  YamlMap aircraft = Sub(root, "aircraft");
  return ReadAircraftCg(aircraft);
}

}  // namespace bifilar

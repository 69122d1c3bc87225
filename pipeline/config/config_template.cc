#include "pipeline/config/config_template.h"

#include <cstdio>
#include <sstream>
#include <utility>
#include <vector>

#include "base/user_error.h"
#include "pendulum/model.h"
#include "pipeline/config/config.h"

namespace bifilar {
namespace {

// The one way a string enters the YAML init writes (issue 23: a log named
// "swing\naircraft: {mass_kg: 0.5}\n#.csv" injected a key): a double-quoted scalar in which
// every character that could end it, start a new line or be read differently is escaped (quote,
// backslash, control characters, DEL, and the Unicode line breaks NEL, LS and PS). Column names
// with brackets, colons, '#', a leading dash or any other UTF-8 survive as they are.
std::string Quoted(const std::string& text) {
  std::string out = "\"";
  for (size_t i = 0; i < text.size(); ++i) {
    const unsigned char c = static_cast<unsigned char>(text[i]);
    const auto next = [&](size_t k) {
      return i + k < text.size() ? static_cast<unsigned char>(text[i + k]) : 0;
    };
    if (c == '"' || c == '\\') {
      (out += '\\') += static_cast<char>(c);
    } else if (c == '\n') {
      out += "\\n";
    } else if (c == '\t') {
      out += "\\t";
    } else if (c == '\r') {
      out += "\\r";
    } else if (c < 0x20 || c == 0x7f) {
      char hex[8];
      std::snprintf(hex, sizeof(hex), "\\x%02x", c);
      out += hex;
    } else if (c == 0xc2 && next(1) == 0x85) {  // NEL: yaml-cpp 0.7 reads "\N" as one byte 0x85
      out += "\\u0085";
      ++i;
    } else if (c == 0xe2 && next(1) == 0x80 && (next(2) == 0xa8 || next(2) == 0xa9)) {  // LS, PS
      out += next(2) == 0xa8 ? "\\L" : "\\P";
      i += 2;
    } else {
      out += static_cast<char>(c);
    }
  }
  return out + "\"";
}

std::string Number(double value) {
  char buffer[40];
  std::snprintf(buffer, sizeof(buffer), "%.10g", value);
  return buffer;
}

std::string List3(const std::array<std::string, 3>& names) {
  return "[" + Quoted(names[0]) + ", " + Quoted(names[1]) + ", " + Quoted(names[2]) + "]";
}

}  // namespace

bool StartingConfigOptions::Check(std::string* why) const {
  RigGeometry geometry;
  geometry.filar_length_m = filar_length_m;
  geometry.filar_separation_m = filar_separation_m;
  geometry.mass_kg = mass_kg;
  geometry.gravity_mps2 = gravity_mps2;
  if (!geometry.Check(why)) return false;
  if (format && !format->Check(why)) return false;
  return true;
}

bool ParseRigSpec(const std::string& text, StartingConfigOptions* options, std::string* why) {
  double values[3];
  char tail = 0;
  if (std::sscanf(text.c_str(), "%lf,%lf,%lf%c", &values[0], &values[1], &values[2], &tail) != 3) {
    *why = "--rig '" + text + "': expected L,D,MASS in m, m and kg, e.g. --rig 0.594,0.030,0.0343";
    return false;
  }
  options->filar_length_m = values[0];
  options->filar_separation_m = values[1];
  options->mass_kg = values[2];
  std::string check;
  if (!options->Check(&check)) {
    *why = "--rig '" + text + "': " + check;
    return false;
  }
  return true;
}

std::string StartingConfigText(const StartingConfigOptions& o) {
  std::ostringstream y;
  y << "# bifilar config, written by `bifilar init`. Every key: configs/README.md in the bifilar\n"
       "# repository. Values are SI (m, kg, s); angles in degrees.\n"
       "#\n"
       "# Fit one log with it:    bifilar fit THIS.yaml LOG.csv\n"
       "# Several swings of one set-up (their scatter enters the uncertainty):\n"
       "#                         bifilar fit THIS.yaml run_1.csv run_2.csv run_3.csv --repeats\n"
       "# A campaign of pitch angles (the ellipse of inertia): fill in `aircraft`, `rig.inertia`\n"
       "# and `runs` below, then   bifilar process THIS.yaml --out OUT\n"
       "\n"
       "gravity_mps2: "
    << Number(o.gravity_mps2)
    << "            # local gravity g\n"
       "\n"
       "rig:\n"
       "  filar_length_m: "
    << Number(o.filar_length_m)
    << "        # L, wire length, from the pivot to the rig's attachment\n"
       "  filar_separation_m: "
    << Number(o.filar_separation_m)
    << "    # D, distance between the two wires\n"
       "  # Everything that hangs. For `bifilar fit` without an `aircraft` section this is the\n"
       "  # whole suspended mass; for a campaign, the rig (+ IMU) alone, and aircraft.mass_kg is\n"
       "  # added for aircraft logs.\n"
       "  mass_kg: "
    << Number(o.mass_kg)
    << "\n"
       "  # How well you measured L, D and the mass (1 sigma). They usually dominate the total\n"
       "  # uncertainty: a 1 mm error on a 30 mm separation is 6.7 % on I. Measure, then fill in.\n"
       "  # uncertainties:\n"
       "  #   filar_length_std_m: 0.001\n"
       "  #   filar_separation_std_m: 0.001\n"
       "  #   mass_std_kg: 0.001\n"
       "  # The rig's own inertia, subtracted from every aircraft moment (campaigns only):\n"
       "  # inertia:\n"
       "  #   tare: {logs: tare/*.csv}        # swings of the rig alone, or\n"
       "  #   # inertia_kg_m2: 0.0             # a known value\n"
       "\n"
       "# aircraft:                          # campaigns only\n"
       "#   mass_kg: 5.5\n"
       "#   mass_std_kg: 0.01\n"
       "\n";
  if (!o.format_source.empty()) {
    y << "# Log format guessed from " << Quoted(o.format_source) << ": check it.\n";
  }
  y << "imu:\n";
  const ImuFormat format = o.format.value_or(ImuFormat());
  if (o.ulog) {
    y << "  format: ulog\n"
         "  ulog:\n"
         "    topic: "
      << Quoted(format.ulog.topic) << "\n    multi_id: " << format.ulog.multi_id
      << "\n    time_field: " << Quoted(format.ulog.time_field)
      << "\n    gyro_fields: " << List3(format.ulog.gyro_fields) << "\n";
    if (format.ulog.accel_fields[0].empty())
      y << "    accel_fields: null\n";
    else
      y << "    accel_fields: " << List3(format.ulog.accel_fields) << "\n";
  } else {
    y << "  time: {column: " << Quoted(format.time_column)
      << ", unit: " << ToString(format.time_unit)
      << "}\n"
         "  gyro: {columns: "
      << List3(format.gyro_columns) << ", unit: " << ToString(format.gyro_unit) << "}\n";
    if (format.has_accel()) {
      y << "  accel: {columns: " << List3(format.accel_columns)
        << ", unit: " << ToString(format.accel_unit) << "}\n";
    } else {
      y << "  accel: null                       # no accelerometer: swing axis from the gyro\n";
    }
    if (format.delimiter != ',') {
      y << "  # the log separates its columns with " << Quoted(std::string(1, format.delimiter))
        << ": bifilar reads comma-separated logs, so convert it first\n";
    }
  }
  y << "  swing_axis: auto                   # the down vertical (accelerometer) or the gyro's\n"
       "                                     # dominant direction\n"
       "\n"
       "# runs:                              # campaigns only: where the aircraft logs are\n"
       "#   root: logs\n"
       "#   pattern: \"pitch_{pitch_deg}/*.csv\"\n"
       "\n"
       "fit:\n"
       "  model: full                        # the exact bifilar model (docs/physics.md)\n";
  return y.str();
}

namespace {

// Every name init would write: at most kMaxStartingConfigNameBytes long; otherwise false and why.
bool NamesBounded(const StartingConfigOptions& options, std::string* why) {
  const ImuFormat format = options.format.value_or(ImuFormat());
  std::vector<std::string> names = {format.time_column, format.ulog.topic, format.ulog.time_field};
  for (int a = 0; a < 3; ++a) {
    for (const std::string* n : {&format.gyro_columns[a], &format.accel_columns[a],
                                 &format.ulog.gyro_fields[a], &format.ulog.accel_fields[a]}) {
      names.push_back(*n);
    }
  }
  for (const std::string& n : names) {
    if (n.size() > kMaxStartingConfigNameBytes) {
      *why = "a column, topic or field name of " + std::to_string(n.size()) + " bytes ('" +
             EchoedName(n, 40) + "'): longer than the " +
             std::to_string(kMaxStartingConfigNameBytes) +
             " bytes of any logger's header; rename the column in the log, or write the config "
             "by hand";
      return false;
    }
  }
  return true;
}

// Which name the YAML did not keep, and what in it: "'gx?' (holds U+0085 (NEL, a line break) at
// byte 2)".
std::string FirstChangedName(const std::vector<std::pair<std::string, std::string>>& meant_read) {
  for (const auto& [meant, read] : meant_read) {
    if (meant == read) continue;
    const std::string what = DescribeUnprintable(meant);
    return "'" + EchoedName(meant, 60) + "'" + (what.empty() ? "" : " (holds " + what + ")") +
           " reads back as '" + EchoedName(read, 60) + "'";
  }
  return "";
}

}  // namespace

std::string CheckedStartingConfigText(const StartingConfigOptions& options, const std::string& path,
                                      CampaignConfig* loaded) {
  std::string why;
  if (!NamesBounded(options, &why)) throw UserError("init: " + path + ": " + why);
  const std::string text = StartingConfigText(options);
  ConfigLoadOptions load;
  load.require_runs = false;  // what `bifilar fit` asks of a config
  CampaignConfig config;
  try {
    config = LoadCampaignConfigText(text, path, load);
  } catch (const UserError& e) {
    throw UserError("init: " + path +
                    ": the config it would write is one `bifilar fit` rejects: " + e.what());
  }
  // The names read back are the names meant (a YAML scalar that changed one would fit the
  // wrong columns, or none).
  const ImuFormat meant = options.format.value_or(ImuFormat());
  const ImuFormat& read = config.imu.format;
  std::vector<std::pair<std::string, std::string>> pairs;
  if (options.ulog) {
    pairs = {{meant.ulog.topic, read.ulog.topic}, {meant.ulog.time_field, read.ulog.time_field}};
    for (int a = 0; a < 3; ++a) {
      pairs.push_back({meant.ulog.gyro_fields[a], read.ulog.gyro_fields[a]});
      if (!meant.ulog.accel_fields[0].empty() || !read.ulog.accel_fields[0].empty()) {
        pairs.push_back({meant.ulog.accel_fields[a], read.ulog.accel_fields[a]});
      }
    }
  } else {
    pairs = {{meant.time_column, read.time_column}};
    for (int a = 0; a < 3; ++a) {
      pairs.push_back({meant.gyro_columns[a], read.gyro_columns[a]});
      pairs.push_back({meant.has_accel() ? meant.accel_columns[a] : std::string(),
                       read.has_accel() ? read.accel_columns[a] : std::string()});
    }
  }
  const std::string changed = FirstChangedName(pairs);
  if (!changed.empty()) {
    throw UserError(
        "init: " + path + ": a name of the log" +
        (options.format_source.empty() ? std::string() : " " + EchoedName(options.format_source)) +
        " does not survive in YAML: " + changed + "; write the config by hand");
  }
  if (loaded != nullptr) *loaded = std::move(config);
  return text;
}

}  // namespace bifilar

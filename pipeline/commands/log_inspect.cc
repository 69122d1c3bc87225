#include "pipeline/commands/log_inspect.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <sstream>

#include "base/bounded_read.h"
#include "base/gzip.h"
#include "base/json_number.h"
#include "base/statistics.h"
#include "base/text_format.h"
#include "base/units.h"
#include "base/user_error.h"
#include "fit/swing_axis.h"
#include "fit/window.h"
#include "pendulum/model.h"
#include "pipeline/logs/imu_log.h"
#include "pipeline/logs/log_unit_check.h"
#include "pipeline/logs/ulog.h"
#include "pipeline/trace/trace_process.h"

namespace bifilar {
namespace {

// Steps longer than this many median steps are dropouts (as the window search treats gaps).
constexpr double kDropoutSteps = 2.5;

// A name of the file's own echoed in a message or on the terminal (EchoedName,
// pipeline/logs/imu_format.h: escape sequences and line breaks as '?', at most 80 bytes).
std::string PrintableName(const std::string& name) { return EchoedName(name, 80); }

// Every subscription with its sample count and rate, in one pass over the file.
void ReadUlogTopics(const std::string& bytes, const std::string& name, InspectReport* report) {
  UlogRequest none;
  none.topic_timestamps = true;
  const UlogContents contents = ParseUlog(bytes, name, none);
  for (const UlogSubscription& s : contents.subscriptions) {
    UlogTopicInfo info;
    info.topic = s.topic;
    info.multi_id = s.multi_id;
    info.samples = s.samples;
    if (s.samples > 1 && std::isfinite(s.first_timestamp_us) &&
        std::isfinite(s.last_timestamp_us)) {
      const double span_s = (s.last_timestamp_us - s.first_timestamp_us) * 1e-6;
      if (span_s > 0) info.rate_hz = (s.samples - 1) / span_s;
    }
    report->topics.push_back(info);
  }
  for (const std::string& w : contents.warnings) report->warnings.push_back(w);
}

// An ArduPilot DataFlash log (pipeline/logs/dataflash.h): every message with its count, rate and
// instances, then the IMU series of the configured instance (or the lowest).
ImuData ReadDataflashLog(const std::string& bytes, const std::string& path,
                         const CampaignConfig* config, ImuLogOptions options,
                         InspectReport* report) {
  report->kind = "dataflash";
  const DataflashContents contents = ParseDataflash(bytes, path);
  report->messages = contents.messages;
  if (config != nullptr) {
    report->format = config->imu.format;
    report->format_from_config = true;
    options.dataflash_instance = config->imu.dataflash_instance;
  }
  ImuData data = ReadDataflashImu(bytes, path, options);
  if (!report->format_from_config) {
    report->guesses.push_back(
        "ArduPilot DataFlash log: gyro in rad/s and accelerometer in m/s^2 "
        "as ArduPilot logs them (FMTU units checked)");
  }
  return data;
}

// The first topic with an IMU among those with known defaults.
bool GuessUlogFormat(InspectReport* report) {
  for (const char* topic : {"sensor_combined", "vehicle_angular_velocity", "sensor_gyro"}) {
    for (const UlogTopicInfo& t : report->topics) {
      if (t.topic == topic && t.samples > 1) {
        UlogTopicDefaults(topic, &report->format.ulog);
        report->format.ulog.multi_id = t.multi_id;
        report->guesses.push_back(std::string("ULog topic '") + topic + "' (" +
                                  std::to_string(t.samples) + " samples)");
        return true;
      }
    }
  }
  return false;
}

// The first rows of a log are often the rest before the twist: the gyro unit guessed there is
// checked against the 99th percentile of the whole series, and the series rescaled to deg/s when
// the readings are no pendulum in rad/s.
void RefineGyroUnitGuess(ImuData* data, InspectReport* report) {
  if (report->format.gyro_unit != RateUnit::kRadPerS) return;
  std::vector<double> magnitudes;
  magnitudes.reserve(3 * data->size());
  for (const Eigen::Vector3d& w : data->gyro_in_imu) {
    for (int a = 0; a < 3; ++a) magnitudes.push_back(std::fabs(w[a]));
  }
  if (magnitudes.empty()) return;
  std::nth_element(magnitudes.begin(), magnitudes.begin() + magnitudes.size() * 99 / 100,
                   magnitudes.end());
  const double p99 = magnitudes[magnitudes.size() * 99 / 100];
  if (p99 <= kDegPerSGuessAbove) return;
  report->format.gyro_unit = RateUnit::kDegPerS;
  for (Eigen::Vector3d& w : data->gyro_in_imu) w *= ToSi(RateUnit::kDegPerS);
  for (std::string& g : report->guesses) {
    if (g.rfind("gyro columns", 0) == 0) {
      g = "gyro columns " + report->format.gyro_columns[0] + ", " + report->format.gyro_columns[1] +
          ", " + report->format.gyro_columns[2] +
          Fmt(" in deg/s (from the readings: 99th percentile of |rate| %.3g over the log is no "
              "pendulum in rad/s)",
              p99);
    }
  }
}

// The guessed time and gyro units checked against the swing (pipeline/logs/log_unit_check.h):
// the series read again in the units that make it a pendulum, the guess lines saying so; angle
// columns taken for rates are the report's format problem.
void CheckGuessedUnits(const std::string& bytes, const std::string& path,
                       const ImuLogOptions& options, const FormatGuess& guess, ImuData* data,
                       InspectReport* report) {
  const UnitCheck check = CheckUnitsAgainstSwing(*data, report->format, guess.time_unit_from_names,
                                                 guess.gyro_unit_from_names);
  const std::string columns = PrintableName(report->format.gyro_columns[0]) + ", " +
                              PrintableName(report->format.gyro_columns[1]) + ", " +
                              PrintableName(report->format.gyro_columns[2]);
  if (!check.angles.empty()) {
    report->format_problem = "the columns " + columns + " look like angles, not angular rates (" +
                             check.angles +
                             "); bifilar needs the gyro's rates: name those "
                             "columns (bifilar init --gyro X,Y,Z, or imu.gyro.columns)";
    return;
  }
  if (!check.warning.empty()) report->warnings.push_back(check.warning);
  if (!check.swing_found || check.best < 0) return;
  const UnitReading& best = check.readings[check.best];
  if (check.changed) {
    report->format.time_unit = best.time;
    report->format.gyro_unit = best.gyro;
    *data = ReadImuLogFromString(bytes, path, report->format, options);
  }
  for (std::string& g : report->guesses) {
    if (g.rfind("time column", 0) == 0) {
      g = "time column '" + PrintableName(report->format.time_column) + "' in " +
          ToString(report->format.time_unit) +
          (best.time != guess.format.time_unit
               ? Fmt(" (from the swing: period %.3g s", best.period_s) +
                     "; the first rows alone suggested " +
                     std::string(ToString(guess.format.time_unit)) + ")"
               : g.substr(std::min(g.size(), g.find(" ("))));
    } else if (g.rfind("gyro columns", 0) == 0) {
      g = "gyro columns " + columns + " in " + ToString(report->format.gyro_unit) + " (" +
          check.note + ")";
    }
  }
}

void SeriesStatistics(const ImuData& data, InspectReport* report) {
  report->samples = static_cast<long>(data.size());
  report->has_accel = data.has_accel();
  if (data.size() < 2) return;
  report->duration_s = data.t_s.back() - data.t_s.front();
  report->rate_mean_hz = (data.size() - 1) / report->duration_s;
  std::vector<double> steps(data.size() - 1);
  for (size_t i = 1; i < data.size(); ++i) steps[i - 1] = data.t_s[i] - data.t_s[i - 1];
  report->step_median_s = UpperMedian(steps, NAN);
  double sum = 0, sum2 = 0, longest = 0;
  int kept = 0;
  for (double s : steps) {
    longest = std::max(longest, s);
    if (s > kDropoutSteps * report->step_median_s) {
      ++report->dropouts;
      continue;
    }
    sum += s;
    sum2 += s * s;
    ++kept;
  }
  report->longest_gap_s = longest;
  if (kept > 1) {
    const double mean = sum / kept;
    report->step_jitter_s = std::sqrt(std::max(0.0, sum2 / kept - mean * mean));
  }
}

void SwingAndWindow(const ImuData& data, const CampaignConfig* config, InspectReport* report) {
  SwingAxisOptions axis_options =
      config != nullptr ? SwingAxisOptionsFor(config->imu) : SwingAxisOptions();
  // The accelerometer unit in use (guessed or declared): the advice of a reading that is not
  // gravity names the other one.
  if (report->kind == "csv") axis_options.accel_unit_si = ToSi(report->format.accel_unit);
  SwingAxis axis;
  std::string why;
  if (!EstimateSwingAxis(data, axis_options, std::nullopt, &axis, &why)) {
    if (!data.has_accel()) {
      report->error = why;  // EstimateSwingAxis says "swing axis: ..."
      return;
    }
    // An accelerometer that does not read gravity: look at the gyro alone, and say so.
    ImuData gyro_only = data;
    gyro_only.accel_in_imu.clear();
    report->warnings.push_back("accelerometer ignored: " + why);
    if (!EstimateSwingAxis(gyro_only, axis_options, std::nullopt, &axis, &why)) {
      report->error = why;  // EstimateSwingAxis says "swing axis: ..."
      return;
    }
  }
  for (int a = 0; a < 3; ++a) report->swing_axis_in_imu[a] = axis.axis_in_imu[a];
  report->swing_axis_source = ToString(axis.source);
  report->pitch_measured_deg = axis.pitch_measured_deg;
  for (const std::string& w : axis.warnings) report->warnings.push_back(w);

  WindowOptions window_options;
  if (config != nullptr) window_options.min_periods = config->fit.quality.min_periods;
  const FreeOscillationWindow window =
      FindFreeOscillationWindow(data.t_s, axis.rate_rad_per_s, window_options, report->file);
  report->window_status = ToString(window.status);
  report->noise_rad_per_s = window.noise_sigma_rad_per_s;
  if (window.period_s > 0) {
    report->period_s = window.period_s;
    report->frequency_hz = 1.0 / window.period_s;
  }
  if (!window.IsUsable()) {
    // No free oscillation (a flight log, a log of the rig at rest): no period and no pitch are
    // given, whatever the axis search made of the data; the error says what was found.
    report->error = window.message;
    report->period_s = NAN;
    report->frequency_hz = NAN;
    report->pitch_measured_deg.reset();
    return;
  }
  report->window_s = {window.t0_s, window.t1_s};
  report->window_end = ToString(window.end_reason);
  report->release_s = window.release_s;
  if (window.period_s > 0) report->cycles = window.duration_s() / window.period_s;
  const std::vector<AngleExtreme> extremes = AngleExtremes(data.t_s, axis.rate_rad_per_s, window);
  if (!extremes.empty()) {
    double hi = 0, lo = INFINITY;
    for (const AngleExtreme& e : extremes) {
      hi = std::max(hi, e.amplitude_deg);
      lo = std::min(lo, e.amplitude_deg);
    }
    report->amplitude_deg = {hi, lo};
    if (hi < 1.0) {
      report->warnings.push_back(
          Fmt("largest amplitude %.2g deg: a real swing is several deg; "
              "check the gyro unit (imu.gyro.unit)",
              hi));
    }
  }
  if (config != nullptr && report->period_s > 0) {
    const RigGeometry geometry = config->AircraftGeometry();
    report->mass_used_kg = geometry.mass_kg;
    report->small_angle_inertia_kg_m2 = InertiaFromSmallAnglePeriod(geometry, report->period_s);
  }
}

}  // namespace

InspectReport InspectLog(const std::string& path, const CampaignConfig* config,
                         const ColumnChoice& choice) {
  InspectReport report;
  report.file = path;
  std::error_code ec;
  if (!std::filesystem::exists(path, ec)) {
    report.kind = "missing";
    report.error = path + ": no such file";
    return report;
  }
  if (std::filesystem::is_directory(path, ec)) {
    report.kind = "folder";
    report.error = path + ": is a folder; give the log files inside it";
    return report;
  }
  // The caps of the config's limits, or their defaults.
  const InputLimits limits = config != nullptr ? config->limits : InputLimits();
  const ImuLogOptions log_options = limits.LogOptions();
  std::string bytes, why;
  if (!ReadRegularFile(path, LogCap(log_options.max_file_bytes), &bytes, &why)) {
    report.kind = "unreadable";
    report.error = why;
    return report;
  }
  if (bytes.empty()) {
    report.kind = "empty";
    report.error = path + ": the file is empty";
    return report;
  }
  if (LooksGzipped(bytes)) {
    std::string text;
    if (!GzipDecompress(bytes, &text, &why,
                        DecompressedLogCap(log_options.max_decompressed_bytes))) {
      report.kind = "binary";
      report.error = path + ": gzip data that cannot be read: " + why;
      return report;
    }
    report.compressed = true;
    bytes.swap(text);
  }
  try {
    ImuData data;
    if (LooksLikeDataflash(bytes) ||
        (NamedLikeDataflash(path) && ClassifyLogText(bytes) == "binary")) {
      data = ReadDataflashLog(bytes, path, config, log_options, &report);
    } else if (LooksLikeUlog(bytes)) {
      report.kind = "ulog";
      ReadUlogTopics(bytes, path, &report);
      if (config != nullptr) {
        report.format = config->imu.format;
        report.format_from_config = true;
      } else if (!GuessUlogFormat(&report)) {
        std::string list;
        for (const UlogTopicInfo& t : report.topics) list += (list.empty() ? "" : ", ") + t.topic;
        report.error = path +
                       ": a ULog file without an IMU topic bifilar knows "
                       "(sensor_combined, vehicle_angular_velocity, sensor_gyro); topics: " +
                       Abbreviated(list, 400) +
                       "; name the topic and fields in imu.ulog (configs/README.md)";
        return report;
      }
      data = ReadUlogImu(bytes, path, report.format, log_options);
    } else {
      const std::string kind = ClassifyLogText(bytes);
      const FormatGuess guess = GuessCsvFormat(bytes, choice);
      report.columns = guess.header;
      if (kind != "text" || (!guess.found && config == nullptr)) {
        report.kind = kind == "text" ? "text" : kind;
        report.error = kind == "binary"
                           ? path + ": a binary file that is neither a ULog log nor gzip"
                       : kind == "config"
                           ? path + ": a bifilar config (YAML), not a log; give it with --config"
                           : path + ": not a log that bifilar recognises: " + guess.why;
        report.columns.clear();
        return report;
      }
      report.kind = "csv";
      if (config != nullptr) {
        report.format = config->imu.format;
        report.format_from_config = true;
      } else {
        report.format = guess.format;
        report.guesses = guess.guesses;
      }
      data = ReadImuLogFromString(bytes, path, report.format, log_options);
      if (!report.format_from_config) {
        if (!guess.gyro_unit_from_names) RefineGyroUnitGuess(&data, &report);
        CheckGuessedUnits(bytes, path, log_options, guess, &data, &report);
      }
    }
    for (const std::string& w : data.warnings) report.warnings.push_back(w);
    SeriesStatistics(data, &report);
    if (!report.format_problem.empty()) {
      report.error = report.format_problem;
    } else if (report.samples >= 2) {
      SwingAndWindow(data, config, &report);
    }
  } catch (const UserError& e) {
    report.error = e.what();
  } catch (const std::exception& e) {
    report.error = path + ": " + e.what();
  }
  return report;
}

std::string InspectReportText(const InspectReport& r) {
  // Every text that holds a part of the file (names, guesses, the reader's messages) is echoed
  // through EchoedName: a header cell with an escape sequence prints as '?', not as a command to
  // the terminal.
  const auto clean = [](const std::string& text) { return EchoedName(text, 4000); };
  std::ostringstream out;
  char line[512];
  out << clean(r.file) << ": " << r.kind << (r.compressed ? " (gzip)" : "") << "\n";
  if (!r.columns.empty()) {
    out << "  columns (" << r.columns.size() << "): " << JoinedNames(r.columns) << "\n";
  }
  if (!r.topics.empty()) {
    out << "  topics (" << r.topics.size() << "):\n";
    for (const UlogTopicInfo& t : r.topics) {
      std::snprintf(line, sizeof(line), "    %-32s multi_id %d  %7ld samples",
                    clean(t.topic).c_str(), t.multi_id, t.samples);
      out << line;
      if (t.rate_hz > 0) out << Fmt("  %.1f Hz", t.rate_hz);
      out << "\n";
    }
  }
  if (!r.messages.empty()) {
    out << "  messages (" << r.messages.size() << "):\n";
    for (const DataflashMessageInfo& m : r.messages) {
      std::snprintf(line, sizeof(line), "    %-6s %8ld", clean(m.name).c_str(), m.count);
      out << line;
      if (m.rate_hz() > 0) {
        out << Fmt("  %8.1f Hz", m.rate_hz());
      } else {
        out << (m.time_field.empty() ? "  (no time field)" : "  (irregular)");
      }
      if (!m.instances.empty()) {
        out << "  instances (" << m.instance_field << "):";
        const double span_s = m.last_time_s - m.first_time_s;
        for (const auto& [instance, count] : m.instances) {
          out << " " << instance << " (" << count;
          if (m.regular() && span_s > 0 && count > 1) out << Fmt(", %.1f Hz", (count - 1) / span_s);
          out << ")";
        }
      }
      out << "\n";
    }
  }
  if (r.is_log()) {
    if (r.format_from_config) {
      out << "  format: from the config\n";
    } else {
      for (const std::string& g : r.guesses) out << "  guessed: " << clean(g) << "\n";
    }
  }
  if (r.samples >= 2) {
    std::snprintf(line, sizeof(line),
                  "  samples %ld over %.2f s: %.1f Hz mean, median step %.4g s, jitter %.2g s, "
                  "%d dropouts (longest gap %.3g s)%s\n",
                  r.samples, r.duration_s, r.rate_mean_hz, r.step_median_s,
                  std::isfinite(r.step_jitter_s) ? r.step_jitter_s : 0.0, r.dropouts,
                  r.longest_gap_s, r.has_accel ? ", accelerometer" : ", no accelerometer");
    out << line;
  }
  if (!r.swing_axis_source.empty()) {
    std::snprintf(line, sizeof(line), "  swing axis in IMU axes (%.3f, %.3f, %.3f) from %s",
                  r.swing_axis_in_imu[0], r.swing_axis_in_imu[1], r.swing_axis_in_imu[2],
                  r.swing_axis_source.c_str());
    out << line;
    if (r.pitch_measured_deg) out << Fmt(", measured pitch %.2f deg", *r.pitch_measured_deg);
    out << "\n";
  }
  if (r.window_status == "ok") {
    std::snprintf(line, sizeof(line),
                  "  free oscillation: release at %.2f s, window [%.2f, %.2f] s (%s), %.1f cycles, "
                  "amplitude %.1f -> %.1f deg\n",
                  r.release_s, r.window_s[0], r.window_s[1], r.window_end.c_str(), r.cycles,
                  r.amplitude_deg[0], r.amplitude_deg[1]);
    out << line;
  }
  if (r.is_log() && !r.window_status.empty() && r.window_status != "ok") {
    out << "  no free oscillation found: no period, frequency or pitch is given (the error below "
           "says what was found)\n";
  }
  if (std::isfinite(r.period_s)) {
    std::snprintf(line, sizeof(line), "  period %.4f s, frequency %.4f Hz, noise %.2g rad/s\n",
                  r.period_s, r.frequency_hz, r.noise_rad_per_s);
    out << line;
  }
  if (std::isfinite(r.small_angle_inertia_kg_m2)) {
    std::snprintf(line, sizeof(line),
                  "  small-angle inertia m g D^2 T^2 / (16 pi^2 L) = %#.5g kg m^2 (m = %.4g kg; "
                  "a whole-log estimate from the mean period, not the result: `bifilar fit` "
                  "gives I)\n",
                  r.small_angle_inertia_kg_m2, r.mass_used_kg);
    out << line;
  }
  for (const std::string& w : r.warnings) out << "  warning: " << clean(w) << "\n";
  if (!r.error.empty()) out << "  error: " << clean(r.error) << "\n";
  return out.str();
}

nlohmann::json InspectReportToJson(const InspectReport& r) {
  nlohmann::json j;
  j["file"] = r.file;
  j["kind"] = r.kind;
  j["compressed"] = r.compressed;
  j["columns"] = r.columns;
  nlohmann::json topics = nlohmann::json::array();
  for (const UlogTopicInfo& t : r.topics) {
    topics.push_back({{"topic", t.topic},
                      {"multi_id", t.multi_id},
                      {"samples", t.samples},
                      {"rate_hz", JsonNumber(t.rate_hz)}});
  }
  j["topics"] = topics;
  nlohmann::json messages = nlohmann::json::array();
  for (const DataflashMessageInfo& m : r.messages) {
    nlohmann::json instances = nlohmann::json::object();
    for (const auto& [instance, count] : m.instances) instances[std::to_string(instance)] = count;
    messages.push_back({{"name", m.name},
                        {"count", m.count},
                        {"rate_hz", JsonNumber(m.rate_hz())},
                        {"instance_field", m.instance_field},
                        {"instances", instances}});
  }
  j["messages"] = messages;
  if (r.is_log()) {
    nlohmann::json format;
    format["from_config"] = r.format_from_config;
    format["guesses"] = r.guesses;
    if (r.kind == "csv") {
      format["time_column"] = r.format.time_column;
      format["time_unit"] = ToString(r.format.time_unit);
      format["gyro_columns"] = r.format.gyro_columns;
      format["gyro_unit"] = ToString(r.format.gyro_unit);
      if (r.format.has_accel()) {
        format["accel_columns"] = r.format.accel_columns;
        format["accel_unit"] = ToString(r.format.accel_unit);
      } else {
        format["accel_columns"] = nullptr;
      }
      format["delimiter"] = std::string(1, r.format.delimiter);
    } else if (r.kind == "ulog") {
      format["ulog_topic"] = r.format.ulog.topic;
      format["ulog_multi_id"] = r.format.ulog.multi_id;
    }
    j["format"] = format;
  }
  j["samples"] = r.samples;
  j["duration_s"] = JsonNumber(r.duration_s);
  j["rate_mean_hz"] = JsonNumber(r.rate_mean_hz);
  j["step_median_s"] = JsonNumber(r.step_median_s);
  j["step_jitter_s"] = JsonNumber(r.step_jitter_s);
  j["dropouts"] = r.dropouts;
  j["longest_gap_s"] = JsonNumber(r.longest_gap_s);
  j["has_accel"] = r.has_accel;
  j["swing_axis_in_imu"] = r.swing_axis_source.empty()
                               ? nlohmann::json()
                               : nlohmann::json({r.swing_axis_in_imu[0], r.swing_axis_in_imu[1],
                                                 r.swing_axis_in_imu[2]});
  j["swing_axis_source"] = r.swing_axis_source;
  j["pitch_measured_deg"] =
      r.pitch_measured_deg ? nlohmann::json(*r.pitch_measured_deg) : nlohmann::json();
  j["window_status"] = r.window_status;
  j["window_s"] = {JsonNumber(r.window_s[0]), JsonNumber(r.window_s[1])};
  j["window_end"] = r.window_end;
  j["release_s"] = JsonNumber(r.release_s);
  j["period_s"] = JsonNumber(r.period_s);
  j["frequency_hz"] = JsonNumber(r.frequency_hz);
  j["cycles"] = JsonNumber(r.cycles);
  j["amplitude_deg"] = {JsonNumber(r.amplitude_deg[0]), JsonNumber(r.amplitude_deg[1])};
  j["noise_rad_per_s"] = JsonNumber(r.noise_rad_per_s);
  j["small_angle_inertia_kg_m2"] = JsonNumber(r.small_angle_inertia_kg_m2);
  j["mass_used_kg"] = JsonNumber(r.mass_used_kg);
  j["warnings"] = r.warnings;
  j["error"] = r.error;
  return j;
}

}  // namespace bifilar

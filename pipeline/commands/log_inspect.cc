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
#include "pipeline/commands/log_unit_check.h"
#include "pipeline/logs/imu_log.h"
#include "pipeline/logs/ulog.h"
#include "pipeline/trace/trace_process.h"

namespace bifilar {
namespace {

// A gyro reading whose 99th percentile exceeds this (in the file's own numbers) is taken to be
// in deg/s: a pendulum swinging 90 deg at a 0.6 s period peaks at 10 rad/s, and rigs swing at
// 1-3 s, so 12 "rad/s" is no swing, while 12 deg/s is a 4-deg swing at 2 s.
constexpr double kDegPerSGuessAbove = 12.0;
// Steps longer than this many median steps are dropouts (as the window search treats gaps).
constexpr double kDropoutSteps = 2.5;

std::string Lower(std::string s) {
  for (char& c : s) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

// `s` without surrounding white space, then without one pair of surrounding quotes ("" or '').
std::string TrimAndUnquote(const std::string& s) {
  size_t b = 0, e = s.size();
  while (b < e && std::isspace(static_cast<unsigned char>(s[b]))) ++b;
  while (e > b && std::isspace(static_cast<unsigned char>(s[e - 1]))) --e;
  std::string t = s.substr(b, e - b);
  if (t.size() >= 2 && (t.front() == '"' || t.front() == '\'') && t.back() == t.front()) {
    t = t.substr(1, t.size() - 2);
  }
  return t;
}

std::vector<std::string> SplitLine(const std::string& line, char delim) {
  std::vector<std::string> out;
  if (delim == ' ') {
    std::istringstream in(line);
    std::string cell;
    while (in >> cell) out.push_back(cell);
    return out;
  }
  std::string cell;
  for (char c : line) {
    if (c == delim) {
      out.push_back(TrimAndUnquote(cell));
      cell.clear();
    } else if (c != '\r') {
      cell += c;
    }
  }
  out.push_back(TrimAndUnquote(cell));
  return out;
}

bool IsNumber(const std::string& cell, double* value) {
  if (cell.empty()) return false;
  char* end = nullptr;
  *value = std::strtod(cell.c_str(), &end);
  return end == cell.c_str() + cell.size() && std::isfinite(*value);
}

bool IsCommentLine(const std::string& line) {
  const std::string t = TrimAndUnquote(line);
  return t.rfind("#", 0) == 0 || t.rfind("%", 0) == 0 || t.rfind("//", 0) == 0;
}

// The lines of the first `max_lines` of a text, without blank and comment lines above the header.
std::vector<std::string> HeadLines(const std::string& text, size_t max_lines) {
  std::vector<std::string> lines;
  size_t start = 0;
  if (text.compare(0, 3, "\xEF\xBB\xBF") == 0) start = 3;  // UTF-8 byte-order mark
  while (start < text.size() && lines.size() < max_lines) {
    size_t end = text.find('\n', start);
    if (end == std::string::npos) end = text.size();
    std::string line = text.substr(start, end - start);
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (!(lines.empty() && (TrimAndUnquote(line).empty() || IsCommentLine(line))))
      lines.push_back(line);
    start = end + 1;
  }
  return lines;
}

// A column name without its unit in brackets and without separators: "Gyro_X (deg/s)" ->
// "gyrox", plus the unit it names, if any.
struct ColumnName {
  std::string bare;
  std::string unit_hint;  // "deg/s", "rad/s", ""
  std::string bracket;    // the text in brackets, without digits: "ms" of "Time [ms]"
};

ColumnName Normalise(const std::string& name) {
  const std::string lower = Lower(name);
  ColumnName out;
  std::string inside;  // text in brackets
  int depth = 0;
  for (char c : lower) {
    if (c == '(' || c == '[') {
      ++depth;
      continue;
    }
    if (c == ')' || c == ']') {
      depth = std::max(0, depth - 1);
      continue;
    }
    if (depth > 0 && !(std::isdigit(static_cast<unsigned char>(c)) && inside.empty())) {
      inside += c;
    }
    if (depth > 0 && !std::isdigit(static_cast<unsigned char>(c))) continue;
    if (std::isalnum(static_cast<unsigned char>(c))) out.bare += c;
  }
  out.bracket = TrimAndUnquote(inside);
  const std::string all = lower;
  if (all.find("deg") != std::string::npos || all.find("dps") != std::string::npos) {
    out.unit_hint = "deg/s";
  } else if (all.find("rad") != std::string::npos) {
    out.unit_hint = "rad/s";
  }
  return out;
}

// The index of the column whose normalised name is `bare`, or -1.
int ColumnIndex(const std::vector<ColumnName>& names, const std::string& bare) {
  for (size_t i = 0; i < names.size(); ++i) {
    if (names[i].bare == bare) return static_cast<int>(i);
  }
  return -1;
}

// Column triplets named word + axis ("gyrox", "gyro0", "gyro1") or axis + word ("xgyro"): the
// index of each axis, or -1. `named` lists whole triplets tried after them, such as the body
// rates p, q, r.
std::array<int, 3> FindTriplet(const std::vector<ColumnName>& names,
                               const std::vector<std::string>& words,
                               const std::vector<std::array<const char*, 3>>& named = {}) {
  static const char* kAxes[][3] = {{"x", "y", "z"}, {"0", "1", "2"}, {"1", "2", "3"}};
  auto all_three = [&](auto&& name_of) {
    std::array<int, 3> idx;
    for (int a = 0; a < 3; ++a) idx[a] = ColumnIndex(names, name_of(a));
    return idx;
  };
  auto found = [](const std::array<int, 3>& idx) { return idx[0] >= 0 && idx[1] >= 0 && idx[2] >= 0; };
  for (const std::string& word : words) {
    for (const auto& axes : kAxes) {
      const std::array<int, 3> after = all_three([&](int a) { return word + axes[a]; });
      // Numbered columns with a fourth one beside them (w1..w4 motor speeds, q0..q3 a
      // quaternion) are no triplet.
      const bool numbered = std::isdigit(static_cast<unsigned char>(axes[0][0]));
      const std::string fourth = word + std::to_string(axes[2][0] - '0' + 1);
      if (found(after) && !(numbered && ColumnIndex(names, fourth) >= 0)) return after;
    }
    const std::array<int, 3> before = all_three([&](int a) { return kAxes[0][a] + word; });
    if (found(before)) return before;
  }
  for (const auto& triplet : named) {
    const std::array<int, 3> idx = all_three([&](int a) { return std::string(triplet[a]); });
    if (found(idx)) return idx;
  }
  return {-1, -1, -1};
}

// At most `max_bytes` of `s` (cut at a UTF-8 character boundary) and "…" when cut: a file's own
// text echoed in a message (a 50 MB one-line file is not echoed whole).
std::string Abbreviated(const std::string& s, size_t max_bytes = 80) {
  if (s.size() <= max_bytes) return s;
  size_t cut = max_bytes;
  while (cut > 0 && (static_cast<unsigned char>(s[cut]) & 0xC0) == 0x80) --cut;
  return s.substr(0, cut) + "\u2026 (" + std::to_string(s.size()) + " bytes)";
}

// A name of the file's own echoed in a message or on the terminal (EchoedName,
// pipeline/logs/imu_format.h: escape sequences and line breaks as '?', at most 80 bytes).
std::string PrintableName(const std::string& name) { return EchoedName(name, 80); }

// Names joined with ", ", at most 400 bytes of them (a header of thousands of columns is cut),
// each made printable.
std::string JoinedNames(const std::vector<std::string>& names) {
  std::string list;
  size_t shown = 0;
  for (; shown < names.size() && list.size() <= 400; ++shown) {
    list += (list.empty() ? "" : ", ") + PrintableName(names[shown]);
  }
  list = Abbreviated(list, 400);
  if (shown < names.size()) list += " and " + std::to_string(names.size() - shown) + " more";
  return list;
}

// Delimiter: the one that splits the header into the most cells, consistently with row 2.
char GuessDelimiter(const std::vector<std::string>& lines) {
  char delim = ',';
  size_t best = 1;
  for (char d : {',', ';', '\t', ' '}) {
    const size_t n = SplitLine(lines[0], d).size();
    if (n > best && (lines.size() < 2 || SplitLine(lines[1], d).size() == n)) {
      best = n;
      delim = d;
    }
  }
  return delim;
}

// Numeric rows below the header, column by column (up to the first row of another width).
std::vector<std::vector<double>> NumericColumns(const std::vector<std::string>& lines, char delim,
                                                size_t width) {
  std::vector<std::vector<double>> columns(width);
  for (size_t r = 1; r < lines.size(); ++r) {
    const std::vector<std::string> cells = SplitLine(lines[r], delim);
    if (cells.size() != width) break;
    for (size_t c = 0; c < cells.size(); ++c) {
      double v = 0;
      if (IsNumber(cells[c], &v)) columns[c].push_back(v);
    }
  }
  return columns;
}

// Time column: a known name, else the first whose name holds "time"; -1 when none.
int GuessTimeColumn(const std::vector<ColumnName>& names) {
  int time = -1;
  for (const char* n : {"t", "time", "times", "ts", "timestamp", "timeus", "timems",
                        "timestampus", "timestampms", "sec", "seconds", "elapsed"}) {
    for (size_t i = 0; i < names.size() && time < 0; ++i) {
      if (names[i].bare == n) time = static_cast<int>(i);
    }
  }
  for (size_t i = 0; i < names.size() && time < 0; ++i) {
    if (names[i].bare.find("time") != std::string::npos) time = static_cast<int>(i);
  }
  return time;
}

// Time unit: from the name (`tname`, normalised), else from the median step of the first rows.
void GuessTimeUnit(const ColumnName& name, const std::vector<double>& tc, FormatGuess* guess) {
  const std::string& tname = name.bare;
  std::vector<double> steps;
  for (size_t i = 1; i < tc.size(); ++i) {
    if (tc[i] > tc[i - 1]) steps.push_back(tc[i] - tc[i - 1]);
  }
  const double step = UpperMedian(steps, NAN);
  std::string time_why;
  const std::string& unit = name.bracket;
  if (unit == "s" || unit == "sec" || unit == "ms" || unit == "us" || unit == "\u00b5s") {
    guess->format.time_unit = unit == "ms"   ? TimeUnit::kMilliseconds
                              : unit == "us" || unit == "\u00b5s" ? TimeUnit::kMicroseconds
                                                                : TimeUnit::kSeconds;
    time_why = "from its name";
  } else if (tname.size() > 2 && tname.compare(tname.size() - 2, 2, "us") == 0) {
    guess->format.time_unit = TimeUnit::kMicroseconds;
    guess->time_unit_from_names = true;
    time_why = "from its name";
  } else if (tname.size() > 2 && tname.compare(tname.size() - 2, 2, "ms") == 0) {
    guess->format.time_unit = TimeUnit::kMilliseconds;
    guess->time_unit_from_names = true;
    time_why = "from its name";
  } else if (std::isfinite(step)) {
    // IMU logs are sampled at 1 Hz - 2 kHz: a median step above 0.5 s is not seconds.
    guess->format.time_unit = step < 0.5     ? TimeUnit::kSeconds
                              : step < 500.0 ? TimeUnit::kMilliseconds
                                             : TimeUnit::kMicroseconds;
    time_why = Fmt("from its median step, %.4g", step);
  } else {
    time_why = "default, no steps to judge by";
  }
  guess->guesses.push_back("time column '" + PrintableName(guess->format.time_column) + "' in " +
                           ToString(guess->format.time_unit) + " (" + time_why + ")");
}

// Gyro unit: from the names, else from the size of the readings.
void GuessGyroUnit(const std::vector<ColumnName>& names, const std::array<int, 3>& gyro,
                   const std::vector<std::vector<double>>& columns, FormatGuess* guess) {
  std::string hint;
  for (int a = 0; a < 3; ++a) {
    if (!names[gyro[a]].unit_hint.empty()) hint = names[gyro[a]].unit_hint;
  }
  std::vector<double> magnitudes;
  for (int a = 0; a < 3; ++a) {
    for (double v : columns[gyro[a]]) magnitudes.push_back(std::fabs(v));
  }
  std::sort(magnitudes.begin(), magnitudes.end());
  const double p99 = magnitudes.empty() ? NAN : magnitudes[magnitudes.size() * 99 / 100];
  std::string gyro_why;
  if (!hint.empty()) {
    ParseRateUnit(hint, &guess->format.gyro_unit);
    guess->gyro_unit_from_names = true;
    gyro_why = "from the column names";
  } else if (std::isfinite(p99)) {
    guess->format.gyro_unit = p99 > kDegPerSGuessAbove ? RateUnit::kDegPerS : RateUnit::kRadPerS;
    gyro_why = Fmt("from the readings: 99th percentile of |rate| %.3g", p99) +
               (p99 > kDegPerSGuessAbove ? " is no pendulum in rad/s" : "");
  } else {
    gyro_why = "default";
  }
  guess->guesses.push_back("gyro columns " + PrintableName(guess->format.gyro_columns[0]) + ", " +
                           PrintableName(guess->format.gyro_columns[1]) + ", " +
                           PrintableName(guess->format.gyro_columns[2]) +
                           " in " + ToString(guess->format.gyro_unit) + " (" + gyro_why + ")");
}

// Accelerometer unit: gravity reads ~9.8 in m/s^2, ~1 in g.
void GuessAccelUnit(const std::array<int, 3>& accel,
                    const std::vector<std::vector<double>>& columns, FormatGuess* guess) {
  std::vector<double> norms;
  const size_t n = std::min({columns[accel[0]].size(), columns[accel[1]].size(),
                             columns[accel[2]].size()});
  for (size_t i = 0; i < n; ++i) {
    norms.push_back(std::hypot(columns[accel[0]][i], columns[accel[1]][i], columns[accel[2]][i]));
  }
  const double norm = UpperMedian(norms, NAN);
  guess->format.accel_unit =
      std::isfinite(norm) && norm < 3.0 ? AccelUnit::kStandardGravity : AccelUnit::kMetresPerS2;
  // Gravity reads 1 in g and 9.81 in m/s^2; a reading far from both (gravity removed by the
  // logger, another unit) is no ground for g: m/s^2 is kept, and the guess says so.
  const bool gravity_in_g = std::isfinite(norm) && std::abs(norm - 1.0) <= 0.3;
  const bool gravity_in_si = std::isfinite(norm) && std::abs(norm / kStandardGravityMps2 - 1.0) <= 0.3;
  if (!gravity_in_g && !gravity_in_si) guess->format.accel_unit = AccelUnit::kMetresPerS2;
  guess->guesses.push_back("accelerometer columns " + PrintableName(guess->format.accel_columns[0]) + ", " +
                           PrintableName(guess->format.accel_columns[1]) + ", " +
                           PrintableName(guess->format.accel_columns[2]) +
                           " in " + ToString(guess->format.accel_unit) +
                           (std::isfinite(norm) ? Fmt(" (median |f| %.3g", norm) +
                                                      (gravity_in_g || gravity_in_si
                                                           ? std::string(")")
                                                           : ": neither 1 g nor 9.81 m/s^2, "
                                                             "gravity removed by the logger or "
                                                             "another unit; check imu.accel.unit)")
                                                : ""));
}

}  // namespace

namespace {

// The index of the header cell named `name` (surrounding blanks and quotes aside): the cell of
// exactly that name, else the one cell equal to it ignoring case; -1 when none (or when several
// cells equal it ignoring case and none exactly: `bifilar fit` reads names as written, so a
// case-insensitive guess between GX and gx would read other columns than the user named).
int HeaderIndex(const std::vector<std::string>& header, const std::string& name,
                std::vector<std::string>* ambiguous = nullptr) {
  const std::string wanted = TrimAndUnquote(name);
  std::vector<int> folded;
  for (size_t i = 0; i < header.size(); ++i) {
    const std::string cell = TrimAndUnquote(header[i]);
    if (cell == wanted) return static_cast<int>(i);
    if (Lower(cell) == Lower(wanted)) folded.push_back(static_cast<int>(i));
  }
  if (folded.size() == 1) return folded[0];
  if (ambiguous != nullptr) {
    for (int i : folded) ambiguous->push_back(TrimAndUnquote(header[i]));
  }
  return -1;
}

// The columns the user named (ColumnChoice) are in the header, each once; otherwise false and
// why (a name that matches several cells only ignoring case names them).
bool ChosenColumnsPresent(const std::vector<std::string>& header, const ColumnChoice& choice,
                          std::string* why) {
  std::vector<std::string> wanted;
  if (!choice.time.empty()) wanted.push_back(choice.time);
  for (const std::string& g : choice.gyro) {
    if (!g.empty()) wanted.push_back(g);
  }
  for (const std::string& w : wanted) {
    std::vector<std::string> candidates;
    if (HeaderIndex(header, w, &candidates) >= 0) continue;
    if (!candidates.empty()) {
      std::string list;
      for (const std::string& c : candidates) list += (list.empty() ? "'" : "', '") + PrintableName(c);
      *why = "column '" + PrintableName(w) + "' is ambiguous: no column is named exactly so, and " +
             std::to_string(candidates.size()) + " differ from it only in case (" + list +
             "'); name one of them as it is written";
      return false;
    }
    *why = "no column '" + PrintableName(w) + "' among the " + std::to_string(header.size()) +
           " column(s) of the first line: " + JoinedNames(header);
    return false;
  }
  return true;
}

}  // namespace

std::string UnrecognisedColumnsMessage(const std::vector<std::string>& header,
                                       const std::string& what) {
  return "no " + what + " recognised among the " + std::to_string(header.size()) +
         " column(s) of the first line: " + JoinedNames(header) +
         ". Name them in the config (imu.time: {column: T, unit: s|ms|us}, imu.gyro: {columns: "
         "[X, Y, Z], unit: rad/s|deg/s}), or let bifilar write that config: bifilar init --log "
         "LOG --time T --gyro X,Y,Z --rig L,D,MASS (units are still guessed from the data)";
}

// GuessDelimiter -> NumericColumns -> GuessTimeColumn (and the gyro and accelerometer triplets)
// -> GuessTimeUnit -> GuessGyroUnit -> GuessAccelUnit.
FormatGuess GuessCsvFormat(const std::string& text, const ColumnChoice& choice) {
  FormatGuess guess;
  const std::vector<std::string> lines = HeadLines(text, 400);
  if (lines.empty()) {
    guess.why = "no header line";
    return guess;
  }
  const char delim = GuessDelimiter(lines);
  guess.format.delimiter = delim;
  const std::vector<std::string> header = SplitLine(lines[0], delim);
  std::vector<ColumnName> names;
  for (const std::string& h : header) names.push_back(Normalise(h));
  const std::vector<std::vector<double>> columns = NumericColumns(lines, delim, header.size());
  if (!ChosenColumnsPresent(header, choice, &guess.why)) return guess;
  const int time = choice.time.empty() ? GuessTimeColumn(names) : HeaderIndex(header, choice.time);
  const std::array<int, 3> gyro =
      choice.gyro[0].empty()
          ? FindTriplet(names,
                        {"g", "gyro", "gyr", "w", "omega", "rate", "gyrorad", "angvel",
                         "angularvelocity", "angularrate", "gyroscope", "bodyrate", "wb"},
                        {{"p", "q", "r"}, {"rollrate", "pitchrate", "yawrate"}})
          : std::array<int, 3>{HeaderIndex(header, choice.gyro[0]),
                               HeaderIndex(header, choice.gyro[1]),
                               HeaderIndex(header, choice.gyro[2])};
  const std::array<int, 3> accel = FindTriplet(
      names, {"a", "acc", "accel", "accelerometer", "accelerometerms2", "acceleration", "f",
              "specificforce", "linacc"});
  if (time < 0 || gyro[0] < 0) {
    guess.why = UnrecognisedColumnsMessage(header, time < 0 ? "time column" : "gyro columns");
    return guess;
  }
  guess.found = true;
  guess.format.time_column = TrimAndUnquote(header[time]);
  for (int a = 0; a < 3; ++a) guess.format.gyro_columns[a] = TrimAndUnquote(header[gyro[a]]);
  if (accel[0] >= 0) {
    for (int a = 0; a < 3; ++a) guess.format.accel_columns[a] = TrimAndUnquote(header[accel[a]]);
  } else {
    guess.format.accel_columns = {"", "", ""};
  }
  GuessTimeUnit(names[time], columns[time], &guess);
  GuessGyroUnit(names, gyro, columns, &guess);
  if (accel[0] >= 0) {
    GuessAccelUnit(accel, columns, &guess);
  } else {
    guess.guesses.push_back("no accelerometer columns (gyro-only: the swing axis from the gyro)");
  }
  if (delim != ',') {
    guess.guesses.push_back(std::string("delimiter '") + (delim == '\t' ? "\\t" : std::string(1, delim)) + "'");
  }
  return guess;
}

namespace {

// What a file that is not a log looks like.
std::string ClassifyText(const std::string& text) {
  const size_t n = std::min<size_t>(text.size(), 4096);
  size_t odd = 0;
  for (size_t i = 0; i < n; ++i) {
    const unsigned char c = static_cast<unsigned char>(text[i]);
    if (c == 0) return "binary";
    if (c < 32 && c != '\n' && c != '\r' && c != '\t') ++odd;
  }
  if (odd * 20 > n) return "binary";
  for (const std::string& line : HeadLines(text, 40)) {
    const std::string t = TrimAndUnquote(line);
    for (const char* key : {"rig:", "imu:", "runs:", "aircraft:", "fit:", "filar_length_m"}) {
      if (t.rfind(key, 0) == 0) return "config";
    }
  }
  return "text";
}

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
    if (s.samples > 1 && std::isfinite(s.first_timestamp_us) && std::isfinite(s.last_timestamp_us)) {
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
    report->guesses.push_back("ArduPilot DataFlash log: gyro in rad/s and accelerometer in m/s^2 "
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
                 "pendulum in rad/s)", p99);
    }
  }
}

// The guessed time and gyro units checked against the swing (pipeline/commands/log_unit_check.h):
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
                             check.angles + "); bifilar needs the gyro's rates: name those "
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
          (best.time != guess.format.time_unit ? Fmt(" (from the swing: period %.3g s", best.period_s) +
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
      report->warnings.push_back(Fmt("largest amplitude %.2g deg: a real swing is several deg; "
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
    if (!GzipDecompress(bytes, &text, &why, DecompressedLogCap(log_options.max_decompressed_bytes))) {
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
        (NamedLikeDataflash(path) && ClassifyText(bytes) == "binary")) {
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
        report.error = path + ": a ULog file without an IMU topic bifilar knows "
                       "(sensor_combined, vehicle_angular_velocity, sensor_gyro); topics: " +
                       Abbreviated(list, 400) +
                       "; name the topic and fields in imu.ulog (configs/README.md)";
        return report;
      }
      data = ReadUlogImu(bytes, path, report.format, log_options);
    } else {
      const std::string kind = ClassifyText(bytes);
      const FormatGuess guess = GuessCsvFormat(bytes, choice);
      const std::vector<std::string> head = HeadLines(bytes, 1);
      if (!head.empty()) {
        for (const std::string& c : SplitLine(head[0], guess.format.delimiter)) {
          report.columns.push_back(c);
        }
      }
      if (kind != "text" || (!guess.found && config == nullptr)) {
        report.kind = kind == "text" ? "text" : kind;
        report.error = kind == "binary" ? path + ": a binary file that is neither a ULog log nor gzip"
                       : kind == "config" ? path + ": a bifilar config (YAML), not a log; give it with --config"
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
      std::snprintf(line, sizeof(line), "    %-32s multi_id %d  %7ld samples", clean(t.topic).c_str(),
                    t.multi_id, t.samples);
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
  j["pitch_measured_deg"] = r.pitch_measured_deg ? nlohmann::json(*r.pitch_measured_deg)
                                                 : nlohmann::json();
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

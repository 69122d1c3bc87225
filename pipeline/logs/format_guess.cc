// The format of a log guessed from its own bytes: GuessCsvFormat (GuessDelimiter ->
// NumericColumns -> GuessTimeColumn and the triplets -> GuessTimeUnit -> GuessGyroUnit ->
// GuessAccelUnit) and ClassifyLogText (format_guess.h). Moved from pipeline/commands/log_inspect.cc
// (issue 36): inspect presents the guess, logs/ makes it.
#include "pipeline/logs/format_guess.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstdlib>

#include "base/csv.h"
#include "base/statistics.h"
#include "base/text_format.h"
#include "base/units.h"
#include "pipeline/logs/log_line.h"

namespace bifilar {
namespace {

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

// A header or row cut as the log reader cuts it (pipeline/logs/log_line.h), so that the columns
// the guess names are the ones the reader finds.
std::vector<std::string> SplitLine(const std::string& line, char delim) {
  return LogLineCells(line, delim);
}

// The whole cell as a finite number (base/csv.h), as the reader reads it.
bool IsNumber(const std::string& cell, double* value) { return ParseNumber(cell, value); }

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
  auto found = [](const std::array<int, 3>& idx) {
    return idx[0] >= 0 && idx[1] >= 0 && idx[2] >= 0;
  };
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

// A name of the file's own echoed in a message or on the terminal (EchoedName,
// pipeline/logs/imu_format.h: escape sequences and line breaks as '?', at most 80 bytes).
std::string PrintableName(const std::string& name) { return EchoedName(name, 80); }

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
  for (const char* n : {"t", "time", "times", "ts", "timestamp", "timeus", "timems", "timestampus",
                        "timestampms", "sec", "seconds", "elapsed"}) {
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
    guess->format.time_unit = unit == "ms"                        ? TimeUnit::kMilliseconds
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
                           PrintableName(guess->format.gyro_columns[2]) + " in " +
                           ToString(guess->format.gyro_unit) + " (" + gyro_why + ")");
}

// Accelerometer unit: gravity reads ~9.8 in m/s^2, ~1 in g.
void GuessAccelUnit(const std::array<int, 3>& accel,
                    const std::vector<std::vector<double>>& columns, FormatGuess* guess) {
  std::vector<double> norms;
  const size_t n =
      std::min({columns[accel[0]].size(), columns[accel[1]].size(), columns[accel[2]].size()});
  for (size_t i = 0; i < n; ++i) {
    norms.push_back(std::hypot(columns[accel[0]][i], columns[accel[1]][i], columns[accel[2]][i]));
  }
  const double norm = UpperMedian(norms, NAN);
  guess->format.accel_unit =
      std::isfinite(norm) && norm < 3.0 ? AccelUnit::kStandardGravity : AccelUnit::kMetresPerS2;
  // Gravity reads 1 in g and 9.81 in m/s^2; a reading far from both (gravity removed by the
  // logger, another unit) is no ground for g: m/s^2 is kept, and the guess says so.
  const bool gravity_in_g = std::isfinite(norm) && std::abs(norm - 1.0) <= 0.3;
  const bool gravity_in_si =
      std::isfinite(norm) && std::abs(norm / kStandardGravityMps2 - 1.0) <= 0.3;
  if (!gravity_in_g && !gravity_in_si) guess->format.accel_unit = AccelUnit::kMetresPerS2;
  guess->guesses.push_back(
      "accelerometer columns " + PrintableName(guess->format.accel_columns[0]) + ", " +
      PrintableName(guess->format.accel_columns[1]) + ", " +
      PrintableName(guess->format.accel_columns[2]) + " in " + ToString(guess->format.accel_unit) +
      (std::isfinite(norm)
           ? Fmt(" (median |f| %.3g", norm) + (gravity_in_g || gravity_in_si
                                                   ? std::string(")")
                                                   : ": neither 1 g nor 9.81 m/s^2, "
                                                     "gravity removed by the logger or "
                                                     "another unit; check imu.accel.unit)")
           : ""));
}

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
      for (const std::string& c : candidates)
        list += (list.empty() ? "'" : "', '") + PrintableName(c);
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

std::string Abbreviated(const std::string& s, size_t max_bytes) {
  if (s.size() <= max_bytes) return s;
  size_t cut = max_bytes;
  while (cut > 0 && (static_cast<unsigned char>(s[cut]) & 0xC0) == 0x80) --cut;
  return s.substr(0, cut) + "\u2026 (" + std::to_string(s.size()) + " bytes)";
}

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
  guess.header = header;
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
  const std::array<int, 3> accel =
      FindTriplet(names, {"a", "acc", "accel", "accelerometer", "accelerometerms2", "acceleration",
                          "f", "specificforce", "linacc"});
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
    guess.guesses.push_back(std::string("delimiter '") +
                            (delim == '\t' ? "\\t" : std::string(1, delim)) + "'");
  }
  return guess;
}

std::string ClassifyLogText(const std::string& text) {
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

}  // namespace bifilar

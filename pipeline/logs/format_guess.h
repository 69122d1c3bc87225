// The format of a log guessed from its own bytes (issue 36: logs/ owns every format guess): a
// CSV's delimiter, time, gyro and accelerometer columns and their units from the header and the
// first rows (GuessCsvFormat), and what a file that is no log looks like (ClassifyLogText).
// `bifilar inspect` and `init` (pipeline/commands/log_inspect.h) present the guess and check its
// units against the whole swing; `bifilar watch` guesses a stream's columns with it.
#pragma once

#include <array>
#include <string>
#include <vector>

#include "pipeline/logs/imu_format.h"

namespace bifilar {

// A gyro reading whose 99th percentile exceeds this (in the file's own numbers) is taken to be
// in deg/s: a pendulum swinging 90 deg at a 0.6 s period peaks at 10 rad/s, and rigs swing at
// 1-3 s, so 12 "rad/s" is no swing, while 12 deg/s is a 4-deg swing at 2 s.
constexpr double kDegPerSGuessAbove = 12.0;

// The log format guessed from a file's own bytes (a CSV header and its first rows, or a ULog's
// topics). `found` is false when no time or gyro column could be identified; `why` says what is
// missing and `guesses` what was seen.
struct FormatGuess {
  bool found = false;
  std::string why;
  ImuFormat format;
  std::vector<std::string> guesses;  // "time column 't' in s (median step 0.04 s)", ...
  // The gyro unit came from the column names; otherwise it is a guess from the first rows,
  // which InspectLog checks against the whole series.
  bool gyro_unit_from_names = false;
  bool time_unit_from_names = false;  // the time unit came from the column's name ("TimeUS")
  std::vector<std::string> header;    // the first line's cells, split as the guess split them
};

// Columns the user names (`bifilar init --time COL --gyro X,Y,Z`) instead of the guess; their
// units are still guessed from the data. Empty: guess.
struct ColumnChoice {
  std::string time;
  std::array<std::string, 3> gyro;
};

// Guesses the format of a CSV text from its header and first rows. Recognised, ignoring case,
// separators and a unit in brackets: time as t, time, timestamp, TimeUS, TimeMS, "Time [ms]"
// (or any name holding "time"); gyro and accelerometer triplets as word + axis (GyroX, gyr_x,
// gyro[0], AngVelX) or axis + word (xGyro, ZGyro, xAcc), and the body rates p, q, r or
// roll_rate, pitch_rate, yaw_rate. `choice` names columns instead.
FormatGuess GuessCsvFormat(const std::string& text, const ColumnChoice& choice = {});

// The message when no time or gyro columns are found (`what`): the columns, the config keys to
// write, and the `bifilar init` command that writes them.
std::string UnrecognisedColumnsMessage(const std::vector<std::string>& header,
                                       const std::string& what);

// What a text that is not a log looks like: "binary" (a NUL byte, or over 5 % control bytes in
// its first 4 KiB), "config" (a line of its first 40 starts like a bifilar YAML config), else
// "text".
std::string ClassifyLogText(const std::string& text);

// Names joined with ", ", at most 400 bytes of them (a header of thousands of columns is cut),
// each made printable (EchoedName): a file's own names in a message.
std::string JoinedNames(const std::vector<std::string>& names);

// At most `max_bytes` of `s` (cut at a UTF-8 character boundary) and "…" when cut: a file's own
// text echoed in a message (a 50 MB one-line file is not echoed whole).
std::string Abbreviated(const std::string& s, size_t max_bytes = 80);

}  // namespace bifilar

#include "pipeline/logs/imu_log.h"

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <limits>
#include <string_view>
#include <system_error>
#include <vector>

#include "base/csv.h"
#include "base/gzip.h"
#include "base/text_format.h"
#include "base/user_error.h"
#include "pipeline/logs/dataflash.h"
#include "pipeline/logs/imu_log_finish.h"
#include "pipeline/logs/log_line.h"
#include "pipeline/logs/simulated_log.h"
#include "pipeline/logs/ulog.h"

namespace bifilar {
namespace {

bool IsBlank(std::string_view line) { return TrimLogCell(line).empty(); }

// Parses one whole cell as a number (base/csv.h's ParseNumber, fast_float inside): surrounding
// spaces and quotes allowed; infinity and NaN are read, and ReadRowCells names them.
bool ParseCell(std::string_view cell, double* value) {
  return ParseNumber(UnquoteLogCell(cell), value, NonFinite::kAccept);
}

// A cell or a name of the file's echoed in a message (EchoedName, pipeline/logs/imu_format.h).
std::string Printable(std::string_view s, size_t max_len = 40) { return EchoedName(s, max_len); }

std::string ListColumns(const std::vector<std::string>& names) {
  std::string out;
  for (size_t i = 0; i < names.size(); ++i) {
    if (i) out += ", ";
    out += "'" + Printable(names[i]) + "'";
  }
  return out.empty() ? "none" : out;
}

// Iterates the lines of a text buffer: line numbers from 1, '\r' left for Trim to remove.
class LineReader {
 public:
  explicit LineReader(std::string_view text) : text_(text) {}
  bool Next(std::string_view* line) {
    if (pos_ >= text_.size()) return false;
    const void* nl = std::memchr(text_.data() + pos_, '\n', text_.size() - pos_);
    const size_t end = nl ? static_cast<const char*>(nl) - text_.data() : text_.size();
    *line = text_.substr(pos_, end - pos_);
    if (!line->empty() && line->back() == '\r') line->remove_suffix(1);
    pos_ = end + 1;
    ++line_number_;
    return true;
  }
  int line_number() const { return line_number_; }

 private:
  std::string_view text_;
  size_t pos_ = 0;
  int line_number_ = 0;
};

// Non-blank lines the reader has not yet returned (consumes them): the rows after the end of the
// time series, for the warning.
int CountNonBlankLinesLeft(LineReader* reader) {
  int count = 0;
  std::string_view line;
  while (reader->Next(&line)) count += IsBlank(line) ? 0 : 1;
  return count;
}

[[noreturn]] void Fail(const std::string& message) { throw UserError(message); }

// True when the file name ends in .ulg or .ulg.gz (any case).
bool NamedLikeUlog(const std::string& path) {
  std::string lower = path;
  for (char& c : lower) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  auto ends_with = [&](const std::string& suffix) {
    return lower.size() >= suffix.size() &&
           lower.compare(lower.size() - suffix.size(), suffix.size(), suffix) == 0;
  };
  return ends_with(".ulg") || ends_with(".ulg.gz");
}

// ArduPilot DataFlash (pipeline/logs/dataflash.h) with imu.format auto: a file that starts with
// the FMT header. A .bin that does not is tried by ReadBin.
bool UseDataflashReader(std::string_view text, const ImuFormat& format) {
  return format.container == LogContainer::kAuto && LooksLikeDataflash(text);
}

// The first bytes of `text` for a message: printable ASCII quoted, anything else as hex.
std::string DescribeStart(std::string_view text) {
  if (text.empty()) return "nothing: the file is empty";
  std::string out;
  const size_t n = std::min<size_t>(text.size(), 8);
  bool printable = true;
  for (size_t i = 0; i < n; ++i) printable = printable && text[i] >= 32 && text[i] < 127;
  if (printable) return "\"" + std::string(text.substr(0, n)) + "\"";
  char hex[4];
  for (size_t i = 0; i < n; ++i) {
    std::snprintf(hex, sizeof(hex), "%s%02x", i ? " " : "", static_cast<unsigned char>(text[i]));
    out += hex;
  }
  return "the bytes " + out;
}

// Strips a UTF-8 byte-order mark from *text; fails on an empty file and on binary data (any NUL
// byte, or more than 1 % control characters in the first 64 KiB).
void RefuseBinary(const std::string& name, const ImuFormat& format, std::string_view* text) {
  if (text->size() >= 3 && static_cast<unsigned char>((*text)[0]) == 0xEF &&
      static_cast<unsigned char>((*text)[1]) == 0xBB &&
      static_cast<unsigned char>((*text)[2]) == 0xBF) {
    text->remove_prefix(3);  // UTF-8 byte-order mark
  }
  if (IsBlank(*text) || text->find_first_not_of(" \t\r\n") == std::string_view::npos) {
    Fail(name + ": the file is empty (expected a CSV header with columns " +
         Printable(format.time_column) + ", " + Printable(format.gyro_columns[0]) + ", ...)");
  }
  if (const void* nul = std::memchr(text->data(), '\0', text->size())) {
    Fail(name + ": not a text CSV file (binary data at byte " +
         std::to_string(static_cast<const char*>(nul) - text->data()) + ")");
  }
  const size_t n = std::min<size_t>(text->size(), 65536);
  size_t control = 0;
  for (size_t i = 0; i < n; ++i) {
    const unsigned char c = (*text)[i];
    if (c < 32 && c != '\n' && c != '\r' && c != '\t' &&
        c != static_cast<unsigned char>(format.delimiter))
      ++control;
  }
  if (control * 100 > n)
    Fail(name + ": not a text CSV file (" + std::to_string(control) +
         " control characters in the first " + std::to_string(n) + " bytes)");
}

// The columns a CSV log is read from: the needed ones (time, gyro x y z, then accel x y z when
// read) with their names, SI scale and field index, and the header's line.
struct CsvColumns {
  int header_line = 0;
  std::vector<std::string> names;
  std::vector<double> scale;
  std::vector<int> column;
  bool with_accel = false;
  int needed = 0;      // column.size()
  int max_column = 0;  // the largest field index a data row must reach
};

// The header row: the first non-blank line that is not a comment ('#', '%' or '//' first: logger
// metadata above the header is common), unquoted; the simulated-log mark and the comments
// skipped become warnings of *data.
std::vector<std::string> ReadHeaderRow(LineReader* reader, const std::string& name,
                                       const ImuFormat& format, int* header_line, ImuData* data) {
  std::string_view line;
  int comment_lines = 0;
  std::string simulated;  // the mark of `bifilar simulate` (pipeline/logs/simulated_log.h)
  while (reader->Next(&line)) {
    const std::string_view trimmed = TrimLogCell(line);
    if (trimmed.empty()) continue;
    if (simulated.empty() && ParseSimulatedCsvMarker(trimmed, &simulated)) continue;
    if (trimmed[0] == '#' || trimmed[0] == '%' || trimmed.substr(0, 2) == "//") {
      ++comment_lines;
      continue;
    }
    break;
  }
  *header_line = reader->line_number();
  if (IsBlank(line) || TrimLogCell(line)[0] == '#' || TrimLogCell(line)[0] == '%' ||
      TrimLogCell(line).substr(0, 2) == "//") {
    Fail(name + ": no header row, only " + std::to_string(comment_lines) + " comment line(s)");
  }
  if (!simulated.empty()) data->warnings.push_back(simulated);
  if (comment_lines > 0) {
    data->warnings.push_back("skipped " + std::to_string(comment_lines) +
                             " comment line(s) before the header");
  }
  std::vector<std::string_view> fields;
  SplitLogLine(line, format.delimiter, &fields);
  std::vector<std::string> header;
  for (auto f : fields) header.emplace_back(UnquoteLogCell(f));
  bool all_numeric = true;
  double v;
  for (auto f : fields) all_numeric = all_numeric && ParseCell(f, &v);
  if (all_numeric) {
    Fail(name + ":" + std::to_string(*header_line) +
         ": no header row (the first line holds numbers); expected a header naming the columns " +
         Printable(format.time_column) + ", " + Printable(format.gyro_columns[0]) + ", " +
         Printable(format.gyro_columns[1]) + ", " + Printable(format.gyro_columns[2]) +
         (format.has_accel() ? ", ..." : ""));
  }
  return header;
}

// The index of column `col` in `header`, -1 when absent; fails when it appears twice.
int FindColumn(const std::vector<std::string>& header, const std::string& col,
               const std::string& name, int header_line) {
  int found = -1;
  for (size_t i = 0; i < header.size(); ++i) {
    if (header[i] == col) {
      if (found >= 0) {
        Fail(name + ":" + std::to_string(header_line) + ": column '" + Printable(col) +
             "' appears twice in the header (columns " + std::to_string(found + 1) + " and " +
             std::to_string(i + 1) + ")");
      }
      found = static_cast<int>(i);
    }
  }
  return found;
}

// Fails on a missing column, guessing the delimiter when the header is one field.
[[noreturn]] void MissingColumn(const std::vector<std::string>& header, const std::string& col,
                                const std::string& name, int header_line, const ImuFormat& format) {
  std::string hint;
  if (header.size() == 1) {
    for (char d : {',', ';', '\t', ' '}) {
      if (d != format.delimiter && header[0].find(d) != std::string::npos) {
        hint = std::string("; is the delimiter '") +
               (d == '\t' ? std::string("\\t") : std::string(1, d)) + "' rather than '" +
               std::string(1, format.delimiter) + "'?";
        break;
      }
    }
  }
  Fail(name + ":" + std::to_string(header_line) + ": missing column '" + Printable(col) +
       "' (columns found: " + ListColumns(header) + hint + ")");
}

// The header row and the columns the format names in it (accelerometer columns absent altogether:
// gyro-only with a warning, unless options.require_accel).
CsvColumns ParseHeader(LineReader* reader, const std::string& name, const ImuFormat& format,
                       const ImuLogOptions& options, ImuData* data) {
  CsvColumns c;
  const std::vector<std::string> header = ReadHeaderRow(reader, name, format, &c.header_line, data);
  c.names = {format.time_column, format.gyro_columns[0], format.gyro_columns[1],
             format.gyro_columns[2]};
  c.scale = {ToSi(format.time_unit), ToSi(format.gyro_unit), ToSi(format.gyro_unit),
             ToSi(format.gyro_unit)};
  for (const auto& n : c.names) {
    const int col = FindColumn(header, n, name, c.header_line);
    if (col < 0) MissingColumn(header, n, name, c.header_line, format);
    c.column.push_back(col);
  }
  if (format.has_accel()) {
    int present = 0;
    std::array<int, 3> accel_col;
    for (int k = 0; k < 3; ++k) {
      accel_col[k] = FindColumn(header, format.accel_columns[k], name, c.header_line);
      present += accel_col[k] >= 0;
    }
    if (present == 0 && !options.require_accel) {
      data->warnings.push_back("no accelerometer columns (" + Printable(format.accel_columns[0]) +
                               ", " + Printable(format.accel_columns[1]) + ", " +
                               Printable(format.accel_columns[2]) +
                               ") in the file; read as gyro-only");
    } else {
      for (int k = 0; k < 3; ++k) {
        if (accel_col[k] < 0)
          MissingColumn(header, format.accel_columns[k], name, c.header_line, format);
        c.names.push_back(format.accel_columns[k]);
        c.scale.push_back(ToSi(format.accel_unit));
        c.column.push_back(accel_col[k]);
      }
      c.with_accel = true;
    }
  }
  c.needed = static_cast<int>(c.column.size());
  for (int col : c.column) c.max_column = std::max(c.max_column, col);
  return c;
}

// One data row's needed cells into row[] (raw units). Returns the error of a row that is not
// numeric (too few fields, a cell not a number), "" for a numeric one; *non_finite_message says
// when a numeric row holds NaN, an infinity or a reading no sensor gives (imu_log.h).
std::string ReadRowCells(const std::vector<std::string_view>& fields, std::string_view line,
                         int line_number, const CsvColumns& c, const std::string& name, double* row,
                         std::string* non_finite_message) {
  if (static_cast<int>(fields.size()) <= c.max_column) {
    int k = 0;
    while (c.column[k] < static_cast<int>(fields.size())) ++k;
    return name + ":" + std::to_string(line_number) + ": the row has only " +
           std::to_string(fields.size()) + " field(s); column '" + Printable(c.names[k]) +
           "' is field " + std::to_string(c.column[k] + 1) + " ('" + Printable(TrimLogCell(line)) +
           "')";
  }
  bool non_finite = false;
  for (int k = 0; k < c.needed; ++k) {
    const std::string_view cell = fields[c.column[k]];
    if (!ParseCell(cell, &row[k])) {
      return name + ":" + std::to_string(line_number) + ":" + std::to_string(c.column[k] + 1) +
             ": column '" + Printable(c.names[k]) + "' holds '" + Printable(TrimLogCell(cell)) +
             "', which is not a number";
    }
    if (!std::isfinite(row[k]) && !non_finite) {
      non_finite = true;
      *non_finite_message = name + ":" + std::to_string(line_number) + ":" +
                            std::to_string(c.column[k] + 1) + ": column '" + c.names[k] +
                            "' holds '" + Printable(TrimLogCell(cell)) +
                            "'; NaN and infinite values are not allowed";
    } else if (k != kImuRowTime && !non_finite) {
      // A reading no sensor gives (imu_log.h): an error like NaN, if the row is data.
      const bool gyro = k <= 3;
      const double bound = gyro ? kMaxGyroRateRadPerS : kMaxAccelMps2;
      if (std::abs(row[k] * c.scale[k]) > bound) {
        non_finite = true;
        *non_finite_message = name + ":" + std::to_string(line_number) + ":" +
                              std::to_string(c.column[k] + 1) + ": column '" + c.names[k] +
                              "' holds '" + Printable(TrimLogCell(cell)) +
                              "' = " + Fmt("%g", row[k] * c.scale[k]) +
                              (gyro ? " rad/s, beyond any gyro (|rate| <= 1e4 rad/s)"
                                    : " m/s^2, beyond any accelerometer (|f| <= 1e5 m/s^2)") +
                              ": a corrupt value, or the wrong unit or column";
      }
    }
  }
  return "";
}

// The data rows read: the samples (row-major, `needed` per row, SI) with their lines, and how the
// time series ended.
struct CsvRows {
  std::vector<double> values;
  std::vector<int> row_line;
  std::string first_bad;
  int bad_rows = 0, first_bad_line = 0, lines_after_end = 0;
  int end_line = 0;  // line of the break that ended the time series (0: the file's end)
  std::string end_reason;
};

// Rows. The time series ends at a break that is not followed by a row continuing it (a later
// time): real loggers append footers (a blank line, then summary rows with text, or whose time
// is numeric again but jumps back). A blank line followed by a non-numeric row always ends it.
// A non-numeric row followed by a row that continues the time series is corruption inside the
// data: an error.
CsvRows ParseRows(LineReader* reader, size_t text_size, const CsvColumns& c,
                  const std::string& name, const ImuFormat& format) {
  CsvRows r;
  const int needed = c.needed;
  r.values.reserve(text_size / 8);
  r.row_line.reserve(text_size / 48);
  int first_blank_line = 0;
  std::string_view line;
  std::vector<std::string_view> fields;
  double row[7];
  while (reader->Next(&line)) {
    if (IsBlank(line)) {
      if (first_blank_line == 0 && !r.row_line.empty()) first_blank_line = reader->line_number();
      continue;
    }
    SplitLogLine(line, format.delimiter, &fields);
    std::string non_finite_message;
    const std::string bad =
        ReadRowCells(fields, line, reader->line_number(), c, name, row, &non_finite_message);
    if (!bad.empty()) {
      if (r.bad_rows == 0) {
        r.first_bad = bad;
        r.first_bad_line = reader->line_number();
      }
      ++r.bad_rows;
      if (first_blank_line > 0 && first_blank_line < r.first_bad_line) {
        // A blank line, then a non-numeric row: a footer. The time series ended at the blank.
        r.end_line = first_blank_line;
        r.end_reason = "a blank line, then a non-numeric row";
        r.lines_after_end = r.bad_rows + CountNonBlankLinesLeft(reader);
        break;
      }
      continue;
    }
    // A numeric row after a break: does it continue the time series?
    const bool after_break = r.bad_rows > 0 || first_blank_line > 0;
    const bool continues =
        r.row_line.empty() || row[kImuRowTime] * c.scale[kImuRowTime] >
                                  r.values[(r.row_line.size() - 1) * needed + kImuRowTime];
    if (after_break && !continues) {
      r.end_line = r.bad_rows > 0 && (first_blank_line == 0 || r.first_bad_line < first_blank_line)
                       ? r.first_bad_line
                       : first_blank_line;
      r.end_reason = r.end_line == r.first_bad_line && r.bad_rows > 0
                         ? "a non-numeric row, then rows whose time does not continue it"
                         : "a blank line, then rows whose time does not continue it";
      r.lines_after_end = 1 + r.bad_rows + CountNonBlankLinesLeft(reader);
      break;
    }
    if (r.bad_rows > 0) Fail(r.first_bad);  // a bad cell with the time series going on after it
    if (!non_finite_message.empty()) Fail(non_finite_message);
    first_blank_line = 0;
    for (int k = 0; k < needed; ++k) r.values.push_back(row[k] * c.scale[k]);
    r.row_line.push_back(reader->line_number());
  }
  return r;
}

// Fails when no data row was read; else warns of the rows after the time series' end.
void CheckRowsEnd(const CsvRows& r, int header_line, const std::string& name, ImuData* data) {
  if (r.row_line.empty()) {
    if (r.bad_rows > 0) {
      Fail(name + ": no numeric data rows after the header (line " + std::to_string(header_line) +
           "): " + std::to_string(r.bad_rows) +
           " row(s), none of them numbers (a footer only, or "
           "the wrong columns?); the first: " +
           r.first_bad);
    }
    Fail(name + ":" + std::to_string(header_line) + ": header only, no data rows");
  }
  if (r.end_line > 0) {
    data->warnings.push_back("the time series ends at line " + std::to_string(r.end_line) + " (" +
                             r.end_reason + "); " + std::to_string(r.lines_after_end) +
                             " row(s) after it (a footer?) are ignored; if they are data, "
                             "fix the row");
  } else if (r.bad_rows > 0) {
    data->warnings.push_back("skipped " + std::to_string(r.bad_rows) +
                             " trailing non-numeric row(s) from line " +
                             std::to_string(r.first_bad_line) + " (" + r.first_bad + ")");
  }
}

// `owner`, when given, holds the bytes `text` views; it is released once the rows are parsed, so a
// long log's text and its samples are not both held while the samples are finished.
// RefuseBinary -> ParseHeader -> ParseRows -> CheckRowsEnd -> FinishImuLog.
ImuData Parse(std::string_view text, const std::string& name, const ImuFormat& format,
              const ImuLogOptions& options, std::string* owner = nullptr) {
  std::string why;
  if (!format.Check(&why)) Fail(name + ": invalid IMU format: " + why);
  if (!options.Check(&why)) Fail(name + ": invalid log options: " + why);
  RefuseBinary(name, format, &text);
  ImuData data;
  LineReader reader(text);
  const CsvColumns columns = ParseHeader(&reader, name, format, options, &data);
  CsvRows rows = ParseRows(&reader, text.size(), columns, name, format);
  if (owner != nullptr) std::string().swap(*owner);  // `text` is not used below
  CheckRowsEnd(rows, columns.header_line, name, &data);
  return FinishImuLog(name, options, rows.values, columns.needed, rows.row_line, columns.scale,
                      columns.with_accel, std::move(data));
}

// The log's text: the file (bounded_read.h: a regular file within the cap), decompressed when
// it is a .csv.gz (within the decompressed cap).
std::string ReadWholeFile(const std::string& path, const ImuLogOptions& options) {
  std::string text, why;
  if (!ReadRegularFile(path, LogCap(options.max_file_bytes), &text, &why)) Fail(why);
  if (LooksGzipped(text)) {  // a .csv.gz log: inflate it in memory
    std::string inflated;
    if (!GzipDecompress(text, &inflated, &why,
                        DecompressedLogCap(options.max_decompressed_bytes))) {
      Fail(path + ": " + why);
    }
    return inflated;
  }
  return text;
}

}  // namespace

ImuData ReadImuLogFromString(const std::string& text, const std::string& name,
                             const ImuFormat& format, const ImuLogOptions& options) {
  if (UseUlogReader(text, format)) return ReadUlogImu(text, name, format, options);
  if (UseDataflashReader(text, format)) return ReadDataflashImu(text, name, options);
  return Parse(text, name, format, options);
}

ImuData ReadImuLog(const std::string& path, const ImuFormat& format, const ImuLogOptions& options) {
  std::string text = ReadWholeFile(path, options);
  if (UseUlogReader(text, format)) return ReadUlogImu(text, path, format, options);
  if (UseDataflashReader(text, format)) return ReadDataflashImu(text, path, options);
  // A .bin that does not start with a DataFlash header: the DataFlash reader skips leading
  // garbage to the first message; a text file named .bin is read as CSV; anything else is the
  // DataFlash reader's error (it names what it found).
  if (format.container == LogContainer::kAuto && NamedLikeDataflash(path)) {
    try {
      return ReadDataflashImu(text, path, options);
    } catch (const UserError& e) {
      if (text.empty() || std::memchr(text.data(), '\0', text.size()) != nullptr) throw;
      try {
        return Parse(text, path, format, options);
      } catch (const UserError& csv) {
        Fail(std::string(e.what()) + "; nor is it a CSV log (" + csv.what() + ")");
      }
    }
  }
  // A .ulg without the ULog magic is read as CSV (a CSV named .ulg still works); when that fails
  // too, say so rather than "missing column 't'", which points at the wrong problem.
  if (NamedLikeUlog(path)) {
    try {
      return Parse(text, path, format, options, &text);
    } catch (const UserError& e) {
      Fail(path + ": not a valid ULog file (a .ulg starts with the bytes \"ULog\" 01 12 35; " +
           "this one starts with " + DescribeStart(text) + ") and not a CSV log either (" +
           e.what() + ")");
    }
  }
  return Parse(text, path, format, options, &text);
}

bool TryReadImuLog(const std::string& path, const ImuFormat& format, const ImuLogOptions& options,
                   ImuData* data, std::string* error) {
  try {
    *data = ReadImuLog(path, format, options);
    return true;
  } catch (const UserError& e) {
    *error = e.what();
  } catch (const std::bad_alloc&) {
    *error = path + ": out of memory while reading the log";
  }
  return false;
}

}  // namespace bifilar

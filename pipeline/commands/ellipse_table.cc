#include "pipeline/commands/ellipse_table.h"

#include <cmath>
#include <fstream>
#include <sstream>

#include "base/bounded_read.h"
#include "base/csv.h"
#include "base/gzip.h"
#include "base/user_error.h"

namespace bifilar {
namespace {

std::string Trim(const std::string& s) {
  const size_t b = s.find_first_not_of(" \t\r");
  if (b == std::string::npos) return "";
  const size_t e = s.find_last_not_of(" \t\r");
  return s.substr(b, e - b + 1);
}

// The fields of a line (base/csv.h, RFC 4180: a quoted field may hold a comma), each trimmed.
std::vector<std::string> SplitCsv(const std::string& line) {
  std::vector<std::string> fields = SplitCsvRecord(line);
  for (std::string& field : fields) field = Trim(field);
  return fields;
}

// A cell as it may appear in a message: printable ASCII only (other bytes as '?'), at most 40
// characters, so a binary file never prints raw bytes into the terminal.
std::string Shown(const std::string& cell) {
  std::string out;
  for (char c : cell.substr(0, 40)) out += (c >= 32 && c < 127) ? c : '?';
  if (cell.size() > 40) out += "...";
  return out;
}

}  // namespace

std::vector<EllipsePoint> ParseEllipseTable(const std::string& text, const std::string& name,
                                            DisplayUnits units) {
  const double to_si = InertiaToSi(units);
  // A UTF-8 byte-order mark (spreadsheet exports) is not part of the first column's name.
  const bool bom = text.compare(0, 3, "\xEF\xBB\xBF") == 0;
  std::istringstream in(bom ? text.substr(3) : text);
  std::string line;
  int line_no = 0;
  int pitch_col = -1, inertia_col = -1, std_col = -1;
  size_t n_cols = 0;
  bool have_header = false;
  std::vector<EllipsePoint> points;
  while (std::getline(in, line)) {
    ++line_no;
    const std::string trimmed = Trim(line);
    if (trimmed.empty() || trimmed[0] == '#') continue;
    const std::string where = name + ":" + std::to_string(line_no) + ": ";
    const std::vector<std::string> fields = SplitCsv(trimmed);
    if (!have_header) {
      have_header = true;
      n_cols = fields.size();
      for (size_t c = 0; c < fields.size(); ++c) {
        int* slot = nullptr;
        if (fields[c] == "pitch_deg") slot = &pitch_col;
        if (fields[c] == "inertia") slot = &inertia_col;
        if (fields[c] == "std") slot = &std_col;
        if (slot == nullptr) {
          throw UserError(where + "unknown column '" + Shown(fields[c]) +
                          "' (expected a header 'pitch_deg,inertia' or 'pitch_deg,inertia,std')");
        }
        if (*slot >= 0) throw UserError(where + "column '" + fields[c] + "' appears twice");
        *slot = static_cast<int>(c);
      }
      if (pitch_col < 0) throw UserError(where + "missing column 'pitch_deg' in the header");
      if (inertia_col < 0) throw UserError(where + "missing column 'inertia' in the header");
      continue;
    }
    if (fields.size() != n_cols) {
      throw UserError(where + "expected " + std::to_string(n_cols) + " fields, got " +
                      std::to_string(fields.size()));
    }
    auto get = [&](int col, const char* what) {
      double v = 0;
      // base/csv.h; infinity and NaN pass here and are refused below with the column's bound.
      if (!ParseNumber(fields[col], &v, NonFinite::kAccept)) {
        throw UserError(where + "column '" + what + "': '" + Shown(fields[col]) +
                        "' is not a number");
      }
      return v;
    };
    EllipsePoint p;
    p.pitch_deg = get(pitch_col, "pitch_deg");
    if (!std::isfinite(p.pitch_deg) || p.pitch_deg < -180.0 || p.pitch_deg > 180.0) {
      throw UserError(where + "column 'pitch_deg': " + fields[pitch_col] +
                      " is outside [-180, 180] deg");
    }
    const double inertia = get(inertia_col, "inertia");
    if (!std::isfinite(inertia) || inertia <= 0.0) {
      throw UserError(where + "column 'inertia': " + fields[inertia_col] +
                      " must be finite and > 0");
    }
    p.inertia_kg_m2 = inertia * to_si;
    if (std_col >= 0) {
      const double s = get(std_col, "std");
      if (!std::isfinite(s) || s <= 0.0) {
        throw UserError(where + "column 'std': " + fields[std_col] +
                        " must be finite and > 0 (drop the column if unknown)");
      }
      p.std_kg_m2 = s * to_si;
    }
    points.push_back(p);
  }
  if (!have_header) throw UserError(name + ": empty table (no header row)");
  if (points.empty()) throw UserError(name + ": no data rows after the header");
  return points;
}

std::vector<EllipsePoint> ReadEllipseTable(const std::string& path, DisplayUnits units) {
  std::string bytes = ReadRegularFileOrThrow(path, TableCap("moments table"));
  if (LooksGzipped(bytes)) {  // a .csv.gz table is read like a .csv.gz log
    std::string inflated, why;
    if (!GzipDecompress(bytes, &inflated, &why, TableCap("moments table once decompressed"))) {
      throw UserError(path + ": gzip-compressed but cannot be inflated: " + why);
    }
    bytes = std::move(inflated);
  }
  if (bytes.find('\0') != std::string::npos) {
    throw UserError(path +
                    ": binary data, not a CSV table (expected a header "
                    "'pitch_deg,inertia[,std]' and one row per moment)");
  }
  return ParseEllipseTable(bytes, path, units);
}

}  // namespace bifilar

// The one rule that cuts a log line into cells (pipeline/logs/log_line.h).
#include "pipeline/logs/log_line.h"

namespace bifilar {
namespace {

bool IsPad(char c) { return c == ' ' || c == '\t' || c == '\r'; }

}  // namespace

std::string_view TrimLogCell(std::string_view cell) {
  size_t b = 0, e = cell.size();
  while (b < e && IsPad(cell[b])) ++b;
  while (e > b && IsPad(cell[e - 1])) --e;
  return cell.substr(b, e - b);
}

std::string_view UnquoteLogCell(std::string_view cell) {
  cell = TrimLogCell(cell);
  if (cell.size() >= 2 && ((cell.front() == '"' && cell.back() == '"') ||
                           (cell.front() == '\'' && cell.back() == '\''))) {
    cell = TrimLogCell(cell.substr(1, cell.size() - 2));
  }
  return cell;
}

void SplitLogLine(std::string_view line, char delim, std::vector<std::string_view>* fields) {
  fields->clear();
  if (delim == ' ') {  // space-separated: runs of spaces (and tabs) are one separator
    size_t i = 0;
    while (true) {
      while (i < line.size() && IsPad(line[i])) ++i;
      if (i >= line.size()) return;
      const size_t b = i;
      while (i < line.size() && !IsPad(line[i])) ++i;
      fields->push_back(line.substr(b, i - b));
    }
  }
  size_t start = 0;
  while (true) {
    const size_t pos = line.find(delim, start);
    if (pos == std::string_view::npos) {
      fields->push_back(line.substr(start));
      return;
    }
    fields->push_back(line.substr(start, pos - start));
    start = pos + 1;
  }
}

std::vector<std::string> LogLineCells(std::string_view line, char delim) {
  std::vector<std::string_view> fields;
  SplitLogLine(line, delim, &fields);
  std::vector<std::string> cells;
  cells.reserve(fields.size());
  for (std::string_view f : fields) cells.emplace_back(UnquoteLogCell(f));
  return cells;
}

}  // namespace bifilar

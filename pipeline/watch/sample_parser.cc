#include "pipeline/watch/sample_parser.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdlib>

#include <nlohmann/json.hpp>

#include "base/csv.h"
#include "base/text_format.h"
#include "base/user_error.h"
#include "pipeline/logs/imu_log_options.h"
#include "pipeline/logs/log_line.h"
#include "pipeline/logs/simulated_log.h"

namespace bifilar {
namespace {

bool IsComment(const std::string& line) {
  return line.rfind("#", 0) == 0 || line.rfind("%", 0) == 0 || line.rfind("//", 0) == 0;
}

char GuessDelimiter(const std::string& header) {
  for (char c : {',', ';', '\t'}) {
    if (header.find(c) != std::string::npos) return c;
  }
  return ' ';
}

// A stream's line is cut as a log's is (pipeline/logs/log_line.h).
std::vector<std::string> Split(const std::string& line, char delimiter) {
  return LogLineCells(line, delimiter);
}

int IndexOf(const std::vector<std::string>& header, const std::string& name) {
  for (size_t i = 0; i < header.size(); ++i) {
    if (header[i] == name) return static_cast<int>(i);
  }
  return -1;
}

// The whole cell as a number; false for anything else ("1.5x", "", "abc", "0x10"): base/csv.h's
// ParseNumber, the rule the saved log is read back with (pipeline/logs/imu_log.cc). Infinity and
// NaN are read, and counted as non_finite.
bool Number(const std::string& cell, double* value) {
  return ParseNumber(cell, value, NonFinite::kAccept);
}

std::string Excerpt(const std::string& line) { return PrintableAscii(line, 120); }

}  // namespace

std::string InputCounters::Text() const {
  std::vector<std::string> parts;
  auto add = [&parts](long n, const char* what) {
    if (n > 0) parts.push_back(std::to_string(n) + " " + what);
  };
  add(garbage, "garbage lines");
  add(non_finite, "NaN or infinite samples");
  add(out_of_range, "samples out of any sensor's range");
  add(time_back, "times that did not move forward");
  add(bad_checksum, "frames with a bad checksum");
  add(restarts, "stream restarts");
  std::string text;
  for (size_t i = 0; i < parts.size(); ++i) text += (i ? ", " : "") + parts[i];
  return text;
}

SampleParser::SampleParser(const WatchInputOptions& options) : options_(options) {}

void SampleParser::Feed(const std::string& bytes, std::vector<WatchSample>* samples,
                        std::vector<RejectedLine>* rejected) {
  partial_ += bytes;
  size_t start = 0;
  for (size_t nl = partial_.find('\n'); nl != std::string::npos; nl = partial_.find('\n', start)) {
    Line(partial_.substr(start, nl - start), samples, rejected);
    start = nl + 1;
  }
  partial_.erase(0, start);
}

void SampleParser::Finish(std::vector<WatchSample>* samples, std::vector<RejectedLine>* rejected) {
  if (!partial_.empty()) {
    std::string last;
    last.swap(partial_);
    Line(last, samples, rejected);
  }
  if (!resolved_ && !header_.empty() && !held_.empty()) {
    Resolve();
    auto held = std::move(held_);
    held_.clear();
    for (const auto& [line, cells] : held) Row(line, cells, samples, rejected);
  }
}

void SampleParser::Restart() {
  partial_.clear();
  mode_.clear();
  header_.clear();
  held_.clear();
  resolved_ = false;
  next_guess_rows_ = 0;
  index_ = 0;
  ++counters_.restarts;
}

bool SampleParser::Cells(const std::string& line, std::vector<std::string>* cells) const {
  if (mode_ == "csv") {
    *cells = Split(line, delimiter_);
    return cells->size() == header_.size();
  }
  const nlohmann::ordered_json j = nlohmann::ordered_json::parse(line, nullptr, false);
  if (j.is_discarded() || !j.is_object()) return false;
  cells->clear();
  for (const std::string& key : header_) {
    const auto it = j.find(key);
    if (it == j.end() || !(it->is_number() || it->is_null() || it->is_string())) return false;
    // A JSON number prints back exactly; null stands for NaN (rejected as non_finite).
    cells->push_back(it->is_number() ? it->dump() : it->is_null() ? "nan" : it->get<std::string>());
  }
  return true;
}

void SampleParser::Line(std::string line, std::vector<WatchSample>* samples,
                        std::vector<RejectedLine>* rejected) {
  if (line.rfind("\xEF\xBB\xBF", 0) == 0) line.erase(0, 3);
  while (!line.empty() && (line.back() == '\r' || line.back() == ' ')) line.pop_back();
  if (line.empty()) return;
  if (header_.empty()) {
    if (IsComment(line)) {
      std::string warning;
      if (ParseSimulatedCsvMarker(line, &warning)) simulated_marker_ = line;
      return;
    }
    if (line[0] == '{') {
      const nlohmann::ordered_json j = nlohmann::ordered_json::parse(line, nullptr, false);
      if (j.is_discarded() || !j.is_object() || j.empty()) {
        ++counters_.garbage;
        rejected->push_back({line, "garbage"});
        return;
      }
      mode_ = "json";
      for (const auto& item : j.items()) header_.push_back(item.key());
    } else {
      mode_ = "csv";
      delimiter_ = GuessDelimiter(line);
      header_ = Split(line, delimiter_);
      return;
    }
  }
  ++counters_.lines;
  std::vector<std::string> cells;
  if (!Cells(line, &cells)) {
    ++counters_.garbage;
    rejected->push_back({line, "garbage"});
    return;
  }
  if (!resolved_) {
    held_.emplace_back(line, cells);
    const size_t first = static_cast<size_t>(std::max(1, options_.rows_to_guess));
    if (held_.size() < first) return;
    // A guess of the units waits for motion (see WatchInputOptions::rows_to_guess).
    if (!ColumnsAreTheConfigs() && options_.guess_format &&
        held_.size() <
            static_cast<size_t>(std::max(options_.max_rows_held, options_.rows_to_guess))) {
      if (held_.size() < std::max(first, next_guess_rows_)) return;
      next_guess_rows_ = 2 * held_.size();
      if (!HeldRowsShowMotion()) return;
    }
    Resolve();
    auto held = std::move(held_);
    held_.clear();
    for (const auto& [l, c] : held) Row(l, c, samples, rejected);
    return;
  }
  Row(line, cells, samples, rejected);
}

bool SampleParser::ColumnsAreTheConfigs() const {
  const ImuFormat& config = options_.format;
  bool all = options_.counter_rate_hz > 0 || IndexOf(header_, config.time_column) >= 0;
  for (int k = 0; k < 3; ++k) {
    all = all && IndexOf(header_, config.gyro_columns[k]) >= 0;
    if (config.has_accel()) all = all && IndexOf(header_, config.accel_columns[k]) >= 0;
  }
  return all;
}

// The guess reads a CSV text: the header and the rows held, with a time column made from the
// counter when the stream has none.
std::string SampleParser::HeldText() const {
  const bool counter = options_.counter_rate_hz > 0;
  std::string text = counter ? "t" : "";
  for (size_t i = 0; i < header_.size(); ++i) text += (i || counter ? "," : "") + header_[i];
  text += "\n";
  for (size_t r = 0; r < held_.size(); ++r) {
    if (counter) text += Fmt("%.9g", static_cast<double>(r) / options_.counter_rate_hz);
    for (size_t i = 0; i < held_[r].second.size(); ++i) {
      text += (i || counter ? "," : "") + held_[r].second[i];
    }
    text += "\n";
  }
  return text;
}

// True when the gyro columns that the guess names on the rows held show rates 20 times the
// noise of the first rows_to_guess rows (a ratio, so true whatever the unit) in enough rows: the
// swing has started and the unit guess can see it.
bool SampleParser::HeldRowsShowMotion() const {
  ImuFormat guessed;
  std::string why;
  if (!options_.guess_format(HeldText(), &guessed, &why)) return false;
  int index[3];
  for (int k = 0; k < 3; ++k) {
    index[k] = IndexOf(header_, guessed.gyro_columns[k]);
    if (index[k] < 0) return false;
  }
  const size_t first = static_cast<size_t>(std::max(1, options_.rows_to_guess));
  double mean[3] = {0, 0, 0}, noise2 = 0.0;
  std::vector<std::array<double, 3>> rates;
  for (const auto& row : held_) {
    std::array<double, 3> w{};
    bool ok = true;
    for (int k = 0; k < 3; ++k) {
      ok = ok && static_cast<size_t>(index[k]) < row.second.size() &&
           Number(row.second[index[k]], &w[k]) && std::isfinite(w[k]);
    }
    if (ok) rates.push_back(w);
  }
  if (rates.size() < first) return false;
  for (size_t r = 0; r < first; ++r) {
    for (int k = 0; k < 3; ++k) mean[k] += rates[r][k] / static_cast<double>(first);
  }
  std::vector<double> d2(rates.size(), 0.0);
  for (size_t r = 0; r < rates.size(); ++r) {
    for (int k = 0; k < 3; ++k) d2[r] += (rates[r][k] - mean[k]) * (rates[r][k] - mean[k]);
    if (r < first) noise2 += d2[r] / static_cast<double>(first);
  }
  // Enough of it for the guess, which reads the 99th percentile of |rate|: a tenth of the rows
  // held, and at least rows_to_guess, move.
  size_t moving = 0;
  for (double v : d2) moving += v > 400.0 * noise2 && v > 0.0 ? 1 : 0;
  return moving >= std::max(first, rates.size() / 10);
}

void SampleParser::Resolve() {
  const ImuFormat& config = options_.format;
  const bool counter = options_.counter_rate_hz > 0;
  counter_index_ = counter ? IndexOf(header_, options_.counter_column) : -1;
  input_format_ = config;
  description_ = "the config's columns";
  if (!ColumnsAreTheConfigs()) {
    if (!options_.guess_format) {
      throw UserError("watch: the stream's columns (" + std::to_string(header_.size()) + ": " +
                      Excerpt(header_.empty() ? "" : header_[0]) +
                      ", ...) are not the config's imu columns, and no guess is available");
    }
    const std::string text = HeldText();
    std::string why;
    if (!options_.guess_format(text, &input_format_, &why)) {
      throw UserError("watch: cannot tell the stream's columns: " + why);
    }
    description_ = "guessed columns";
  }
  time_index_ = counter ? -1 : IndexOf(header_, input_format_.time_column);
  for (int k = 0; k < 3; ++k) {
    gyro_index_[k] = IndexOf(header_, input_format_.gyro_columns[k]);
    accel_index_[k] =
        input_format_.has_accel() ? IndexOf(header_, input_format_.accel_columns[k]) : -1;
  }
  if ((!counter && time_index_ < 0) || gyro_index_[0] < 0 || gyro_index_[1] < 0 ||
      gyro_index_[2] < 0) {
    throw UserError("watch: the stream has no time or gyro columns (header " +
                    Excerpt(header_.empty() ? "" : header_[0]) + ", ...)");
  }
  if (config.has_accel() && accel_index_[0] < 0) {
    throw UserError("watch: the config names accelerometer columns (" + config.accel_columns[0] +
                    ", ...) but the stream has none; set `imu.accel: null` in the config");
  }
  description_ +=
      ": time " +
      (counter ? "counter at " + Fmt("%g", options_.counter_rate_hz) + " Hz"
               : input_format_.time_column + " (" + ToString(input_format_.time_unit) + ")") +
      ", gyro " + input_format_.gyro_columns[0] + "," + input_format_.gyro_columns[1] + "," +
      input_format_.gyro_columns[2] + " (" + ToString(input_format_.gyro_unit) + ")";
  resolved_ = true;
}

void SampleParser::Row(const std::string& line, const std::vector<std::string>& cells,
                       std::vector<WatchSample>* samples, std::vector<RejectedLine>* rejected) {
  auto reject = [&](long* counter, const char* reason) {
    ++*counter;
    rejected->push_back({line, reason});
  };
  double values[7] = {0, 0, 0, 0, 0, 0, 0};
  const int indices[7] = {options_.counter_rate_hz > 0 ? counter_index_ : time_index_,
                          gyro_index_[0],
                          gyro_index_[1],
                          gyro_index_[2],
                          accel_index_[0],
                          accel_index_[1],
                          accel_index_[2]};
  const bool has_accel = options_.format.has_accel();
  for (int k = 0; k < 7; ++k) {
    if (indices[k] < 0) continue;
    if (!Number(cells[indices[k]], &values[k])) return reject(&counters_.garbage, "garbage");
  }
  const long index = index_++;
  WatchSample s;
  if (options_.counter_rate_hz > 0) {
    s.t_s =
        (counter_index_ >= 0 ? values[0] : static_cast<double>(index)) / options_.counter_rate_hz;
  } else {
    s.t_s = values[0] * ToSi(input_format_.time_unit);
  }
  for (int k = 0; k < 3; ++k) s.gyro_rad_per_s[k] = values[1 + k] * ToSi(input_format_.gyro_unit);
  s.has_accel = has_accel;
  for (int k = 0; k < 3 && has_accel; ++k) {
    s.accel_mps2[k] = values[4 + k] * ToSi(input_format_.accel_unit);
  }
  if (!std::isfinite(s.t_s) || !s.gyro_rad_per_s.allFinite() || !s.accel_mps2.allFinite()) {
    return reject(&counters_.non_finite, "non_finite");
  }
  if (s.gyro_rad_per_s.cwiseAbs().maxCoeff() > kMaxGyroRateRadPerS ||
      s.accel_mps2.cwiseAbs().maxCoeff() > kMaxAccelMps2) {
    return reject(&counters_.out_of_range, "out_of_range");
  }
  if (!(s.t_s > last_t_)) return reject(&counters_.time_back, "time_back");
  last_t_ = s.t_s;
  ++counters_.samples;
  samples->push_back(s);
}

}  // namespace bifilar

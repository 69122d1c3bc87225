#include "pipeline/logs/dataflash.h"

#include <algorithm>
#include <cctype>
#include <cstdio>
#include <cstring>
#include <set>
#include <utility>

#include "base/text_format.h"
#include "base/units.h"
#include "base/user_error.h"
#include "pipeline/logs/imu_log_finish.h"
#include "pipeline/logs/simulated_log.h"

namespace bifilar {
namespace {

constexpr size_t kHeader = 3;  // A3 95 <type>
// The simulated-log mark (pipeline/logs/simulated_log.h): a MSG text "simulated by <origin>".
constexpr std::string_view kSimulatedPrefix = "simulated by bifilar ";

// ArduPilot's built-in unit and multiplier ids (AP_Logger/LogStructure.h), used when the log has
// no UNIT/MULT messages for an id that FMTU names.
const std::map<char, std::string>& BuiltinUnits() {
  static const std::map<char, std::string> units = {
      {'-', ""},         {'s', "s"},    {'E', "rad/s"}, {'k', "deg/s"}, {'o', "m/s/s"},
      {'#', "instance"}, {'O', "degC"}, {'z', "Hz"},    {'d', "deg"},   {'r', "rad"}};
  return units;
}
const std::map<char, double>& BuiltinMultipliers() {
  static const std::map<char, double> mults = {
      {'2', 1e2},  {'1', 1e1},  {'0', 1e0},  {'A', 1e-1}, {'B', 1e-2}, {'C', 1e-3},  {'D', 1e-4},
      {'E', 1e-5}, {'F', 1e-6}, {'G', 1e-7}, {'I', 1e-9}, {'!', 3.6},  {'/', 3600.0}};
  return mults;
}

template <typename U>
U Load(const unsigned char* p) {
  U v = 0;
  for (size_t i = 0; i < sizeof(U); ++i) v |= static_cast<U>(p[i]) << (8 * i);
  return v;
}

bool IsScaledChar(char c) { return c == 'c' || c == 'C' || c == 'e' || c == 'E' || c == 'L'; }
bool IsStringChar(char c) { return c == 'n' || c == 'N' || c == 'Z'; }

// One numeric field as stored, with its format character's scale; NaN for strings and arrays.
double DecodeNumber(const unsigned char* p, char c) {
  switch (c) {
    case 'b':
      return static_cast<int8_t>(p[0]);
    case 'B':
    case 'M':
      return p[0];
    case 'h':
      return static_cast<int16_t>(Load<uint16_t>(p));
    case 'H':
      return Load<uint16_t>(p);
    case 'i':
      return static_cast<int32_t>(Load<uint32_t>(p));
    case 'I':
      return Load<uint32_t>(p);
    case 'q':
      return static_cast<double>(static_cast<int64_t>(Load<uint64_t>(p)));
    case 'Q':
      return static_cast<double>(Load<uint64_t>(p));
    case 'c':
      return static_cast<int16_t>(Load<uint16_t>(p)) / 100.0;
    case 'C':
      return Load<uint16_t>(p) / 100.0;
    case 'e':
      return static_cast<int32_t>(Load<uint32_t>(p)) / 100.0;
    case 'E':
      return Load<uint32_t>(p) / 100.0;
    case 'L':
      return static_cast<int32_t>(Load<uint32_t>(p)) / 1e7;
    case 'f': {
      const uint32_t bits = Load<uint32_t>(p);
      float f;
      std::memcpy(&f, &bits, sizeof(f));
      return f;
    }
    case 'd': {
      const uint64_t bits = Load<uint64_t>(p);
      double d;
      std::memcpy(&d, &bits, sizeof(d));
      return d;
    }
    default:
      return NAN;
  }
}

// A fixed-width string field up to its first NUL.
std::string DecodeString(const unsigned char* p, size_t width) {
  const void* nul = std::memchr(p, 0, width);
  const size_t n = nul ? static_cast<const unsigned char*>(nul) - p : width;
  return std::string(reinterpret_cast<const char*>(p), n);
}

// Bytes of a name or format echoed in a message (PrintableAscii).
constexpr size_t kDataflashTextEcho = 64;

std::vector<std::string> SplitLabels(const std::string& labels) {
  std::vector<std::string> out;
  size_t start = 0;
  while (start <= labels.size()) {
    const size_t comma = labels.find(',', start);
    const size_t end = comma == std::string::npos ? labels.size() : comma;
    out.push_back(labels.substr(start, end - start));
    if (comma == std::string::npos) break;
    start = comma + 1;
  }
  if (labels.empty()) out.clear();
  return out;
}

// Fills offsets/decodable/problem of a format from its characters, labels and length.
void LayOutFields(DataflashFormat* f) {
  f->offsets.clear();
  int at = 0;
  for (char c : f->format) {
    const int size = DataflashFieldSize(c);
    if (size == 0) {
      f->problem = std::string("unknown format character '") +
                   PrintableAscii(std::string(1, c), kDataflashTextEcho) + "' in '" +
                   PrintableAscii(f->format, kDataflashTextEcho) + "'";
      f->decodable = false;
      return;
    }
    f->offsets.push_back(at);
    at += size;
  }
  if (f->labels.size() != f->format.size()) {
    f->problem = std::to_string(f->labels.size()) + " labels for the " +
                 std::to_string(f->format.size()) + " fields of format '" +
                 PrintableAscii(f->format, kDataflashTextEcho) + "'";
    f->decodable = false;
    return;
  }
  if (static_cast<int>(kHeader) + at > f->length) {
    f->problem = "its length " + std::to_string(f->length) + " is too short for its format '" +
                 PrintableAscii(f->format, kDataflashTextEcho) + "', which needs 3 + " +
                 std::to_string(at) + " = " + std::to_string(3 + at) + " bytes";
    f->decodable = false;
    return;
  }
  f->problem.clear();
  f->decodable = true;
  f->time_index = f->instance_index = -1;
  for (size_t i = 0; i < f->labels.size(); ++i) {
    const char c = f->format[i];
    const bool number = !IsStringChar(c) && c != 'a';
    if (f->time_index < 0 && number && (f->labels[i] == "TimeUS" || f->labels[i] == "TimeMS")) {
      f->time_index = static_cast<int>(i);
    }
    if (f->instance_index < 0 && number && (f->labels[i] == "I" || f->labels[i] == "Instance")) {
      f->instance_index = static_cast<int>(i);
    }
  }
}

int LabelIndex(const DataflashFormat& f, const std::string& label) {
  for (size_t i = 0; i < f.labels.size(); ++i) {
    if (f.labels[i] == label) return static_cast<int>(i);
  }
  return -1;
}

class DataflashParser {
 public:
  DataflashParser(std::string_view bytes, const std::string& name, const DataflashRequest& request)
      : data_(reinterpret_cast<const unsigned char*>(bytes.data())),
        size_(bytes.size()),
        name_(name),
        request_(request) {
    DataflashFormat fmt;
    fmt.type = kDataflashFmtType;
    fmt.length = kDataflashFmtLength;
    fmt.name = "FMT";
    fmt.format = "BBnNZ";
    fmt.labels = {"Type", "Length", "Name", "Format", "Columns"};
    LayOutFields(&fmt);
    out_.formats[fmt.type] = fmt;
    out_.unit_labels = BuiltinUnits();
    out_.multiplier_values = BuiltinMultipliers();
  }

  DataflashContents Run();

 private:
  // The length of a message of `type` at `pos` when it is a whole message followed by another
  // header (or the end of the file); 0 otherwise.
  // `in_sync`: the message before ended here.
  size_t WholeMessageAt(size_t pos, bool in_sync);
  void OnMessage(size_t pos, const DataflashFormat& f);
  void OnFmt(size_t pos, const unsigned char* body);
  void OnFmtu(const DataflashFormat& f, const unsigned char* body);
  void OnUnitOrMult(const DataflashFormat& f, const unsigned char* body);
  void OnMsg(const DataflashFormat& f, const unsigned char* body);
  void Count(const DataflashFormat& f, const unsigned char* body);
  void Decode(size_t pos, const DataflashFormat& f, const unsigned char* body);
  void NoteSkipped(size_t start, size_t end, bool at_end);
  [[noreturn]] void Fail(const std::string& what) const { throw UserError(name_ + ": " + what); }

  const unsigned char* data_;
  size_t size_;
  const std::string& name_;
  const DataflashRequest& request_;
  DataflashContents out_;
  std::map<std::string, size_t> message_index_;
  // Skipped runs: how many, and the first.
  long skipped_runs_ = 0;
  size_t first_skip_at_ = 0, first_skip_bytes_ = 0;
  std::string tail_;  // what the cut tail was, when the log ends inside a message
  size_t tail_bytes_ = 0;
  bool simulated_noted_ = false;
  std::set<int> confirmed_ = {kDataflashFmtType};
  std::vector<int> slot_by_type_ =
      std::vector<int>(256, -1);  // into out_.messages  // types seen followed by another message
  // The request's field indices in the format last used (by its FMT byte offset).
  uint64_t request_format_at_ = UINT64_MAX;
  std::vector<int> request_index_;
  int request_instance_index_ = -1;
};

size_t DataflashParser::WholeMessageAt(size_t pos, bool in_sync) {
  const auto it = out_.formats.find(data_[pos + 2]);
  if (it == out_.formats.end()) return 0;
  const size_t length = static_cast<size_t>(it->second.length);
  if (length < kHeader || size_ - pos < length) return 0;
  const size_t next = pos + length;
  const size_t left = size_ - next;
  const bool followed = left == 0 || (data_[next] == kDataflashHead1 &&
                                      (left == 1 || data_[next + 1] == kDataflashHead2));
  if (followed) {
    confirmed_.insert(it->first);
    return length;
  }
  // Garbage after a message: kept when the reader is in step and the type's length has been
  // seen to frame the messages before (else a wrong FMT length would be read as data).
  if (in_sync && confirmed_.count(it->first)) return length;
  ++out_.misframed[it->first];
  return 0;
}

DataflashContents DataflashParser::Run() {
  size_t pos = 0, skip_start = 0;
  bool skipping = false;
  while (pos < size_) {
    if (size_ - pos >= kHeader && data_[pos] == kDataflashHead1 &&
        data_[pos + 1] == kDataflashHead2) {
      const size_t length = WholeMessageAt(pos, !skipping);
      if (length > 0) {
        if (skipping) NoteSkipped(skip_start, pos, false);
        skipping = false;
        OnMessage(pos, out_.formats.at(data_[pos + 2]));
        pos += length;
        continue;
      }
    }
    if (!skipping) {
      skipping = true;
      skip_start = pos;
    }
    // On to the next possible header byte.
    const void* next = std::memchr(data_ + pos + 1, kDataflashHead1, size_ - pos - 1);
    pos = next ? static_cast<const unsigned char*>(next) - data_ : size_;
  }
  if (skipping) NoteSkipped(skip_start, size_, true);
  if (out_.messages_read == 0) {
    std::string start;
    char hex[4];
    for (size_t i = 0; i < std::min<size_t>(size_, 8); ++i) {
      std::snprintf(hex, sizeof(hex), "%s%02x", i ? " " : "", data_[i]);
      start += hex;
    }
    Fail("not an ArduPilot DataFlash log: no message found in its " + std::to_string(size_) +
         " bytes, which start with " + start +
         " (a DataFlash log is a series of messages that "
         "start with the bytes a3 95, the first a FMT message a3 95 80)");
  }
  if (skipped_runs_ > 0) {
    out_.warnings.push_back(
        "skipped " + std::to_string(out_.skipped_bytes - tail_bytes_) +
        " byte(s) that are not "
        "part of a whole message, in " +
        std::to_string(skipped_runs_) + " place(s) (the first " +
        std::to_string(first_skip_bytes_) + " byte(s) at byte " + std::to_string(first_skip_at_) +
        "): bad sync bytes or garbage between messages; reading went on at the next message");
  }
  if (!tail_.empty()) out_.warnings.push_back(tail_);
  return std::move(out_);
}

void DataflashParser::NoteSkipped(size_t start, size_t end, bool at_end) {
  out_.skipped_bytes += end - start;
  if (at_end && end - start >= kHeader && data_[start] == kDataflashHead1 &&
      data_[start + 1] == kDataflashHead2) {
    const auto it = out_.formats.find(data_[start + 2]);
    if (it != out_.formats.end() && static_cast<size_t>(it->second.length) > end - start) {
      tail_bytes_ = end - start;
      tail_ = "the log ends inside a " + PrintableAscii(it->second.name, kDataflashTextEcho) +
              " message at byte " + std::to_string(start) + " (" + std::to_string(end - start) +
              " of its " + std::to_string(it->second.length) +
              " bytes): the logger stopped mid-write; read "
              "to the last whole message";
      return;
    }
  }
  if (skipped_runs_++ == 0) {
    first_skip_at_ = start;
    first_skip_bytes_ = end - start;
  }
}

void DataflashParser::OnMessage(size_t pos, const DataflashFormat& f) {
  ++out_.messages_read;
  const unsigned char* body = data_ + pos + kHeader;
  if (f.type == kDataflashFmtType) {
    OnFmt(pos, body);
    Count(out_.formats.at(kDataflashFmtType), body);
    return;
  }
  Count(f, body);
  if (!f.decodable) return;
  if (f.name == "FMTU")
    OnFmtu(f, body);
  else if (f.name == "UNIT" || f.name == "MULT")
    OnUnitOrMult(f, body);
  else if (f.name == "MSG")
    OnMsg(f, body);
  if (!request_.message.empty() && f.name == request_.message) Decode(pos, f, body);
}

void DataflashParser::OnFmt(size_t pos, const unsigned char* body) {
  DataflashFormat f;
  f.type = body[0];
  f.length = body[1];
  f.name = DecodeString(body + 2, 4);
  f.format = DecodeString(body + 6, 16);
  f.labels = SplitLabels(DecodeString(body + 22, 64));
  f.byte_offset = pos;
  if (f.type == kDataflashFmtType) {
    if (f.length != kDataflashFmtLength) {
      out_.warnings.push_back("a FMT at byte " + std::to_string(pos) +
                              " redefines FMT itself with " + std::to_string(f.length) +
                              " bytes; ignored (FMT is 89 bytes)");
    }
    return;
  }
  if (f.length < static_cast<int>(kHeader)) {
    out_.warnings.push_back("the FMT at byte " + std::to_string(pos) + " gives message '" +
                            PrintableAscii(f.name, kDataflashTextEcho) + "' (type " +
                            std::to_string(f.type) + ") a length of " + std::to_string(f.length) +
                            " bytes, less than its 3-byte header; ignored");
    return;
  }
  LayOutFields(&f);
  const auto old = out_.formats.find(f.type);
  if (old != out_.formats.end() && old->second.name == f.name && old->second.format == f.format &&
      old->second.labels == f.labels && old->second.length == f.length) {
    return;  // the same definition again (a log restarted): keep its FMTU
  }
  out_.formats[f.type] = f;
  slot_by_type_[f.type] = -1;  // its name may have changed
}

void DataflashParser::OnFmtu(const DataflashFormat& f, const unsigned char* body) {
  const int type_at = LabelIndex(f, "FmtType"), units_at = LabelIndex(f, "UnitIds"),
            mults_at = LabelIndex(f, "MultIds");
  if (type_at < 0 || units_at < 0 || mults_at < 0 || f.format[type_at] != 'B' ||
      f.format[units_at] != 'N' || f.format[mults_at] != 'N') {
    return;
  }
  const auto it = out_.formats.find(body[f.offsets[type_at]]);
  if (it == out_.formats.end()) return;
  it->second.units = DecodeString(body + f.offsets[units_at], 16);
  it->second.multipliers = DecodeString(body + f.offsets[mults_at], 16);
}

void DataflashParser::OnUnitOrMult(const DataflashFormat& f, const unsigned char* body) {
  const int id_at = LabelIndex(f, "Id");
  if (id_at < 0 || f.format[id_at] != 'b') return;
  const char id = static_cast<char>(body[f.offsets[id_at]]);
  if (f.name == "UNIT") {
    const int label_at = LabelIndex(f, "Label");
    if (label_at >= 0 && f.format[label_at] == 'Z') {
      out_.unit_labels[id] = DecodeString(body + f.offsets[label_at], 64);
    }
  } else {
    const int mult_at = LabelIndex(f, "Mult");
    if (mult_at >= 0 && f.format[mult_at] == 'd') {
      const double m = DecodeNumber(body + f.offsets[mult_at], 'd');
      if (std::isfinite(m)) out_.multiplier_values[id] = m;
    }
  }
}

void DataflashParser::OnMsg(const DataflashFormat& f, const unsigned char* body) {
  const int text_at = LabelIndex(f, "Message");
  if (text_at < 0 || f.format[text_at] != 'Z' || simulated_noted_) return;
  const std::string text = DecodeString(body + f.offsets[text_at], 64);
  if (text.compare(0, kSimulatedPrefix.size(), kSimulatedPrefix) != 0) return;
  simulated_noted_ = true;
  out_.warnings.push_back(SimulatedLogWarning(std::string_view(text).substr(13)));
}

// The count, time span and instances of a message name.
void DataflashParser::Count(const DataflashFormat& f, const unsigned char* body) {
  int& slot = slot_by_type_[f.type];
  if (slot < 0) {
    auto [it, added] = message_index_.emplace(f.name, out_.messages.size());
    if (added) {
      DataflashMessageInfo info;
      info.name = f.name;
      out_.messages.push_back(info);
    }
    slot = static_cast<int>(it->second);
  }
  DataflashMessageInfo& info = out_.messages[slot];
  ++info.count;
  if (f.time_index >= 0) {
    const double t = DecodeNumber(body + f.offsets[f.time_index], f.format[f.time_index]) *
                     (f.labels[f.time_index] == "TimeUS" ? 1e-6 : 1e-3);
    if (info.count == 1 || !std::isfinite(info.first_time_s)) info.first_time_s = t;
    if (info.timed > 0 && std::isfinite(t) && std::isfinite(info.last_time_s)) {
      const double step = t - info.last_time_s;
      if (step < 0) ++info.backward_steps;
      info.max_step_s = std::max(info.max_step_s, step);
    }
    ++info.timed;
    info.time_field = f.labels[f.time_index];
    info.last_time_s = t;
  }
  if (f.instance_index >= 0) {
    if (info.instance_field.empty()) info.instance_field = f.labels[f.instance_index];
    const double v = DecodeNumber(body + f.offsets[f.instance_index], f.format[f.instance_index]);
    if (std::isfinite(v) && v >= 0 && v <= kMaxDataflashInstance && v == std::floor(v)) {
      ++info.instances[static_cast<int>(v)];
    } else {
      ++info.invalid_instances;
      if (info.invalid_instance_example.empty()) {
        char text[40];
        std::snprintf(text, sizeof(text), "%g", v);
        info.invalid_instance_example = text;
      }
    }
  }
}

void DataflashParser::Decode(size_t pos, const DataflashFormat& f, const unsigned char* body) {
  if (request_format_at_ != f.byte_offset) {
    request_format_at_ = f.byte_offset;
    request_index_.clear();
    out_.field_units.clear();
    out_.field_multipliers.clear();
    out_.field_chars.clear();
    for (const std::string& label : request_.fields) {
      const int i = LabelIndex(f, label);
      if (i >= 0 && (IsStringChar(f.format[i]) || f.format[i] == 'a')) {
        Fail("message " + f.name + " (FMT at byte " + std::to_string(f.byte_offset) +
             ") has a field '" + label + "' of type '" + std::string(1, f.format[i]) + "' (" +
             (f.format[i] == 'a' ? "an array" : "a string") +
             "), not a number: the FMT is damaged or not an IMU message's");
      }
      if (i < 0) {
        std::string list;
        for (const std::string& l : f.labels)
          list += (list.empty() ? "" : ", ") + PrintableAscii(l, kDataflashTextEcho);
        Fail("message " + f.name + " (FMT at byte " + std::to_string(f.byte_offset) +
             ") has no numeric field '" + label + "'; its fields are: " + list);
      }
      request_index_.push_back(i);
      out_.field_chars.push_back(f.format[i]);
      std::string unit;
      double mult = NAN;
      if (static_cast<size_t>(i) < f.units.size()) {
        const auto u = out_.unit_labels.find(f.units[i]);
        if (u != out_.unit_labels.end()) unit = u->second;
      }
      if (static_cast<size_t>(i) < f.multipliers.size()) {
        const auto m = out_.multiplier_values.find(f.multipliers[i]);
        if (m != out_.multiplier_values.end()) mult = m->second;
      }
      out_.field_units.push_back(unit);
      out_.field_multipliers.push_back(mult);
    }
    request_instance_index_ =
        request_.instance_field.empty() ? -1 : LabelIndex(f, request_.instance_field);
    if (!request_.instance_field.empty() && request_instance_index_ < 0) {
      Fail("message " + f.name + " (FMT at byte " + std::to_string(f.byte_offset) +
           ") has no field '" + request_.instance_field + "'");
    }
  }
  if (request_instance_index_ >= 0) {
    const double v =
        DecodeNumber(body + f.offsets[request_instance_index_], f.format[request_instance_index_]);
    if (!(v == request_.instance)) return;
  }
  for (size_t k = 0; k < request_index_.size(); ++k) {
    const int i = request_index_[k];
    out_.values.push_back(DecodeNumber(body + f.offsets[i], f.format[i]));
  }
  out_.value_offsets.push_back(pos);
}

// ---- The IMU series ----

// Where one IMU instance is: a message name, and the value of its instance field if it has one.
struct ImuSource {
  std::string message;
  std::string instance_field;  // "" when the name gives the instance
  int instance = 0;
  long count = 0;
};

// The instances of a family ("IMU": IMU with its I field, or IMU, IMU2, IMU3; "GYR": GYR with I,
// or GYR1, GYR2, GYR3), lowest first.
std::vector<ImuSource> SourcesOf(const DataflashContents& log, const std::string& family) {
  std::map<int, ImuSource> by_instance;
  for (const DataflashMessageInfo& m : log.messages) {
    if (m.name.compare(0, family.size(), family) != 0 || m.count == 0) continue;
    const std::string rest = m.name.substr(family.size());
    const DataflashFormat* f = log.FormatOf(m.name);
    if (f == nullptr) continue;
    if (rest.empty() && !m.instance_field.empty()) {
      for (const auto& [instance, count] : m.instances) {
        by_instance.emplace(instance, ImuSource{m.name, m.instance_field, instance, count});
      }
    } else if (rest.empty() || (rest.size() == 1 && rest[0] >= '1' && rest[0] <= '9')) {
      const int instance = rest.empty() ? 0 : rest[0] - '1';
      by_instance.emplace(instance, ImuSource{m.name, "", instance, m.count});
    }
  }
  std::vector<ImuSource> out;
  for (const auto& [instance, source] : by_instance) out.push_back(source);
  return out;
}

std::string ListMessages(const DataflashContents& log) {
  std::string list;
  size_t n = 0;
  for (const DataflashMessageInfo& m : log.messages) {
    if (++n > 60) {
      list += ", ... (" + std::to_string(log.messages.size()) + " in all)";
      break;
    }
    list += (list.empty() ? "" : ", ") + PrintableAscii(m.name, kDataflashTextEcho) + " (" +
            std::to_string(m.count) + ")";
  }
  return list.empty() ? "none" : list;
}

// A FMT of `message` that cannot be read: say why, with the misframed headers if any.
[[noreturn]] void FailFormat(const std::string& name, const DataflashContents& log,
                             const std::string& message) {
  const DataflashFormat* f = log.FormatOf(message);
  std::string what = name + ": the FMT of " + message;
  if (f != nullptr) {
    what += " (type " + std::to_string(f->type) + ", byte " + std::to_string(f->byte_offset) +
            ") cannot be read: ";
    const auto mis = log.misframed.find(f->type);
    if (!f->decodable) {
      what += f->problem;
    } else if (mis != log.misframed.end()) {
      what += "it defines the message as " + std::to_string(f->length) + " bytes, but " +
              std::to_string(mis->second) + " " + message +
              " header(s) in the file are not followed by another message at that length "
              "(the FMT does not match the data)";
    }
  }
  throw UserError(what + "; the log is damaged");
}

// The values of one source: time (s), gyro (rad/s), accel (m/s^2) when `with_accel`.
struct SourceSeries {
  std::vector<double> t_s;
  std::vector<double> xyz;            // 3 per sample
  std::vector<uint64_t> byte_offset;  // of each message in the file
  double time_scale = 1e-6;
};

SourceSeries ReadSource(std::string_view bytes, const std::string& name,
                        const DataflashContents& first, const ImuSource& src,
                        const std::string& prefix) {
  const DataflashFormat* f = first.FormatOf(src.message);
  if (f == nullptr || !f->decodable) FailFormat(name, first, src.message);
  std::string time = "TimeUS";
  if (LabelIndex(*f, "SampleUS") >= 0)
    time = "SampleUS";
  else if (LabelIndex(*f, "TimeUS") < 0 && LabelIndex(*f, "TimeMS") >= 0)
    time = "TimeMS";
  DataflashRequest request;
  request.message = src.message;
  request.fields = {time, prefix + "X", prefix + "Y", prefix + "Z"};
  request.instance_field = src.instance_field;
  request.instance = src.instance;
  const DataflashContents log = ParseDataflash(bytes, name, request);
  SourceSeries s;
  const double mult0 = log.field_multipliers.empty() ? NAN : log.field_multipliers[0];
  s.time_scale = std::isfinite(mult0) && mult0 > 0 ? mult0 : (time == "TimeMS" ? 1e-3 : 1e-6);
  // Each of the three fields its own unit (FMTU) and multiplier; a unit that is not a rate (a
  // gyro) or a specific force (an accelerometer) is refused, not read as one.
  double scale[3];
  const bool rate = prefix == "Gyr";
  for (int a = 0; a < 3; ++a) {
    const size_t k = 1 + a;
    const std::string unit = k < log.field_units.size() ? log.field_units[k] : "";
    const bool known = rate ? (unit.empty() || unit == "rad/s" || unit == "deg/s")
                            : (unit.empty() || unit == "m/s/s" || unit == "m/s^2");
    if (!known) {
      throw UserError(
          name + ": field " + request.fields[k] + " of " + src.message + " is declared in '" +
          PrintableAscii(unit, kDataflashTextEcho) + "' (FMTU), not " +
          (rate ? "an angular rate (rad/s or deg/s)" : "a specific force (m/s/s)") +
          ": the log's units are damaged; it is not read as " + (rate ? "rad/s" : "m/s^2"));
    }
    scale[a] = unit == "deg/s" ? kRadPerDeg : 1.0;
    if (k < log.field_multipliers.size() && std::isfinite(log.field_multipliers[k]) &&
        log.field_multipliers[k] > 0 && !IsScaledChar(log.field_chars[k])) {
      scale[a] *= log.field_multipliers[k];
    }
  }
  const size_t rows = log.value_offsets.size();
  s.byte_offset = log.value_offsets;
  s.t_s.resize(rows);
  s.xyz.resize(3 * rows);
  for (size_t r = 0; r < rows; ++r) {
    s.t_s[r] = log.values[4 * r] * s.time_scale;
    for (int a = 0; a < 3; ++a) s.xyz[3 * r + a] = log.values[4 * r + 1 + a] * scale[a];
  }
  return s;
}

// The accelerometer sample nearest in time to each of `t_s` (both increasing or nearly).
std::vector<double> NearestInTime(const std::vector<double>& t_s, const SourceSeries& acc) {
  std::vector<double> out(3 * t_s.size());
  size_t j = 0;
  for (size_t i = 0; i < t_s.size(); ++i) {
    while (j + 1 < acc.t_s.size() &&
           std::abs(acc.t_s[j + 1] - t_s[i]) <= std::abs(acc.t_s[j] - t_s[i])) {
      ++j;
    }
    for (int a = 0; a < 3; ++a) out[3 * i + a] = acc.xyz[3 * j + a];
  }
  return out;
}

// Picks the source of `instance` (-1: the lowest); fails listing those there are.
ImuSource ChooseSource(const std::vector<ImuSource>& sources, int instance,
                       const std::string& name) {
  if (instance < 0) return sources.front();
  std::string list;
  for (const ImuSource& s : sources) {
    if (s.instance == instance) return s;
    list += (list.empty() ? "" : ", ") + std::to_string(s.instance) + " (" + s.message + ", " +
            std::to_string(s.count) + " messages)";
  }
  throw UserError(name + ": no IMU instance " + std::to_string(instance) +
                  " (imu.dataflash.instance) in the log; its instances are: " + list);
}

// The rows FinishImuLog takes (t, gyro x y z, then accel x y z when `with_accel`). A message
// with a value that is not finite or beyond any sensor (imu_log_options.h: a flipped bit in a
// float, -9.2e36) is a glitch: dropped, counted and named (message index and byte offset) in a
// warning, as a gap. More than `max_dropped_fraction` of the messages so damaged is an error
// naming the first.
void PackRows(const SourceSeries& gyro, const std::vector<double>& accel, bool with_accel,
              const std::string& name, const std::string& what, double max_dropped_fraction,
              std::vector<double>* values_out, std::vector<int>* row_number_out,
              std::vector<std::string>* warnings) {
  const size_t rows = gyro.t_s.size();
  const int needed = with_accel ? 7 : 4;
  std::vector<double>& values = *values_out;
  values.clear();
  values.reserve(rows * needed);
  std::vector<int>& row_number = *row_number_out;
  row_number.clear();
  row_number.reserve(rows);
  long damaged = 0;
  std::string first;
  for (size_t r = 0; r < rows; ++r) {
    double v[7];
    v[0] = gyro.t_s[r];
    for (int a = 0; a < 3; ++a) v[1 + a] = gyro.xyz[3 * r + a];
    if (with_accel)
      for (int a = 0; a < 3; ++a) v[4 + a] = accel[3 * r + a];
    int bad = -1;
    for (int k = 0; k < needed && bad < 0; ++k) {
      const double bound = k == 0 ? INFINITY : (k <= 3 ? kMaxGyroRateRadPerS : kMaxAccelMps2);
      if (!std::isfinite(v[k]) || std::abs(v[k]) > bound) bad = k;
    }
    if (bad >= 0) {
      if (++damaged == 1) {
        char value[32];
        std::snprintf(value, sizeof(value), "%g", v[bad]);
        first = "message " + std::to_string(r + 1) + " of " + what +
                (r < gyro.byte_offset.size() ? " (byte " + std::to_string(gyro.byte_offset[r]) + ")"
                                             : std::string()) +
                " has " +
                (bad == 0   ? "time"
                 : bad <= 3 ? "a gyro rate"
                            : "a specific force") +
                " = " + value +
                (bad == 0   ? " s"
                 : bad <= 3 ? " rad/s (|rate| <= 1e4 rad/s: a gyro logs no more)"
                            : " m/s^2 (|f| <= 1e5 m/s^2: an accelerometer logs no more)");
      }
      continue;
    }
    values.insert(values.end(), v, v + needed);
    row_number.push_back(static_cast<int>(std::min<size_t>(r + 1, 2147483647)));
  }
  if (damaged == 0) return;
  if (static_cast<double>(damaged) > std::max(1.0, max_dropped_fraction * rows)) {
    throw UserError(name + ": " + std::to_string(damaged) + " of " + std::to_string(rows) + " " +
                    what + " messages hold a value no sensor gives (more than the " +
                    Fmt("%g", 100 * max_dropped_fraction) +
                    " % that are dropped as glitches); the first: " + first);
  }
  warnings->push_back(std::to_string(damaged) + " " + what + " message(s) with a damaged value " +
                      "dropped as glitches (a gap in the series): " + first);
}

}  // namespace

double DataflashMessageInfo::rate_hz() const {
  if (!regular()) return 0.0;
  return (count - 1) / (last_time_s - first_time_s);
}

bool DataflashMessageInfo::regular() const {
  if (timed < 3 || timed != count || !std::isfinite(first_time_s) || !std::isfinite(last_time_s))
    return false;
  const double span = last_time_s - first_time_s;
  if (!(span > 0)) return false;
  const double mean_step = span / (count - 1);
  const bool gap = max_step_s > kIrregularStepFactor * mean_step && max_step_s > kIrregularGapS;
  return !gap && backward_steps * 100 <= count;  // instances interleaved may step back a little
}

const DataflashMessageInfo* DataflashContents::Find(const std::string& name) const {
  for (const DataflashMessageInfo& m : messages) {
    if (m.name == name) return &m;
  }
  return nullptr;
}

const DataflashFormat* DataflashContents::FormatOf(const std::string& name) const {
  for (const auto& [type, f] : formats) {
    if (f.name == name) return &f;
  }
  return nullptr;
}

int DataflashFieldSize(char c) {
  switch (c) {
    case 'b':
    case 'B':
    case 'M':
      return 1;
    case 'h':
    case 'H':
    case 'c':
    case 'C':
      return 2;
    case 'i':
    case 'I':
    case 'f':
    case 'e':
    case 'E':
    case 'L':
    case 'n':
      return 4;
    case 'd':
    case 'q':
    case 'Q':
      return 8;
    case 'N':
      return 16;
    case 'Z':
    case 'a':
      return 64;
    default:
      return 0;
  }
}

bool LooksLikeDataflash(std::string_view bytes) {
  return bytes.size() >= kHeader && static_cast<unsigned char>(bytes[0]) == kDataflashHead1 &&
         static_cast<unsigned char>(bytes[1]) == kDataflashHead2 &&
         static_cast<unsigned char>(bytes[2]) == kDataflashFmtType;
}

bool NamedLikeDataflash(const std::string& path) {
  std::string lower = path;
  for (char& c : lower) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  auto ends_with = [&](const std::string& suffix) {
    return lower.size() >= suffix.size() &&
           lower.compare(lower.size() - suffix.size(), suffix.size(), suffix) == 0;
  };
  return ends_with(".bin") || ends_with(".bin.gz");
}

DataflashContents ParseDataflash(std::string_view bytes, const std::string& name,
                                 const DataflashRequest& request) {
  if (bytes.empty()) {
    throw UserError(name + ": the file is empty (expected an ArduPilot DataFlash log)");
  }
  return DataflashParser(bytes, name, request).Run();
}

ImuData ReadDataflashImu(std::string_view bytes, const std::string& name,
                         const ImuLogOptions& options) {
  std::string why;
  if (!options.Check(&why)) throw UserError(name + ": invalid log options: " + why);
  const DataflashContents log = ParseDataflash(bytes, name);
  std::vector<ImuSource> sources = SourcesOf(log, "IMU");
  bool gyr = false;
  if (sources.empty()) {
    sources = SourcesOf(log, "GYR");
    gyr = true;
  }
  if (sources.empty()) {
    for (const char* m : {"IMU", "IMU2", "IMU3", "GYR"}) {
      const DataflashFormat* f = log.FormatOf(m);
      if (f != nullptr && !f->decodable) FailFormat(name, log, m);
      if (f != nullptr && log.misframed.count(f->type) && log.Find(m) == nullptr) {
        FailFormat(name, log, m);
      }
    }
    for (const char* m : {"IMU", "GYR"}) {
      const DataflashMessageInfo* info = log.Find(m);
      if (info == nullptr || info->count == 0 || info->invalid_instances == 0) continue;
      throw UserError(name + ": " + std::to_string(info->count) + " " + m + " messages, but " +
                      "none with an instance the reader can use: their " + info->instance_field +
                      " field reads " + info->invalid_instance_example + " (an instance is 0-" +
                      std::to_string(kMaxDataflashInstance) + "), in " +
                      std::to_string(info->invalid_instances) + " of them: the log is damaged; " +
                      (options.dataflash_instance < 0
                           ? std::string("no instance is present")
                           : "instance " + std::to_string(options.dataflash_instance) +
                                 " (imu.dataflash.instance) is not present"));
    }
    throw UserError(name +
                    ": an ArduPilot DataFlash log without IMU (or GYR) messages: is IMU "
                    "logging on (LOG_BITMASK)? Messages found: " +
                    ListMessages(log));
  }
  const ImuSource src = ChooseSource(sources, options.dataflash_instance, name);
  SourceSeries gyro = ReadSource(bytes, name, log, src, "Gyr");
  bool with_accel = false;
  std::vector<double> accel;
  if (!gyr) {
    accel = ReadSource(bytes, name, log, src, "Acc").xyz;
    with_accel = true;
  } else {
    std::vector<ImuSource> acc = SourcesOf(log, "ACC");
    for (const ImuSource& a : acc) {
      if (a.instance != src.instance) continue;
      const SourceSeries s = ReadSource(bytes, name, log, a, "Acc");
      if (!s.t_s.empty()) {
        accel = NearestInTime(gyro.t_s, s);
        with_accel = true;
      }
    }
  }
  if (options.require_accel && !with_accel) {
    throw UserError(name +
                    ": accelerometer data is required but the log has no ACC messages of "
                    "instance " +
                    std::to_string(src.instance));
  }
  const std::string what =
      src.message + (src.instance_field.empty()
                         ? std::string()
                         : " " + src.instance_field + "=" + std::to_string(src.instance));
  const size_t rows = gyro.t_s.size();
  if (rows == 0) throw UserError(name + ": no " + what + " messages could be read");
  const int needed = with_accel ? 7 : 4;
  std::vector<double> values;
  std::vector<int> row_number;
  ImuData data;
  data.warnings = log.warnings;
  PackRows(gyro, accel, with_accel, name, what, options.max_dropped_fraction, &values, &row_number,
           &data.warnings);
  if (sources.size() > 1 && options.dataflash_instance < 0) {
    data.warnings.push_back(std::to_string(sources.size()) + " IMU instances in the log; read " +
                            what + " (the lowest; imu.dataflash.instance chooses another)");
  }
  if (const DataflashMessageInfo* info = log.Find(src.message);
      info != nullptr && info->invalid_instances > 0) {
    data.warnings.push_back(std::to_string(info->invalid_instances) + " " + src.message +
                            " message(s) skipped: their " + info->instance_field +
                            " field is no "
                            "instance (" +
                            info->invalid_instance_example + ", a damaged value)");
  }
  if (gyr)
    data.warnings.push_back("no IMU messages: read " + what +
                            (with_accel ? " with ACC" : " (gyro only)"));
  const size_t before = data.warnings.size();
  std::vector<double> scale(needed, 1.0);
  scale[0] = gyro.time_scale;
  data =
      FinishImuLog(name, options, values, needed, row_number, scale, with_accel, std::move(data));
  for (size_t i = before; i < data.warnings.size(); ++i) {
    std::string& w = data.warnings[i];
    for (const char* from : {"near line ", "at line "}) {
      const size_t at = w.find(from);
      if (at != std::string::npos) {
        w.replace(at, std::strlen(from), std::string(from, std::strlen(from) - 5) + "message ");
      }
    }
    w += " [" + what + "]";
  }
  return data;
}

}  // namespace bifilar

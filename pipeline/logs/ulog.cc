#include "pipeline/logs/ulog.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <map>
#include <set>
#include <utility>

#include "base/text_format.h"
#include "base/user_error.h"
#include "pipeline/logs/imu_log_finish.h"
#include "pipeline/logs/simulated_log.h"

namespace bifilar {
namespace {

constexpr size_t kHeaderSize = 16;    // magic (7), version (1), start timestamp (8)
constexpr size_t kMessageHeader = 3;  // uint16_t msg_size, uint8_t msg_type
constexpr size_t kFlagBitsSize = 40;  // compat[8], incompat[8], appended_offsets[3]
// Bounds checked before anything is allocated for a format (pipeline/logs/ulog.h):
constexpr int kMaxNestingDepth = kUlogMaxNestingDepth;  // nested type levels, the topic's included
// A data message holds at most 65535 - 2 bytes of payload; a type larger than 65535 bytes can
// never be logged. So a topic flattens to at most 65535 fields.
constexpr uint64_t kMaxTypeSize = 65535;
constexpr uint64_t kMaxFlatNameBytes = kUlogMaxFlatNameBytes;  // all flattened names of a type
// Format fields visited while sizing, locating timestamps and flattening, per file: a file that
// redefines formats or re-subscribes topics over and over cannot make the reader quadratic.
// PX4 logs take ~1e4; 2e6 take ~1 s.
constexpr uint64_t kMaxFormatWork = 2000000;

enum class Kind : uint8_t {
  kI8,
  kU8,
  kI16,
  kU16,
  kI32,
  kU32,
  kI64,
  kU64,
  kF32,
  kF64,
  kBool,
  kChar,
  kNested
};

struct Scalar {
  const char* name;
  Kind kind;
  int size;
};
constexpr Scalar kScalars[] = {
    {"int8_t", Kind::kI8, 1},    {"uint8_t", Kind::kU8, 1},   {"int16_t", Kind::kI16, 2},
    {"uint16_t", Kind::kU16, 2}, {"int32_t", Kind::kI32, 4},  {"uint32_t", Kind::kU32, 4},
    {"int64_t", Kind::kI64, 8},  {"uint64_t", Kind::kU64, 8}, {"float", Kind::kF32, 4},
    {"double", Kind::kF64, 8},   {"bool", Kind::kBool, 1},    {"char", Kind::kChar, 1}};

int KindSize(Kind kind) {
  for (const Scalar& s : kScalars) {
    if (s.kind == kind) return s.size;
  }
  return 0;
}

const Scalar* FindScalar(std::string_view type) {
  for (const Scalar& s : kScalars) {
    if (type == s.name) return &s;
  }
  return nullptr;
}

// One field of an 'F' definition as written: `type[array_len] name`.
struct RawField {
  std::string type;
  uint32_t array_len = 1;
  bool is_array = false;
  std::string name;
};

struct RawFormat {
  std::vector<RawField> fields;
  uint64_t byte_offset = 0;  // of its 'F' message
};

// A field of a flattened topic: nested types and arrays expanded, padding left out.
struct FlatField {
  std::string name;
  std::string type;
  Kind kind;
  uint32_t offset;
};

// The resolved layout of a logged topic.
struct Layout {
  std::vector<FlatField> fields;
  uint32_t size = 0;              // bytes of the whole message (padding included)
  uint32_t trailing_padding = 0;  // bytes of a last `_padding` field, which is not logged
};

// Little-endian loads, whatever the host's byte order.
template <typename U>
U LoadUnsigned(const unsigned char* p) {
  U v = 0;
  for (size_t i = 0; i < sizeof(U); ++i) v |= static_cast<U>(p[i]) << (8 * i);
  return v;
}

double Decode(const unsigned char* p, Kind kind) {
  switch (kind) {
    case Kind::kI8:
      return static_cast<int8_t>(p[0]);
    case Kind::kU8:
    case Kind::kBool:
    case Kind::kChar:
      return p[0];
    case Kind::kI16:
      return static_cast<int16_t>(LoadUnsigned<uint16_t>(p));
    case Kind::kU16:
      return LoadUnsigned<uint16_t>(p);
    case Kind::kI32:
      return static_cast<int32_t>(LoadUnsigned<uint32_t>(p));
    case Kind::kU32:
      return LoadUnsigned<uint32_t>(p);
    case Kind::kI64:
      return static_cast<double>(static_cast<int64_t>(LoadUnsigned<uint64_t>(p)));
    case Kind::kU64:
      return static_cast<double>(LoadUnsigned<uint64_t>(p));
    case Kind::kF32: {
      const uint32_t bits = LoadUnsigned<uint32_t>(p);
      float f;
      std::memcpy(&f, &bits, sizeof(f));
      return f;
    }
    case Kind::kF64: {
      const uint64_t bits = LoadUnsigned<uint64_t>(p);
      double d;
      std::memcpy(&d, &bits, sizeof(d));
      return d;
    }
    case Kind::kNested:
      break;
  }
  return 0.0;
}

// Bytes of a name or format echoed in a message (PrintableAscii).
constexpr size_t kUlogTextEcho = 60;

std::string Join(const std::vector<std::string>& items, size_t max_items = 200) {
  std::string out;
  for (size_t i = 0; i < items.size() && i < max_items; ++i) out += (i ? ", " : "") + items[i];
  if (items.size() > max_items) out += ", ... (" + std::to_string(items.size()) + " in all)";
  return out.empty() ? "none" : out;
}

class UlogParser {
 public:
  UlogParser(std::string_view bytes, const std::string& name, const UlogRequest& request)
      : data_(reinterpret_cast<const unsigned char*>(bytes.data())),
        size_(bytes.size()),
        name_(name),
        request_(request),
        msg_role_(65536, kUnknown) {}

  UlogContents Run();

 private:
  enum Role : uint8_t { kUnknown, kOther, kWanted };

  [[noreturn]] void Fail(uint64_t offset, const std::string& what) const {
    throw UserError(name_ + ": byte " + std::to_string(offset) + ": " + what);
  }

  void ReadHeader();
  // Reads the messages in [begin, end); `last` is true for the section that ends the file.
  void ReadSection(uint64_t begin, uint64_t end, bool last);
  void OnMessage(uint64_t offset, char type, const unsigned char* body, uint32_t size);
  void OnFlagBits(uint64_t offset, const unsigned char* body, uint32_t size);
  void OnFormat(uint64_t offset, const unsigned char* body, uint32_t size);
  void OnSubscription(uint64_t offset, const unsigned char* body, uint32_t size);
  void OnData(uint64_t offset, const unsigned char* body, uint32_t size);
  void NoteSimulatedInfo(const unsigned char* body, uint32_t size);

  // What a type flattens to: its size (bytes), its fields (padding left out) and the bytes of
  // their flattened names.
  struct TypeInfo {
    uint32_t size = 0;
    uint64_t fields = 0;
    uint64_t name_bytes = 0;
  };
  // Memoised; fails (naming the format) on an undefined or circular type, nesting deeper than
  // kMaxNestingDepth, and a type that could not fit a message or would flatten to more than
  // kMaxFlatNameBytes of names: all before anything is allocated for it.
  TypeInfo Measure(const std::string& type, uint64_t offset);
  uint32_t SizeOf(const std::string& type, uint64_t offset) { return Measure(type, offset).size; }
  void Flatten(const std::string& type, const std::string& prefix, uint32_t base, Layout* layout);
  Layout Resolve(const std::string& topic, uint64_t offset);
  // The offset and kind of the top-level scalar `timestamp` of `topic` (false: none, or its
  // format cannot be resolved).
  bool FindTimestamp(const std::string& topic, uint64_t offset, uint32_t* at, Kind* kind);
  std::string DroppedTail(uint64_t pos) const;

  const unsigned char* data_;
  uint64_t size_;
  const std::string& name_;
  const UlogRequest& request_;
  UlogContents out_;
  bool simulated_noted_ = false;

  std::map<std::string, RawFormat> formats_;
  std::map<std::string, TypeInfo> measured_;  // memoised Measure
  std::vector<std::string> resolving_;        // types being measured, outermost first
  uint64_t format_work_ = 0;                  // steps of Measure, FindTimestamp and Flatten
  // Memoised FindTimestamp (offset, or -1: none) and Resolve of the wanted topic; cleared with
  // measured_ when a format is redefined.
  std::map<std::string, std::pair<int32_t, Kind>> timestamps_;
  std::map<std::string, Layout> layouts_;
  // Counts `steps` of format work; fails past kMaxFormatWork.
  void Spend(uint64_t steps, uint64_t offset) {
    format_work_ += steps;
    if (format_work_ > kMaxFormatWork) {
      Fail(offset, "the format definitions need more than " + std::to_string(kMaxFormatWork) +
                       " steps to resolve (formats redefined or topics subscribed over and "
                       "over?): the file is damaged or crafted");
    }
  }
  std::vector<uint64_t> appended_offsets_;
  std::vector<uint8_t> msg_role_;        // by msg_id
  std::vector<int> subscription_index_;  // by msg_id into out_.subscriptions (-1: none)
  bool first_message_ = true;

  // The wanted topic, once subscribed.
  std::vector<std::pair<uint32_t, Kind>> wanted_;  // offset and kind of each requested field
  uint32_t wanted_min_size_ = 0, wanted_max_size_ = 0;
  uint64_t first_wanted_offset_ = 0;  // of the first wanted sample

  // request_.topic_timestamps: where each subscription's `timestamp` is (by msg_id; -1: none).
  std::vector<int32_t> timestamp_at_;
  std::vector<Kind> timestamp_kind_;
};

void UlogParser::ReadHeader() {
  if (size_ < kHeaderSize) {
    Fail(size_, "the file is " + std::to_string(size_) +
                    " bytes long, shorter than a ULog header (16 bytes)");
  }
  if (std::memcmp(data_, kUlogMagic, sizeof(kUlogMagic)) != 0) {
    Fail(0, "not a ULog file (it does not start with the ULog magic bytes 'ULog' 01 12 35)");
  }
  out_.version = data_[7];
  out_.start_timestamp_us = LoadUnsigned<uint64_t>(data_ + 8);
  if (out_.version > 1) {
    out_.warnings.push_back("ULog file format version " + std::to_string(out_.version) +
                            " is newer than this reader (1); read as version 1");
  }
}

UlogContents UlogParser::Run() {
  subscription_index_.assign(65536, -1);
  if (request_.topic_timestamps) {
    timestamp_at_.assign(65536, -1);
    timestamp_kind_.assign(65536, Kind::kU64);
  }
  ReadHeader();
  // The first message must be the flag bits (if any); it tells where appended sections start.
  uint64_t end = size_;
  if (size_ >= kHeaderSize + kMessageHeader && data_[kHeaderSize + 2] == 'B') {
    const uint32_t msg_size = LoadUnsigned<uint16_t>(data_ + kHeaderSize);
    if (kHeaderSize + kMessageHeader + msg_size <= size_) {
      OnFlagBits(kHeaderSize, data_ + kHeaderSize + kMessageHeader, msg_size);
    }
  }
  if (!appended_offsets_.empty()) end = appended_offsets_.front();
  ReadSection(kHeaderSize, end, appended_offsets_.empty());
  for (size_t i = 0; i < appended_offsets_.size(); ++i) {
    const bool last = i + 1 == appended_offsets_.size();
    ReadSection(appended_offsets_[i], last ? size_ : appended_offsets_[i + 1], last);
  }
  for (const auto& s : out_.subscriptions) {
    if (s.topic == request_.topic && s.multi_id == request_.multi_id) out_.found = true;
  }
  return std::move(out_);
}

void UlogParser::ReadSection(uint64_t pos, uint64_t end, bool last) {
  while (pos < end) {
    if (end - pos < kMessageHeader ||
        pos + kMessageHeader + LoadUnsigned<uint16_t>(data_ + pos) > end) {
      // A message cut short: by the end of the file (the logger stopped mid-write) or by the
      // next appended section (the spec's way of appending to a log that may end anywhere).
      if (last) out_.warnings.push_back(DroppedTail(pos));
      return;
    }
    const uint32_t msg_size = LoadUnsigned<uint16_t>(data_ + pos);
    const unsigned char type = data_[pos + 2];
    if (msg_size == 0 || !((type >= 'A' && type <= 'Z') || (type >= 'a' && type <= 'z'))) {
      Fail(pos, "corrupt message header (size " + std::to_string(msg_size) + ", type byte " +
                    std::to_string(type) + "): the file is damaged");
    }
    OnMessage(pos, static_cast<char>(type), data_ + pos + kMessageHeader, msg_size);
    first_message_ = false;
    pos += kMessageHeader + msg_size;
  }
}

void UlogParser::OnMessage(uint64_t offset, char type, const unsigned char* body, uint32_t size) {
  switch (type) {
    case 'D':
      OnData(offset, body, size);
      return;
    case 'F':
      OnFormat(offset, body, size);
      return;
    case 'A':
      OnSubscription(offset, body, size);
      return;
    case 'B':
      if (!first_message_) {
        out_.warnings.push_back("a flag-bits message at byte " + std::to_string(offset) +
                                " that is not the first message is ignored");
      }
      return;  // the first one was read before the sections
    case 'O': {
      if (size < 2) Fail(offset, "dropout message too short (" + std::to_string(size) + " bytes)");
      out_.dropouts.push_back({offset, LoadUnsigned<uint16_t>(body), out_.samples()});
      return;
    }
    case 'R': {
      if (size < 2) Fail(offset, "unsubscribe message too short");
      const uint16_t msg_id = LoadUnsigned<uint16_t>(body);
      msg_role_[msg_id] = kUnknown;  // later data with this id is an error
      return;
    }
    case 'L':
    case 'C':
      if (size < (type == 'L' ? 9u : 11u)) Fail(offset, "logging message too short");
      ++out_.log_messages;
      return;
    case 'I':
    case 'P':
    case 'M':
    case 'Q': {
      // key_len follows 0 ('I', 'P') or 1 ('M': is_continued, 'Q': default_types) byte(s).
      const uint32_t skip = (type == 'M' || type == 'Q') ? 1 : 0;
      if (size < skip + 1 || body[skip] > size - skip - 1) {
        Fail(offset, std::string("'") + type + "' message: key length " +
                         (size > skip ? std::to_string(body[skip]) : std::string("missing")) +
                         " exceeds the message (" + std::to_string(size) + " bytes)");
      }
      if (type == 'I') NoteSimulatedInfo(body, size);  // pipeline/logs/simulated_log.h
      return;
    }
    default:
      return;  // 'S' (sync) and message types newer than this reader: skipped, as the spec asks
  }
}

// An info message "char[N] bifilar_simulated" (the key length was checked): a log written by
// `bifilar simulate` says so once in the warnings (pipeline/logs/simulated_log.h).
void UlogParser::NoteSimulatedInfo(const unsigned char* body, uint32_t size) {
  const std::string_view key(reinterpret_cast<const char*>(body) + 1, body[0]);
  const std::string suffix = std::string("] ") + kSimulatedUlogInfoKey;
  if (key.substr(0, 5) != "char[" || key.size() < suffix.size() ||
      key.substr(key.size() - suffix.size()) != suffix || simulated_noted_) {
    return;
  }
  simulated_noted_ = true;
  out_.warnings.push_back(SimulatedLogWarning(
      std::string_view(reinterpret_cast<const char*>(body) + 1 + body[0], size - 1 - body[0])));
}

void UlogParser::OnFlagBits(uint64_t offset, const unsigned char* body, uint32_t size) {
  if (size < kFlagBitsSize) {
    Fail(offset, "flag-bits message too short (" + std::to_string(size) + " bytes, expected 40)");
  }
  const unsigned char* incompat = body + 8;
  if ((incompat[0] & ~1u) != 0 ||
      std::any_of(incompat + 1, incompat + 8, [](unsigned char c) { return c != 0; })) {
    Fail(offset + kMessageHeader + 8,
         "unknown incompatible flag bits are set: this log uses a newer ULog format that this "
         "reader cannot read");
  }
  if (!(incompat[0] & 1u)) return;
  uint64_t previous = kHeaderSize;
  for (int i = 0; i < 3; ++i) {
    const uint64_t o = LoadUnsigned<uint64_t>(body + 16 + 8 * i);
    if (o == 0) continue;
    if (o <= previous || o > size_) {
      Fail(offset + kMessageHeader + 16 + 8 * i,
           "appended data offset " + std::to_string(o) + " is outside the file (" +
               std::to_string(size_) + " bytes) or not after the previous section");
    }
    appended_offsets_.push_back(o);
    previous = o;
  }
}

void UlogParser::OnFormat(uint64_t offset, const unsigned char* body, uint32_t size) {
  const std::string_view text(reinterpret_cast<const char*>(body), size);
  const size_t colon = text.find(':');
  if (colon == std::string_view::npos || colon == 0) {
    Fail(offset,
         "format definition without 'name:' ('" + PrintableAscii(text, kUlogTextEcho) + "')");
  }
  const std::string type_name(text.substr(0, colon));
  RawFormat format;
  format.byte_offset = offset;
  size_t pos = colon + 1;
  while (pos < text.size()) {
    size_t semi = text.find(';', pos);
    if (semi == std::string_view::npos) semi = text.size();
    std::string_view field = text.substr(pos, semi - pos);
    pos = semi + 1;
    if (field.empty()) continue;
    const size_t space = field.rfind(' ');
    if (space == std::string_view::npos || space == 0 || space + 1 == field.size()) {
      Fail(offset, "format '" + PrintableAscii(type_name, kUlogTextEcho) + "': field '" +
                       PrintableAscii(field, kUlogTextEcho) + "' is not 'type name'");
    }
    RawField f;
    std::string_view type = field.substr(0, space);
    f.name = std::string(field.substr(space + 1));
    const size_t bracket = type.find('[');
    if (bracket != std::string_view::npos) {
      const std::string_view len = type.substr(bracket + 1);
      uint64_t n = 0;
      size_t i = 0;
      for (; i < len.size() && len[i] >= '0' && len[i] <= '9' && n <= 65535; ++i)
        n = n * 10 + (len[i] - '0');
      if (i == 0 || i + 1 != len.size() || len[i] != ']' || n == 0 || n > 65535) {
        Fail(offset, "format '" + PrintableAscii(type_name, kUlogTextEcho) +
                         "': bad array size in '" + PrintableAscii(field, kUlogTextEcho) + "'");
      }
      f.array_len = static_cast<uint32_t>(n);
      f.is_array = true;
      type = type.substr(0, bracket);
    }
    f.type = std::string(type);
    format.fields.push_back(std::move(f));
  }
  if (format.fields.empty())
    Fail(offset, "format '" + PrintableAscii(type_name, kUlogTextEcho) + "' has no fields");
  // A new type changes no measured one (a type used before its definition was not measured);
  // a redefinition may.
  if (formats_.count(type_name) != 0) {
    measured_.clear();
    timestamps_.clear();
    layouts_.clear();
  }
  formats_[type_name] = std::move(format);
}

bool IsPadding(const RawField& f) { return f.name.rfind("_padding", 0) == 0; }

UlogParser::TypeInfo UlogParser::Measure(const std::string& type, uint64_t offset) {
  if (const Scalar* s = FindScalar(type)) return {static_cast<uint32_t>(s->size), 1, 0};
  if (const auto it = measured_.find(type); it != measured_.end()) return it->second;
  const auto it = formats_.find(type);
  if (it == formats_.end())
    Fail(offset, "type '" + PrintableAscii(type, kUlogTextEcho) + "' is used but never defined");
  const uint64_t at = it->second.byte_offset;
  if (std::find(resolving_.begin(), resolving_.end(), type) != resolving_.end()) {
    std::string chain;
    for (const std::string& t : resolving_) chain += PrintableAscii(t, 40) + " -> ";
    Fail(at, "format '" + PrintableAscii(type, kUlogTextEcho) +
                 "' contains itself (circular definition: " + chain + PrintableAscii(type, 40) +
                 ")");
  }
  if (static_cast<int>(resolving_.size()) >= kMaxNestingDepth) {
    Fail(at, "format '" + PrintableAscii(resolving_.front(), kUlogTextEcho) +
                 "' nests types more than " + std::to_string(kMaxNestingDepth) +
                 " levels deep (at '" + PrintableAscii(type, kUlogTextEcho) +
                 "'); this reader accepts at most " + std::to_string(kMaxNestingDepth));
  }
  resolving_.push_back(type);
  TypeInfo info;
  uint64_t size = 0;
  for (const RawField& f : it->second.fields) {
    Spend(1, at);
    const TypeInfo element = Measure(f.type, at);
    size += static_cast<uint64_t>(element.size) * f.array_len;
    if (size > kMaxTypeSize) {
      Fail(at, "format '" + PrintableAscii(type, kUlogTextEcho) + "' is more than " +
                   std::to_string(kMaxTypeSize) + " bytes (at field '" +
                   PrintableAscii(f.name, kUlogTextEcho) +
                   "'), more than a ULog data message can hold");
    }
    if (IsPadding(f)) continue;
    // Each element's name: the field name, "[i]" for an array, "." before a nested field.
    const uint64_t own = f.name.size() + (f.is_array ? 2 + std::to_string(f.array_len).size() : 0) +
                         (FindScalar(f.type) ? 0 : 1);
    info.fields += static_cast<uint64_t>(f.array_len) * element.fields;
    info.name_bytes +=
        static_cast<uint64_t>(f.array_len) * (element.fields * own + element.name_bytes);
    if (info.name_bytes > kMaxFlatNameBytes) {
      Fail(at, "format '" + PrintableAscii(type, kUlogTextEcho) + "' flattens to " +
                   std::to_string(info.fields) + " or more fields whose names take more than " +
                   std::to_string(kMaxFlatNameBytes >> 20) + " MiB (at field '" +
                   PrintableAscii(f.name, kUlogTextEcho) + "'): no real log has such a topic");
    }
  }
  resolving_.pop_back();
  info.size = static_cast<uint32_t>(size);
  measured_[type] = info;
  return info;
}

// Every field of a measured type visits at least one byte of it, so this is bounded by the
// type's size (<= 65535) plus its fields; the names by kMaxFlatNameBytes.
void UlogParser::Flatten(const std::string& type, const std::string& prefix, uint32_t base,
                         Layout* layout) {
  const RawFormat& format = formats_.at(type);
  uint32_t at = base;
  for (const RawField& f : format.fields) {
    Spend(IsPadding(f) ? 1 : f.array_len, format.byte_offset);
    const uint32_t element = SizeOf(f.type, format.byte_offset);
    const Scalar* scalar = FindScalar(f.type);
    for (uint32_t i = 0; i < f.array_len && !IsPadding(f); ++i) {
      const std::string name = prefix + f.name + (f.is_array ? "[" + std::to_string(i) + "]" : "");
      const uint32_t where = at + i * element;
      if (scalar) {
        layout->fields.push_back({name, f.type, scalar->kind, where});
      } else {
        Flatten(f.type, name + ".", where, layout);
      }
    }
    at += element * f.array_len;
  }
}

Layout UlogParser::Resolve(const std::string& topic, uint64_t offset) {
  if (const auto it = layouts_.find(topic); it != layouts_.end()) return it->second;
  if (formats_.find(topic) == formats_.end()) {
    Fail(offset, "topic '" + PrintableAscii(topic, kUlogTextEcho) +
                     "' is subscribed but has no format definition");
  }
  Layout layout;
  const TypeInfo info = Measure(topic, offset);  // bounds the allocations below
  layout.size = info.size;
  layout.fields.reserve(info.fields);
  Flatten(topic, "", 0, &layout);
  const RawField& last = formats_.at(topic).fields.back();
  if (IsPadding(last)) layout.trailing_padding = SizeOf(last.type, offset) * last.array_len;
  layouts_[topic] = layout;
  return layout;
}

bool UlogParser::FindTimestamp(const std::string& topic, uint64_t offset, uint32_t* at,
                               Kind* kind) {
  if (const auto it = timestamps_.find(topic); it != timestamps_.end()) {
    *at = static_cast<uint32_t>(std::max(0, it->second.first));
    *kind = it->second.second;
    return it->second.first >= 0;
  }
  const auto it = formats_.find(topic);
  if (it == formats_.end()) return false;  // not memoised: the format may come later
  std::pair<int32_t, Kind> found{-1, Kind::kU64};
  try {
    uint64_t position = 0;
    for (const RawField& f : it->second.fields) {
      Spend(1, offset);
      const Scalar* scalar = FindScalar(f.type);
      if (f.name == "timestamp" && !f.is_array && scalar != nullptr) {
        found = {static_cast<int32_t>(position), scalar->kind};
        break;
      }
      position += static_cast<uint64_t>(SizeOf(f.type, offset)) * f.array_len;
      if (position > kMaxTypeSize) break;
    }
  } catch (const UserError&) {
    resolving_.clear();  // listed without a rate; a use of the topic names the fault
    if (format_work_ > kMaxFormatWork) throw;
  }
  timestamps_[topic] = found;
  *at = static_cast<uint32_t>(std::max(0, found.first));
  *kind = found.second;
  return found.first >= 0;
}

// What is lost when the last section ends inside a message at `pos`.
std::string UlogParser::DroppedTail(uint64_t pos) const {
  const uint64_t rest = size_ - pos;
  std::string what = "the log ends inside a message at byte " + std::to_string(pos) + " of " +
                     std::to_string(size_);
  if (size_ - pos >= kMessageHeader) {
    what += " (its header claims " + std::to_string(LoadUnsigned<uint16_t>(data_ + pos)) +
            " bytes, " + std::to_string(rest - kMessageHeader) + " remain)";
  }
  char percent[32];
  std::snprintf(percent, sizeof(percent), "%.2g", 100.0 * static_cast<double>(rest) / size_);
  what += ": the last " + std::to_string(rest) + " bytes (" + percent +
          " % of the file) are not read (the log was cut short while logging, or that size "
          "field is damaged)";
  const long samples = out_.samples();
  if (samples > 1 && pos > first_wanted_offset_) {
    const double bytes_per_sample = static_cast<double>(pos - first_wanted_offset_) / (samples - 1);
    const long lost = std::lround(static_cast<double>(rest) / bytes_per_sample);
    if (lost > 0) {
      what += "; at the rate of the data before it, that is about " + std::to_string(lost) +
              " sample(s) of topic '" + PrintableAscii(request_.topic, kUlogTextEcho) + "'";
    }
  }
  return what;
}

void UlogParser::OnSubscription(uint64_t offset, const unsigned char* body, uint32_t size) {
  if (size < 4) Fail(offset, "subscription message too short (" + std::to_string(size) + " bytes)");
  UlogSubscription s;
  s.multi_id = body[0];
  s.msg_id = LoadUnsigned<uint16_t>(body + 1);
  s.topic.assign(reinterpret_cast<const char*>(body + 3), size - 3);
  subscription_index_[s.msg_id] = static_cast<int>(out_.subscriptions.size());
  msg_role_[s.msg_id] = kOther;
  if (request_.topic_timestamps) {
    uint32_t at = 0;
    Kind kind = Kind::kU64;
    const bool has = FindTimestamp(s.topic, offset, &at, &kind);
    timestamp_at_[s.msg_id] = has ? static_cast<int32_t>(at) : -1;
    timestamp_kind_[s.msg_id] = kind;
  }
  if (s.topic == request_.topic && s.multi_id == request_.multi_id) {
    msg_role_[s.msg_id] = kWanted;
    const Layout layout = Resolve(s.topic, offset);
    Spend(layout.fields.size() * (1 + request_.fields.size()), offset);  // copied and searched
    out_.fields.clear();
    out_.field_types.clear();
    for (const FlatField& f : layout.fields) {
      out_.fields.push_back(f.name);
      out_.field_types.push_back(f.type);
    }
    wanted_.clear();
    uint32_t extent = 0;
    for (const std::string& want : request_.fields) {
      const auto it = std::find_if(layout.fields.begin(), layout.fields.end(),
                                   [&](const FlatField& f) { return f.name == want; });
      if (it == layout.fields.end()) {
        throw UserError(name_ + ": ULog topic '" + s.topic + "' (multi_id " +
                        std::to_string(s.multi_id) + ") has no field '" + want +
                        "'; its fields are: " + Join(out_.fields));
      }
      wanted_.emplace_back(it->offset, it->kind);
      extent = std::max<uint32_t>(extent, it->offset + FindScalar(it->type)->size);
    }
    wanted_max_size_ = layout.size;
    wanted_min_size_ = std::max(layout.size - layout.trailing_padding, extent);
  }
  out_.subscriptions.push_back(std::move(s));
}

void UlogParser::OnData(uint64_t offset, const unsigned char* body, uint32_t size) {
  if (size < 2) Fail(offset, "data message too short (" + std::to_string(size) + " bytes)");
  const uint16_t msg_id = LoadUnsigned<uint16_t>(body);
  const uint8_t role = msg_role_[msg_id];
  if (role == kUnknown) {
    Fail(offset,
         "data for msg_id " + std::to_string(msg_id) +
             ", which no subscription ('A' message) before it announced: the file is damaged");
  }
  UlogSubscription& subscription = out_.subscriptions[subscription_index_[msg_id]];
  ++subscription.samples;
  if (!timestamp_at_.empty() && timestamp_at_[msg_id] >= 0) {
    const uint32_t at = static_cast<uint32_t>(timestamp_at_[msg_id]);
    const Kind kind = timestamp_kind_[msg_id];
    if (size - 2 >= at + static_cast<uint32_t>(KindSize(kind))) {
      const double t = Decode(body + 2 + at, kind);
      if (subscription.samples == 1) subscription.first_timestamp_us = t;
      subscription.last_timestamp_us = t;
    } else {
      timestamp_at_[msg_id] = -1;  // a sample too short for it: no rate
      subscription.first_timestamp_us = subscription.last_timestamp_us = NAN;
    }
  }
  if (role != kWanted) return;
  const uint32_t n = size - 2;
  if (n < wanted_min_size_ || n > wanted_max_size_) {
    Fail(offset, "data of topic '" + request_.topic + "' holds " + std::to_string(n) +
                     " bytes; its format defines " + std::to_string(wanted_max_size_) +
                     (wanted_min_size_ != wanted_max_size_
                          ? " (" + std::to_string(wanted_min_size_) + " without trailing padding)"
                          : std::string()) +
                     ": the file is damaged");
  }
  const unsigned char* p = body + 2;
  if (out_.value_offsets.empty()) first_wanted_offset_ = offset;
  for (const auto& [field_offset, kind] : wanted_)
    out_.values.push_back(Decode(p + field_offset, kind));
  out_.value_offsets.push_back(offset);
}

std::string TopicList(const UlogContents& c) {
  std::map<std::string, std::set<int>> by_topic;
  for (const auto& s : c.subscriptions) by_topic[s.topic].insert(s.multi_id);
  std::vector<std::string> items;
  for (const auto& [topic, ids] : by_topic) {
    std::string item = topic;
    if (ids.size() > 1 || *ids.begin() != 0) {
      item += " (multi_id";
      for (int id : ids) item += " " + std::to_string(id);
      item += ")";
    }
    items.push_back(item);
  }
  return Join(items);
}

// Undoes the wrap-around of a timestamp field narrower than 64 bits: a step back by more than
// half its range is a wrap. Steps back by less stay (the repair drops those samples).
void UnwrapTimestamps(const std::string& type, size_t stride, std::vector<double>* values) {
  int bits = 0;
  if (type == "uint32_t")
    bits = 32;
  else if (type == "uint16_t")
    bits = 16;
  else if (type == "uint8_t")
    bits = 8;
  if (bits == 0 || values->empty()) return;
  const double range = std::ldexp(1.0, bits);
  double offset = 0.0, previous = (*values)[0];
  for (size_t i = stride; i < values->size(); i += stride) {
    const double raw = (*values)[i];
    if (raw < previous - range / 2) offset += range;
    previous = raw;
    (*values)[i] = raw + offset;
  }
}

}  // namespace

bool LooksLikeUlog(std::string_view bytes) {
  return bytes.size() >= sizeof(kUlogMagic) &&
         std::memcmp(bytes.data(), kUlogMagic, sizeof(kUlogMagic)) == 0;
}

bool UseUlogReader(std::string_view bytes, const ImuFormat& format) {
  return format.container == LogContainer::kUlog ||
         (format.container == LogContainer::kAuto && LooksLikeUlog(bytes));
}

bool UlogTopicDefaults(const std::string& topic, UlogSelection* selection) {
  selection->topic = topic;
  if (topic == "sensor_combined") {
    selection->gyro_fields = {"gyro_rad[0]", "gyro_rad[1]", "gyro_rad[2]"};
    selection->accel_fields = {"accelerometer_m_s2[0]", "accelerometer_m_s2[1]",
                               "accelerometer_m_s2[2]"};
  } else if (topic == "vehicle_angular_velocity") {
    selection->gyro_fields = {"xyz[0]", "xyz[1]", "xyz[2]"};
    selection->accel_fields = {"", "", ""};
  } else if (topic == "sensor_gyro") {
    selection->gyro_fields = {"x", "y", "z"};
    selection->accel_fields = {"", "", ""};
  } else {
    return false;
  }
  return true;
}

UlogContents ParseUlog(std::string_view bytes, const std::string& name,
                       const UlogRequest& request) {
  return UlogParser(bytes, name, request).Run();
}

ImuData ReadUlogImu(std::string_view bytes, const std::string& name, const ImuFormat& format,
                    const ImuLogOptions& options) {
  std::string why;
  if (!options.Check(&why)) throw UserError(name + ": invalid log options: " + why);
  const UlogSelection& sel = format.ulog;
  const bool with_accel = !sel.accel_fields[0].empty();
  if (options.require_accel && !with_accel) {
    throw UserError(name + ": accelerometer data is required but imu.ulog.accel_fields is empty");
  }
  UlogRequest request;
  request.topic = sel.topic;
  request.multi_id = sel.multi_id;
  request.fields = {sel.time_field, sel.gyro_fields[0], sel.gyro_fields[1], sel.gyro_fields[2]};
  if (with_accel)
    request.fields.insert(request.fields.end(), sel.accel_fields.begin(), sel.accel_fields.end());
  const int needed = static_cast<int>(request.fields.size());

  UlogContents log = ParseUlog(bytes, name, request);
  const std::string what =
      "ULog topic '" + sel.topic + "' (multi_id " + std::to_string(sel.multi_id) + ")";
  if (!log.found) {
    std::string note;
    for (const auto& w : log.warnings) note += "; " + w;
    throw UserError(name + ": no " + what + " in the log; its topics are: " + TopicList(log) +
                    note);
  }
  if (log.samples() == 0)
    throw UserError(name + ": the " + what + " is subscribed but has no data");

  ImuData data;
  data.warnings = log.warnings;
  // Field types and scales: the time field in us (ms for uint8_t), the rest SI already.
  const auto type_of = [&](const std::string& field) {
    return log
        .field_types[std::find(log.fields.begin(), log.fields.end(), field) - log.fields.begin()];
  };
  const std::string time_type = type_of(sel.time_field);
  UnwrapTimestamps(time_type, needed, &log.values);
  const double time_scale = time_type == "uint8_t" ? 1e-3 : 1e-6;
  const size_t rows = log.value_offsets.size();
  std::vector<int> row_number(rows);
  for (size_t r = 0; r < rows; ++r) {
    double* v = &log.values[r * needed];
    for (int k = 0; k < needed; ++k) {
      if (!std::isfinite(v[k])) {
        throw UserError(name + ": byte " + std::to_string(log.value_offsets[r]) + ": sample " +
                        std::to_string(r + 1) + " of the " + what + " has " + request.fields[k] +
                        " = " + (std::isnan(v[k]) ? "nan" : "inf") +
                        "; NaN and infinite values are not allowed");
      }
      if (k > 0 && std::abs(v[k]) > (k <= 3 ? kMaxGyroRateRadPerS : kMaxAccelMps2)) {
        char value[32];
        std::snprintf(value, sizeof(value), "%g", v[k]);
        throw UserError(name + ": byte " + std::to_string(log.value_offsets[r]) + ": sample " +
                        std::to_string(r + 1) + " of the " + what + " has " + request.fields[k] +
                        " = " + value +
                        (k <= 3 ? " rad/s, beyond any gyro (|rate| <= 1e4 rad/s)"
                                : " m/s^2, beyond any accelerometer (|f| <= 1e5 m/s^2)"));
      }
    }
    v[0] *= time_scale;
    row_number[r] = static_cast<int>(std::min<size_t>(r + 1, 2147483647));
  }
  if (!log.dropouts.empty()) {
    long total_ms = 0;
    for (const auto& d : log.dropouts) total_ms += d.duration_ms;
    data.warnings.push_back(std::to_string(log.dropouts.size()) +
                            " logging dropout(s) ('O' messages, " + std::to_string(total_ms) +
                            " ms in all, the first at byte " +
                            std::to_string(log.dropouts.front().byte_offset) +
                            "): the samples lost are gaps in time, nothing is interpolated");
  }
  const size_t before = data.warnings.size();
  std::vector<double> scale(needed, 1.0);
  scale[0] = time_scale;
  data = FinishImuLog(name, options, log.values, needed, row_number, scale, with_accel,
                      std::move(data));
  // The shared repair speaks of CSV lines; here they are sample numbers of the topic.
  for (size_t i = before; i < data.warnings.size(); ++i) {
    std::string& w = data.warnings[i];
    for (const char* from : {"near line ", "at line "}) {
      const size_t at = w.find(from);
      if (at != std::string::npos)
        w.replace(at, std::strlen(from), std::string(from, std::strlen(from) - 5) + "sample ");
    }
    w += " [" + what + "]";
  }
  return data;
}

}  // namespace bifilar
